//! # Ressort engine
//!
//! The mass-interaction physics core of Ressort: every element of the mi-gen~ toolbox with the
//! equations of the reference specification (`shared/reference/mass-interaction.md`), a model
//! spec with a Rust builder, a compiler to flat per-kind arrays, a realtime simulation, stability
//! analysis, lock-free motion buffers, and the [`instrument`] that plays a model as the plugin
//! and the command line do. Plain Rust: no plugin or GUI dependency.
//!
//! ```
//! use ressort_engine::{compile, CompileOptions, Endpoint, ModelBuilder};
//! // A harmonic oscillator hit by a force impulse (Oscillator tutorial 0).
//! let mut b = ModelBuilder::new();
//! b.osc("o", 1.0, 0.1, 0.0003, 0.0, 0.0);
//! b.frc_input(1, Endpoint::label("o"));
//! b.pos_output(1, Endpoint::label("o"));
//! let mut engine = compile(&b.build(), &CompileOptions::at(48_000.0)).unwrap();
//! let mut input = vec![0.0; 64];
//! input[0] = 1.0;
//! let mut output = vec![0.0; 64];
//! engine.process(64, &input, &mut output);
//! assert!(output[1] != 0.0);
//! ```

// The pipeline, in order: text → spec → compiled model → simulation → instrument, with the
// laws beside the spec and the analyses beside the simulation. Each folder's module doc says
// what it owns; no folder imports one that imports it back (test `folders`).
pub mod analysis;
pub mod compile;
pub mod instrument;
pub mod lang;
pub mod laws;
pub mod sim;
pub mod spec;

// The public paths of the modules that moved into the folders above.
pub use analysis::{modes, stability};
pub use sim::{engine, info, lanes, motion};
pub use spec::{expr, generators, reference};

pub use analysis::stability::{MassStability, StabilityReport, StabilityWarning};
pub use compile::{compile, CompileError, CompileErrorKind, CompileErrors, CompileOptions};
pub use lang::{parse, parse_bytes, print, Diagnostic, DiagnosticCode, Parsed, Severity};
pub use laws::LawKind;
pub use sim::engine::{
    BlockReport, Engine, GuardEvent, GuardKind, IoKind, IoPoint, ParamError, ParamId,
};
pub use sim::info::{InputUse, ModelInfo, OutputUse, PointInfo, PointKind};
pub use sim::motion::{MotionLayout, MotionStore, NamedBuffer};
pub use spec::expr::{BinOp, Expr, Func};
pub use spec::{
    Element, ElementKind, Endpoint, ExciterDecl, ExciterKind, HostSpec, Label, Law, LawForm,
    MacroKind, MacroRange, MacroSpec, ModelBuilder, ModelSpec, ParamDecl, ParamKind, Route,
    RouteSource, SampleRateMode, ScaleClass, Span, Vector, REFERENCE_SAMPLE_RATE_HZ,
};
