//! What one voice's gains are made of, apart from the controls that compute them
//! ([`super::controls`]) and the model they act on ([`super::prepare`]): the gains in use,
//! what a control acts on ([`Controlled`]), and the bits that tell a voice its gains have not
//! changed ([`TuneKey`], [`TuningMemo`]). The voice bank reads these without reaching back
//! into the controls.

use super::NUM_MACROS;
use crate::{Engine, ParamId, ScaleClass};

/// The gains in use after the last chunk, for meters and the editor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains {
    /// After the stability clamp.
    pub stiffness: f64,
    pub damping: f64,
    /// Asked for (Stiffness × Tune × note pitch), before the clamp.
    pub requested_stiffness: f64,
    pub requested_damping: f64,
    /// True while the clamp holds a gain below what was asked for.
    pub clamped: bool,
}

impl Default for Gains {
    fn default() -> Self {
        Gains {
            stiffness: 1.0,
            damping: 1.0,
            requested_stiffness: 1.0,
            requested_damping: 1.0,
            clamped: false,
        }
    }
}

/// What the controls act on: a model's engine, or one voice of a bank.
pub trait Controlled {
    fn set_class_gain(&mut self, class: ScaleClass, gain: f64);
    /// Ignores values the parameter cannot take (the controls only send finite ones).
    fn set_param(&mut self, id: ParamId, value: f64);
}

impl Controlled for Engine {
    fn set_class_gain(&mut self, class: ScaleClass, gain: f64) {
        Engine::set_class_gain(self, class, gain);
    }
    fn set_param(&mut self, id: ParamId, value: f64) {
        let _ = Engine::set_param(self, id, value);
    }
}

/// The smoothed controls a voice's gains read, bit for bit (`controls::Smoothed::controls_key`).
pub type ControlsKey = [u64; 3 + NUM_MACROS];

/// The inputs of one voice's gains, bit for bit ([`TuneKey::new`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TuneKey {
    smoothed: ControlsKey,
    voice: [u64; 4],
}

impl TuneKey {
    /// Everything `Smoothed::gains_offset` and `Smoothed::set` (in `controls`) read for one
    /// voice: when it has not changed since the voice was last tuned, neither have its gains.
    pub fn new(
        controls: &ControlsKey,
        note_st: f64,
        z_factor: f64,
        k_octaves: f64,
        z_octaves: f64,
    ) -> TuneKey {
        TuneKey {
            smoothed: *controls,
            voice: [note_st, z_factor, k_octaves, z_octaves].map(f64::to_bits),
        }
    }
}

/// A voice's tuning gain (`tuning_gain`) for the last semitones, reference pitch and sample
/// rate: its note rarely moves while the controls do.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TuningMemo(pub(super) Option<(TuningInputs, f64)>);

/// The bits of a tuning gain's inputs: semitones, reference pitch, sample rate.
pub(super) type TuningInputs = (u64, Option<u64>, u64);
