//! What the audio thread reports, as atomics that the editor and the tests read.

use atomic_float::AtomicF64;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64};

/// Live state of the running plugin. Written by the audio thread without locks.
#[derive(Debug)]
pub struct RuntimeStatus {
    /// How many times the guard reset an exploding model since the plugin was created.
    pub guard_trips: AtomicU32,
    /// Set on a guard trip; cleared by whoever shows it (the editor's reset button).
    pub guard_active: AtomicBool,
    /// The Stiffness and Damping gains in use, after the stability clamp.
    pub stiffness_gain: AtomicF64,
    pub damping_gain: AtomicF64,
    /// The Stiffness gain asked for (Stiffness × Tune × MIDI pitch) before the clamp.
    pub requested_stiffness_gain: AtomicF64,
    /// True while the clamp holds a gain below what was asked for.
    pub clamped: AtomicBool,
    /// Processing time as a fraction of real time, smoothed.
    pub cpu_load: AtomicF64,
    /// How many models the audio thread has switched to.
    pub running_generation: AtomicU64,
    /// The Damping gain asked for, before the clamp.
    pub requested_damping_gain: AtomicF64,
    /// Set by the editor's Strike button: the audio thread strikes the note input once.
    pub strike_requested: AtomicBool,
    /// The editor's Audition switch: strike the note input every second.
    pub audition: AtomicBool,
    /// Voices sounding, and the bank's size (1 and 1 when monophonic).
    pub voices_sounding: AtomicU32,
    pub voices_total: AtomicU32,
    /// The macro slot positions in use (a MIDI controller may have moved a slot away from its
    /// parameter's value).
    pub macros: [AtomicF64; ressort_engine::instrument::NUM_MACROS],
    /// Set by the editor's reset button; the audio thread resets the model at its next block
    /// and clears the guard flag.
    pub reset_requested: AtomicBool,
    /// The loudest sidechain sample that pushes the model (or triggers it) since the editor
    /// last read it: the input meter's.
    pub input_peak: AtomicF64,
    /// Strikes the sidechain trigger has played.
    pub triggered: AtomicU32,
    /// Provisional models that have taken their exact analyses ([`crate::model::Refinement`]).
    pub refinements: AtomicU64,
}

impl Default for RuntimeStatus {
    fn default() -> Self {
        RuntimeStatus {
            guard_trips: AtomicU32::new(0),
            guard_active: AtomicBool::new(false),
            stiffness_gain: AtomicF64::new(1.0),
            damping_gain: AtomicF64::new(1.0),
            requested_stiffness_gain: AtomicF64::new(1.0),
            clamped: AtomicBool::new(false),
            cpu_load: AtomicF64::new(0.0),
            running_generation: AtomicU64::new(0),
            requested_damping_gain: AtomicF64::new(1.0),
            strike_requested: AtomicBool::new(false),
            audition: AtomicBool::new(false),
            reset_requested: AtomicBool::new(false),
            macros: std::array::from_fn(|_| AtomicF64::new(0.5)),
            voices_sounding: AtomicU32::new(1),
            voices_total: AtomicU32::new(1),
            input_peak: AtomicF64::new(0.0),
            triggered: AtomicU32::new(0),
            refinements: AtomicU64::new(0),
        }
    }
}
