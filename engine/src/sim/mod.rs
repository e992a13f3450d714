//! The simulation: a compiled model and its running state, and the three ways of running it
//! sample by sample (stage order of spec §1.5). Fourth step of the pipeline: [`crate::compile`]
//! builds an [`Engine`](engine::Engine), the [`crate::instrument`] plays it.
//!
//! This folder owns:
//! * the compiled model, immutable and shared by its voices (`compiled`), and a running copy
//!   of it with its state ([`engine`]): points, arguments, controls (`control`), the guard
//!   (`guard`), held fixed points (`rest`), the flush of tiny values (`flush`);
//! * the reference kernels on `f64` (`kernels`), the voice lanes that run eight copies in
//!   vectors ([`lanes`]) and the native code for small models (`jit`, driven by `native`),
//!   bit-identical to each other; the laws they apply live in [`crate::laws`];
//! * what the outside reads of a model: its metadata ([`info`]), the motion buffers of spec §6
//!   ([`motion`]) and the places of its inputs and outputs (`display`).
//!
//! It depends on [`crate::spec`] and [`crate::laws`] only. Within it, `engine` is the top: the
//! files it drives import the state's parts (`kernels`, `compiled`), not the engine, except
//! the lanes, which hold one as their template, and the native driver (`native`).

pub(crate) mod compiled;
pub(crate) mod control;
pub(crate) mod display;
pub mod engine;
pub(crate) mod flush;
pub(crate) mod guard;
pub mod info;
pub(crate) mod jit;
pub(crate) mod kernels;
pub mod lanes;
pub mod motion;
pub(crate) mod native;
pub(crate) mod rest;
pub(crate) mod space;
