//! The modes of a prepared model at the instrument's controls (issue 14, the editor's Modes
//! view): the modal analysis of [`crate::analysis::modes`] run on a copy of the model with the
//! gains and macro values the instrument would put on it for a note at the reference key.
//!
//! The copy is taken when the model is prepared, off the audio thread, and analysed on a
//! worker thread: nothing here runs in `process()`.

use super::controls::{ClampView, Controls, Smoothed};
use super::gains::Gains;
use super::macros::MacroBinding;
use super::prepare::Prepared;
use crate::analysis::envelope::StabilityEnvelope;
use crate::analysis::modes::ModalAnalysis;
use crate::Engine;

/// What the modal analysis needs of a prepared model.
#[derive(Clone, Debug)]
pub struct ModalModel {
    engine: Engine,
    sample_rate: f64,
    reference_pitch_hz: Option<f64>,
    envelope: StabilityEnvelope,
    macros: Vec<Option<MacroBinding>>,
    macro_envelopes: Vec<Option<(StabilityEnvelope, StabilityEnvelope)>>,
    macro_reference: StabilityEnvelope,
    /// The model input a note strikes, 1-based as `@in1`.
    pub note_input: Option<usize>,
    /// How many inputs and outputs the model has.
    pub num_inputs: usize,
    pub num_outputs: usize,
}

/// The modes at one setting of the controls.
#[derive(Clone, Debug)]
pub struct ModesAtControls {
    pub analysis: ModalAnalysis,
    /// The Stiffness and Damping gains the analysis used (after the stability clamp).
    pub gains: Gains,
}

impl ModalModel {
    /// A copy of `prepared`'s model at rest, with what the clamp reads. Allocates.
    pub fn of(prepared: &Prepared) -> ModalModel {
        let info = prepared.engine.info();
        ModalModel {
            engine: prepared.engine.clone(),
            sample_rate: prepared.facts.sample_rate,
            reference_pitch_hz: prepared.facts.settings.reference_pitch_hz,
            envelope: prepared.facts.envelope.clone(),
            macros: prepared.facts.macros.clone(),
            macro_envelopes: prepared.facts.macro_envelopes.clone(),
            macro_reference: prepared.facts.macro_reference.clone(),
            note_input: prepared.facts.note_input.map(|i| i + 1),
            num_inputs: info.inputs.len(),
            num_outputs: info.outputs.len(),
        }
    }

    pub fn sample_rate(&self) -> f64 {
        self.sample_rate
    }

    /// The stability numbers of the model as written (every gain at 1, spec §5.2), and the
    /// label of the mass closest to its limit. Works on a copy: the editor's summary asks for
    /// them once, off the load (the 22,500-mass plate takes 4 ms).
    pub fn stability(&self) -> (crate::StabilityReport, Option<String>) {
        let mut engine = self.engine.clone();
        let report = engine.stability_numbers();
        let worst = report
            .worst()
            .map(|w| engine.info().point_label(w.point as usize));
        (report, worst)
    }

    /// The Stiffness and Damping gains and macro values the instrument puts on the model for a
    /// note at the reference key with these controls (every smoother at its target), clamped
    /// as when it plays.
    pub fn gains(&self, controls: &Controls) -> Gains {
        let view = ClampView {
            reference_pitch_hz: self.reference_pitch_hz,
            sample_rate: self.sample_rate,
            envelope: &self.envelope,
            macros: &self.macros,
            macro_envelopes: &self.macro_envelopes,
            macro_reference: &self.macro_reference,
        };
        Smoothed::snapped(controls, self.sample_rate).gains(&view, 0.0, 1.0)
    }

    /// The modes of the model with `controls` applied ([`Engine::modes`]: every mode of a
    /// model up to [`crate::analysis::modes::DENSE_LIMIT`] moving points, else the lowest `count`).
    /// Takes up to a few seconds on the largest models.
    pub fn modes(&mut self, controls: &Controls, count: Option<usize>) -> ModesAtControls {
        let gains = self.gains(controls);
        Smoothed::snapped(controls, self.sample_rate).set(&mut self.engine, &self.macros, &gains);
        ModesAtControls {
            analysis: self.engine.modes(count),
            gains,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::prepare;

    const OSC: &str = "@k param 0.01\n~macro k 0.005 0.02\n@g ground 0.\n@m mass 1. 0. 0.\n\
                       @s springDamper @g @m k 0.\n@in1 frcInput @m\n@out1 posOutput @m\n";

    fn controls() -> Controls {
        Controls::DEFAULT
    }

    /// f = SR/π·asin(√(K/M)/2) for one oscillator (spec §5.3), with K scaled by the gain.
    fn law(k: f64, sr: f64) -> f64 {
        sr / std::f64::consts::PI * (k.sqrt() / 2.0).asin()
    }

    #[test]
    fn the_modes_follow_stiffness_tune_and_the_macros() {
        let p = prepare("osc", OSC, 48_000.0).unwrap();
        let mut m = ModalModel::of(&p);
        assert_eq!(m.note_input, Some(1));
        let k = 0.01 * (44_100.0f64 / 48_000.0).powi(2);
        let f = |m: &mut ModalModel, c: &Controls| m.modes(c, None).analysis.modes[0].frequency_hz;
        let base = f(&mut m, &controls());
        assert!((base - law(k, 48_000.0)).abs() < 1e-6 * base, "{base}");

        // One octave of Stiffness doubles K.
        let mut c = controls();
        c.stiffness_octaves = 1.0;
        let up = f(&mut m, &c);
        assert!((up - law(2.0 * k, 48_000.0)).abs() < 1e-6 * up, "{up}");

        // Tune +12 semitones puts the reference pitch an octave up exactly. The reference is
        // this mode settled to PITCH_BITS of mantissa (a relative step δ ≤ 2^-(bits+1)), so the
        // mode itself lands within the law's sensitivity to δ: with x = πf/SR and the gain
        // 4cos²(x_ref), sin(πf''/SR) = 2 sin x cos x_ref, so f''/f = 2 + 2δ·sin²x / cos 2x.
        let mut c = controls();
        c.tune_st = 12.0;
        let octave = f(&mut m, &c);
        let x = std::f64::consts::PI * base / 48_000.0;
        let delta = 0.5f64.powi(crate::instrument::pitch::PITCH_BITS as i32 + 1);
        let bound = 2.0 * delta * x.sin().powi(2) / (2.0 * x).cos();
        let ratio = octave / base;
        assert!(
            (ratio - 2.0).abs() <= bound * (1.0 + 1e-3) + 1e-12,
            "{ratio} (bound {bound:e})"
        );

        // The macro slot at its top reads k = 0.02.
        let mut c = controls();
        c.macros[0] = 1.0;
        let top = f(&mut m, &c);
        let k2 = 0.02 * (44_100.0f64 / 48_000.0).powi(2);
        assert!((top - law(k2, 48_000.0)).abs() < 1e-6 * top, "{top}");

        // Back at the defaults, the same modes again: nothing sticks to the copy.
        assert_eq!(f(&mut m, &controls()), base);
    }

    #[test]
    fn a_stiffness_beyond_the_limit_is_analysed_as_clamped() {
        let p = prepare("osc", OSC, 48_000.0).unwrap();
        let mut m = ModalModel::of(&p);
        let mut c = controls();
        c.stiffness_octaves = 12.0;
        let r = m.modes(&c, None);
        assert!(r.gains.clamped);
        assert!(r.gains.stiffness < r.gains.requested_stiffness);
        // The clamped model is stable: every mode decays or holds.
        assert!(r.analysis.modes.iter().all(|m| m.radius <= 1.0 + 1e-12));
    }
}
