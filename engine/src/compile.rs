//! Compiles a [`ModelSpec`] for one sample rate into an [`Engine`]. Runs off the audio thread;
//! every problem is collected in one go (spec §3.12 f).
//!
//! The compiler is a sequence of named passes over the spec, sharing one state (`Cx`, in
//! `context`):
//!
//! 1. **resolve labels** (`labels`): the symbol table of parameters and elements, and the
//!    parameters' declared values;
//! 2. **number points** (`points`): single masses, macro nodes, avatars, in the order of
//!    spec §6.2;
//! 3. **group into kinds** (`kinds`): single masses, macros, avatars, one group per interaction
//!    law, inputs and outputs, every endpoint resolved to a point (connection points are
//!    created here);
//! 4. **order into bands** (`bands`): each interaction group's links reordered so that its
//!    bands (links (q + j, q + j + d)) lie next to each other, where that bands more of them;
//! 5. **bind arguments** (`bind`): argument slots and columns, compiled expressions, init runs;
//!
//! then `assemble` lays out the motion buffers and builds the engine. Errors are reported by
//! each pass in script order, pass after pass.

use crate::sim::engine::Engine;
use crate::sim::motion::DEFAULT_MOTION_INTERVAL_SAMPLES;
use crate::spec::{ModelSpec, SampleRateMode, REFERENCE_SAMPLE_RATE_HZ};
use context::Cx;

mod assemble;
mod bands;
mod bind;
mod context;
mod errors;
mod kinds;
mod labels;
mod points;
mod space;

pub use errors::{CompileError, CompileErrorKind, CompileErrors};

/// The most material points a model may have (about 100 MB of state and scratch).
pub const MAX_POINTS: usize = 1 << 20;
/// The deepest expression tree accepted.
pub const MAX_EXPR_DEPTH: usize = 256;
/// The sample rates accepted, in Hz.
pub const SAMPLE_RATE_RANGE_HZ: std::ops::RangeInclusive<f64> = 1.0..=10_000_000.0;

/// How to compile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompileOptions {
    /// The running sample rate in Hz.
    pub sample_rate_hz: f64,
    /// The motion refresh interval R in samples (spec §6.1), ≥ 1.
    pub motion_interval: u32,
    /// Whether a small model's sample loop is also compiled to machine code ([`crate::sim::jit`]:
    /// the same samples, faster). On by default; off runs every model on the interpreter.
    pub jit: bool,
}

impl Default for CompileOptions {
    fn default() -> Self {
        CompileOptions {
            sample_rate_hz: REFERENCE_SAMPLE_RATE_HZ,
            motion_interval: DEFAULT_MOTION_INTERVAL_SAMPLES,
            jit: true,
        }
    }
}

impl CompileOptions {
    /// Options for `sample_rate_hz` with the default motion interval.
    pub fn at(sample_rate_hz: f64) -> CompileOptions {
        CompileOptions {
            sample_rate_hz,
            ..CompileOptions::default()
        }
    }
}

/// Compiles `spec` for `options.sample_rate_hz`. Returns every error found, or an engine in its
/// initial state (spec §1.5 stage 0).
pub fn compile(spec: &ModelSpec, options: &CompileOptions) -> Result<Engine, CompileErrors> {
    let mut cx = Cx::new(spec);
    let rate = cx.rate(options);
    let params = cx.resolve_labels();
    // A 3-D model (`~dim 3`) has passes of its own (3-D spec).
    if spec.space.is_some() {
        return cx.compile_space(options, rate, params);
    }
    let numbering = cx.number_points();
    let mut kinds = cx.group_into_kinds(&params, &numbering);
    kinds.links.order_into_bands();
    let bound = cx.bind_arguments(&kinds, &numbering, rate);
    cx.assemble(options, rate, params, numbering, kinds, bound)
}

/// The sample rate a model is compiled for, and how its arguments scale with it (spec §1.7).
#[derive(Clone, Copy, Debug)]
struct Rate {
    sr: f64,
    mode: SampleRateMode,
}

impl Rate {
    /// The factor from a script's velocity to a per-sample displacement.
    fn velocity_factor(self) -> f64 {
        match self.mode {
            SampleRateMode::Scaled => 1.0 / self.sr,
            SampleRateMode::Raw => 1.0,
        }
    }
}

impl Cx<'_> {
    /// Checks the options; an invalid sample rate is reported, and the passes then go on at
    /// the reference rate so that every other error is found too.
    fn rate(&mut self, options: &CompileOptions) -> Rate {
        let sr = options.sample_rate_hz;
        if !(sr.is_finite() && SAMPLE_RATE_RANGE_HZ.contains(&sr)) {
            self.error(None, CompileErrorKind::InvalidSampleRate(sr));
        }
        if options.motion_interval == 0 {
            self.error(None, CompileErrorKind::InvalidMotionInterval);
        }
        let sr = if self.errors.is_empty() {
            sr
        } else {
            REFERENCE_SAMPLE_RATE_HZ
        };
        Rate {
            sr,
            mode: self.spec.sample_rate_mode,
        }
    }
}
