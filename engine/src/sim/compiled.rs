//! The compiled model: what [`crate::compile`] produces and no sample ever writes. Every
//! running copy of a model (an [`Engine`](crate::Engine), each voice of a bank, the template of
//! each group of voice lanes) holds it behind one `Arc`, so a voice costs its state alone:
//! positions, forces, arguments, coefficients and guard (`Engine`'s own fields).
//!
//! What lives here is cold for the sample loop except the routes, which the loop reads once
//! per sample: the structure of the links and macros stays with the state (`Interactions`,
//! `Macros`), because their uniform-chain flags and coefficients follow each voice's controls.
//! The native code, built from both, is shared the same way beside it (`Engine::native`).

use crate::laws::{ArgClass, NUM_ARG_CLASSES};
use crate::sim::info::ModelInfo;
use crate::spec::expr::{ExprRef, Program};

/// The immutable part of a compiled model.
///
/// 584 bytes on x86-64 (checked below), plus its vectors: per point the labels and rendering
/// coordinates of [`ModelInfo`] (about 28 bytes), per route 8 bytes, per expression node of the
/// program about 24 bytes.
#[derive(Debug)]
pub(crate) struct Compiled {
    /// Counts, labels, parameters, channels and the motion layout.
    pub info: ModelInfo,
    /// Every argument's and initial value's expression, compiled to one program.
    pub program: Program,

    // Routes, read at every sample.
    /// Avatars: input channel → point (stage 1 a).
    pub avatars: Vec<Route>,
    /// Audio-rate parameters: input channel → parameter slot (stage 1 b).
    pub audio_params: Vec<Route>,
    /// Force inputs: input channel → point (stage 4).
    pub force_inputs: Vec<Route>,
    /// `posOutput`: output channel ← point.
    pub pos_outputs: Vec<Route>,
    /// `frcOutput`: output channel ← the sum of F over `frc_sources[start..start+len]`, packed
    /// as (channel, start, len). A plain target has one source; a connection point reads every
    /// connection point at the same location (spec §3.12 e, see `compile`).
    pub frc_outputs: Vec<(u32, u32, u32)>,
    pub frc_sources: Vec<u32>,

    // What the audio-rate parameters move.
    /// Arguments that depend on an audio-rate parameter: re-evaluated every sample.
    pub audio_bindings: Vec<Binding>,
    /// Single masses and proxies whose coefficients depend on audio-rate arguments.
    pub audio_masses: Vec<u32>,
    pub audio_proxies: Vec<u32>,
    /// Scale factor of each argument class at this sample rate (spec §1.7).
    pub class_scale: [f64; NUM_ARG_CLASSES],

    // Initial state (stage 0 of spec §1.5).
    pub init_runs: Vec<InitRun>,
    /// Fixed nodes of macros, as point indices: x̃ = x after `init_runs`.
    pub init_fixed_points: Vec<u32>,

    /// The motion refresh interval R, in samples (spec §6.1).
    pub motion_interval: u32,
}

/// A signal routed between a 0-based channel and a point or parameter slot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Route {
    pub channel: u32,
    pub index: u32,
}

/// One argument: its slot in `Engine::args` receives `program(expr) × class factor`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Binding {
    pub slot: u32,
    pub expr: ExprRef,
    pub class: ArgClass,
}

/// How a point's initial state is computed at stage 0 (spec §1.5).
#[derive(Clone, Copy, Debug)]
pub(crate) enum InitRule {
    /// x = x̃ = X₀ (grounds, avatars, fixed nodes).
    Fixed,
    /// x̃ = X₀ − v·factor (factor 1/SR scaled, 1 raw).
    Velocity { v: ExprRef, factor: f64 },
    /// massG: x̃ = X₀ − (X₀ − X_R0)·factor (factor 44100/SR scaled, 1 raw).
    Delayed { xr0: ExprRef, factor: f64 },
}

/// The initial state of a run of points `first..first+count` that share X₀ and a rule.
#[derive(Clone, Copy, Debug)]
pub(crate) struct InitRun {
    pub first: u32,
    pub count: u32,
    pub x0: ExprRef,
    pub rule: InitRule,
}

/// The size written in [`Compiled`]'s doc comment.
#[cfg(target_arch = "x86_64")]
const _: () = assert!(std::mem::size_of::<Compiled>() == 584);
