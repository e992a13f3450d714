//! The control stage: the host's knobs (Stiffness, Damping, Tune, the gains, the macro slots)
//! smoothed once per chunk and applied to the running model through its stability clamp.
//!
//! Stiffness and Damping multiply every K-class and Z-class argument (spec §1.7's classes);
//! Tune and the note move the Stiffness gain by the exact discrete tuning law
//! sin²(πf/SR) = K/4M (spec §5.3), see [`tuning_gain`].

use super::dsp::{db_to_gain, tuning_gain, ChunkSmoother};
use super::gains::{Controlled, ControlsKey, Gains, TuningMemo};
use super::macros::MacroBinding;
use super::prepare::Prepared;
use super::{CHUNK, NUM_MACROS};
use crate::analysis::envelope::StabilityEnvelope;
use crate::ScaleClass;

/// The range of the A4 reference, Hz.
pub const A4_RANGE_HZ: (f64, f64) = (400.0, 480.0);

/// Smoothing time constant of the physical controls.
const CONTROL_SMOOTHING_MS: f64 = 15.0;
/// Smoothing time constant of the gains.
const GAIN_SMOOTHING_MS: f64 = 5.0;
/// The Stiffness gain that Damping can never take away through the stability clamp: the
/// model's own stiffness.
const KEPT_STIFFNESS_GAIN: f64 = 1.0;

/// The instrument's knobs, in the units the plugin's parameters store.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controls {
    /// log₂ of the Stiffness factor.
    pub stiffness_octaves: f64,
    /// log₂ of the Damping factor.
    pub damping_octaves: f64,
    /// Semitones, by the exact law.
    pub tune_st: f64,
    pub output_db: f64,
    pub force_db: f64,
    pub position_db: f64,
    /// Macro slot positions, 0 … 1 (0.5: the declared value).
    pub macros: [f64; NUM_MACROS],
    /// The 40 Hz high-pass of the mi-gen example patches.
    pub dc_filter: bool,
    /// Semitones of a full pitch bend, up or down.
    pub bend_range_st: f64,
    /// A note's strike is velocity^exponent (1: linear; above 1 soft notes are softer).
    pub velocity_exponent: f64,
    /// MPE: MIDI channel 1 is the master channel (its bend moves every voice by the Bend
    /// Range), channels 2 … 16 are member channels whose bend (±48 semitones) and pressure
    /// move only their own voices.
    pub mpe: bool,
    /// The damper a released voice gets, 0 … 1: its Damping gain × 16^release (0: it rings
    /// on as a struck object does).
    pub release: f64,
    /// The tuning reference: the pitch of A4 in Hz. It moves every model by
    /// 12·log₂(A4/440) semitones, with Tune.
    pub a4_hz: f64,
    /// Sidechain trigger mode: onsets on the host's force signals strike the model (play a
    /// voice) instead of pushing it.
    pub trigger: bool,
    /// The trigger's sensitivity in dB: added to an onset's level before it becomes a
    /// velocity ([`super::trigger`]).
    pub trigger_sensitivity_db: f64,
}

impl Controls {
    /// What a fresh plugin instance starts with.
    pub const DEFAULT: Controls = Controls {
        stiffness_octaves: 0.0,
        damping_octaves: 0.0,
        tune_st: 0.0,
        output_db: 0.0,
        force_db: 0.0,
        position_db: 0.0,
        macros: [0.5; NUM_MACROS],
        dc_filter: true,
        bend_range_st: 2.0,
        velocity_exponent: 1.0,
        release: 0.0,
        mpe: false,
        a4_hz: 440.0,
        trigger: false,
        trigger_sensitivity_db: 0.0,
    };

    /// The controls a project saved before the automatic output trim started with: Output
    /// Gain +24 dB.
    pub const LEGACY: Controls = Controls {
        output_db: 24.0,
        ..Controls::DEFAULT
    };

    /// The A4 reference as semitones from 440 Hz.
    pub fn a4_semitones(&self) -> f64 {
        12.0 * (self.a4_hz / 440.0).log2()
    }

    /// The smoothed controls as numbers, to notice automation between blocks. Non-finite
    /// values read as their defaults, so a bad host value never reaches the model.
    pub(super) fn sanitized(mut self) -> Controls {
        let d = Controls::DEFAULT;
        let fix = |v: &mut f64, default: f64| {
            if !v.is_finite() {
                *v = default;
            }
        };
        fix(&mut self.stiffness_octaves, d.stiffness_octaves);
        fix(&mut self.damping_octaves, d.damping_octaves);
        fix(&mut self.tune_st, d.tune_st);
        fix(&mut self.output_db, d.output_db);
        fix(&mut self.force_db, d.force_db);
        fix(&mut self.position_db, d.position_db);
        fix(&mut self.bend_range_st, d.bend_range_st);
        fix(&mut self.velocity_exponent, d.velocity_exponent);
        fix(&mut self.release, d.release);
        self.release = self.release.clamp(0.0, 1.0);
        fix(&mut self.a4_hz, d.a4_hz);
        self.a4_hz = self.a4_hz.clamp(A4_RANGE_HZ.0, A4_RANGE_HZ.1);
        fix(&mut self.trigger_sensitivity_db, d.trigger_sensitivity_db);
        for m in &mut self.macros {
            fix(m, 0.5);
        }
        self
    }
}

impl Default for Controls {
    fn default() -> Self {
        Controls::DEFAULT
    }
}

/// The smoothed controls, advanced once per chunk.
#[derive(Clone, Debug, Default)]
pub(super) struct Smoothed {
    stiffness: ChunkSmoother,
    damping: ChunkSmoother,
    tune: ChunkSmoother,
    pub force_gain: ChunkSmoother,
    pub position_gain: ChunkSmoother,
    pub output_gain: ChunkSmoother,
    macros: [ChunkSmoother; NUM_MACROS],
    /// 2^Stiffness and 2^Damping (octaves) for the last exponent: while a control moves, every
    /// voice asks for the same power every chunk.
    pow2: [Pow2; 2],
    /// Each macro slot's parameter value for the last position and binding asked: every
    /// voice asks for the same one every chunk.
    macro_values: [MacroValue; NUM_MACROS],
}

/// [`MacroBinding::value_at`] for the last slot position and binding asked (the same call,
/// made once per distinct input).
#[derive(Clone, Debug, Default)]
struct MacroValue(std::cell::Cell<Option<[f64; 5]>>);

impl MacroValue {
    fn of(&self, b: &MacroBinding, position: f64) -> f64 {
        let same = |x: f64, y: f64| x.to_bits() == y.to_bits();
        match self.0.get() {
            Some([p, lo, mid, hi, v])
                if same(p, position)
                    && same(lo, b.min)
                    && same(mid, b.default)
                    && same(hi, b.max) =>
            {
                v
            }
            _ => {
                let v = b.value_at(position);
                self.0.set(Some([position, b.min, b.default, b.max, v]));
                v
            }
        }
    }
}

/// 2^x for the last x asked: the same `powf` call, made once per distinct argument.
#[derive(Clone, Debug, Default)]
struct Pow2(std::cell::Cell<Option<(u64, f64)>>);

impl Pow2 {
    fn of(&self, x: f64) -> f64 {
        match self.0.get() {
            Some((k, v)) if k == x.to_bits() => v,
            _ => {
                let v = 2f64.powf(x);
                self.0.set(Some((x.to_bits(), v)));
                v
            }
        }
    }
}

impl Smoothed {
    /// Every smoother on its target: a fresh start.
    pub fn snapped(c: &Controls, sample_rate: f64) -> Smoothed {
        let control = |v| ChunkSmoother::new(sample_rate, CHUNK, CONTROL_SMOOTHING_MS, v);
        let gain = |db| ChunkSmoother::new(sample_rate, CHUNK, GAIN_SMOOTHING_MS, db_to_gain(db));
        Smoothed {
            stiffness: control(c.stiffness_octaves),
            damping: control(c.damping_octaves),
            tune: control(c.tune_st + c.a4_semitones()),
            force_gain: gain(c.force_db),
            position_gain: gain(c.position_db),
            output_gain: gain(c.output_db),
            macros: c.macros.map(control),
            pow2: Default::default(),
            macro_values: Default::default(),
        }
    }

    /// Advances every smoother by `n` samples towards `c`; `bend_st` joins Tune.
    pub fn advance(&mut self, n: usize, c: &Controls, bend_st: f64) {
        self.stiffness.advance(n, c.stiffness_octaves);
        self.damping.advance(n, c.damping_octaves);
        self.tune.advance(n, c.tune_st + bend_st + c.a4_semitones());
        self.force_gain.advance(n, db_to_gain(c.force_db));
        self.position_gain.advance(n, db_to_gain(c.position_db));
        self.output_gain.advance(n, db_to_gain(c.output_db));
        for (s, &m) in self.macros.iter_mut().zip(&c.macros) {
            s.advance(n, m);
        }
    }

    /// Applies the smoothed gains and macros to `model`, clamped by its stability envelope
    /// and the macro envelopes of the slots that moved. `note_st` is the note's distance
    /// from the reference key in semitones.
    pub fn apply(&self, model: &mut Prepared, note_st: f64) -> Gains {
        let gains = self.gains(&ClampView::of(model), note_st, 1.0);
        self.set(&mut model.engine, &model.facts.macros, &gains);
        gains
    }

    /// The clamped Stiffness and Damping gains for a note `note_st` semitones from the
    /// reference key, with the Damping gain asked for multiplied by `z_factor` (the Release
    /// damper of a released voice).
    pub fn gains(&self, view: &ClampView<'_>, note_st: f64, z_factor: f64) -> Gains {
        self.gains_offset(
            view,
            note_st,
            z_factor,
            0.0,
            0.0,
            &mut TuningMemo::default(),
        )
    }

    /// [`Smoothed::gains`] with a voice's own modulation of Stiffness and Damping, in octaves
    /// (CLAP polyphonic modulation).
    pub fn gains_offset(
        &self,
        view: &ClampView<'_>,
        note_st: f64,
        z_factor: f64,
        k_octaves: f64,
        z_octaves: f64,
        memo: &mut TuningMemo,
    ) -> Gains {
        let semitones = self.tune.value + note_st;
        let key = (
            semitones.to_bits(),
            view.reference_pitch_hz.map(f64::to_bits),
            view.sample_rate.to_bits(),
        );
        let tuning = match memo.0 {
            Some((k, g)) if k == key => g,
            _ => {
                let g = tuning_gain(semitones, view.reference_pitch_hz, view.sample_rate);
                memo.0 = Some((key, g));
                g
            }
        };
        let requested_k = self.pow2[0].of(self.stiffness.value + k_octaves) * tuning;
        let requested_z = self.pow2[1].of(self.damping.value + z_octaves) * z_factor;
        let mut moved = [(view.envelope, 0.0); NUM_MACROS];
        let mut n_moved = 0;
        for (slot, (binding, envs)) in view.macros.iter().zip(view.macro_envelopes).enumerate() {
            if let (Some(b), Some((low, high))) = (binding, envs) {
                let v = self.macro_values[slot].of(b, self.macros[slot].value);
                let (env, f) = if v > b.default && b.max > b.default {
                    (high, (v - b.default) / (b.max - b.default))
                } else if v < b.default && b.min < b.default {
                    (low, (b.default - v) / (b.default - b.min))
                } else {
                    continue;
                };
                moved[n_moved] = (env, f.clamp(0.0, 1.0));
                n_moved += 1;
            }
        }
        let (gk, gz, clamped) = view.envelope.clamp_moved(
            requested_k,
            requested_z,
            KEPT_STIFFNESS_GAIN,
            view.macro_reference,
            &moved[..n_moved],
        );
        Gains {
            stiffness: gk,
            damping: gz,
            requested_stiffness: requested_k,
            requested_damping: requested_z,
            clamped,
        }
    }

    /// The smoothed controls every voice's gains read, formed once per tuning pass over the
    /// bank ([`TuneKey::new`]).
    pub fn controls_key(&self) -> ControlsKey {
        let mut key = [0; 3 + NUM_MACROS];
        key[0] = self.stiffness.value.to_bits();
        key[1] = self.damping.value.to_bits();
        key[2] = self.tune.value.to_bits();
        for (k, m) in key[3..].iter_mut().zip(&self.macros) {
            *k = m.value.to_bits();
        }
        key
    }

    /// Puts `gains` and the macro values on one engine (the model's, or a voice's).
    pub fn set(
        &self,
        engine: &mut impl Controlled,
        macros: &[Option<MacroBinding>],
        gains: &Gains,
    ) {
        engine.set_class_gain(ScaleClass::Stiffness, gains.stiffness);
        engine.set_class_gain(ScaleClass::Damping, gains.damping);
        for (slot, binding) in macros.iter().enumerate() {
            if let Some(b) = binding {
                engine.set_param(
                    b.param,
                    self.macro_values[slot].of(b, self.macros[slot].value),
                );
            }
        }
    }
}

/// What the stability clamp reads of a prepared model.
#[derive(Clone, Copy, Debug)]
pub struct ClampView<'a> {
    pub reference_pitch_hz: Option<f64>,
    pub sample_rate: f64,
    pub envelope: &'a StabilityEnvelope,
    pub macros: &'a [Option<MacroBinding>],
    pub macro_envelopes: &'a [Option<(StabilityEnvelope, StabilityEnvelope)>],
    /// The envelope the macro envelopes compare with: the Gershgorin one at the declared
    /// values ([`Facts::macro_reference`](super::Facts)).
    pub macro_reference: &'a StabilityEnvelope,
}

impl<'a> ClampView<'a> {
    pub fn of(m: &'a Prepared) -> ClampView<'a> {
        ClampView {
            reference_pitch_hz: m.facts.settings.reference_pitch_hz,
            sample_rate: m.facts.sample_rate,
            envelope: &m.facts.envelope,
            macros: &m.facts.macros,
            macro_envelopes: &m.facts.macro_envelopes,
            macro_reference: &m.facts.macro_reference,
        }
    }
}
