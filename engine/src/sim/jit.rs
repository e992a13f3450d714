//! Small models compiled to machine code (Cranelift), with their state in registers.
//!
//! The sample loop of [`crate::sim::engine`] keeps the state in arrays: each sample's chain of
//! dependent operations (mass update → link force → force accumulator → next mass update)
//! goes through memory, and every kind, route and run costs a loop of its own. For a model of
//! a few points that bookkeeping is the whole cost: a one-spring oscillator took 25 ns per
//! sample where compiled Faust `mi.lib`, which keeps x, x̃ and F in registers, takes 9.3.
//!
//! So a small model (at most [`MAX_ELEMENTS`] points and interactions, no macro, no
//! connection point, no audio-rate parameter) is also compiled, when the engine is built,
//! into one function that runs samples `start..end` of a block: it loads x, x̃ and F of every
//! point into SSA values, runs stages 1 a, 2 a, 4 and 6 of spec §1.5 sample after sample with
//! the point and link indices and the input and output channels fixed in the code, and stores
//! the state back when it returns. Arguments and mass coefficients are loaded from the
//! engine's arrays at entry, so parameter and gain changes need no new code.
//!
//! The code does the interpreter's IEEE operations in the interpreter's order (no FMA, no
//! reassociation; the laws of `crate::laws` on `jit/arith.rs`), so both give the same samples, bit
//! for bit (tests `native_code_equals_the_interpreter` and `every_law_equals_the_scalar_law`). The
//! one choice fixed in the code is which single masses run the plain update (2X − X̃) + F·(1/M):
//! the ones that were plain when the code was made. Plain is the general update's arithmetic
//! when a = 2, b = −1, g = +0, so the code is exact as long as those masses stay plain; a
//! parameter that makes one of them general sets the engine back on its interpreter until
//! it is plain again ([`NativeCode::fits`]). Plain masses of M = 1 that no parameter moves
//! skip the multiplication by 1/M (F·1 = F).
//!
//! Where an operation is an identity for the values a sample almost always has (+0 + c = c
//! for c ≠ 0, F + 0 = F for a silent input, a ground's X + 0·X̃ + 0·F = X), the code takes
//! the identity on a predicted branch and computes the operation on the other: the same
//! bits, with the operation out of the chain of dependent operations that bounds a small
//! model's sample (`add_force`, `ground` and the force inputs in `jit/emit.rs`).
//!
//! What stays with the interpreter's driver (`Engine::run_native`): the guard (the code
//! returns at the first sample with a bad output, and `outputs_or_trip` records it from the
//! stored state), the periodic flush (calls end at flush boundaries), the motion store (an
//! engine with one attached runs the interpreter), and the held fixed points of `rest.rs`.
//!
//! A small 3-D model (3-D spec §1.5; at most [`space::MAX_SPACE_ELEMENTS`] points and
//! interactions and fewer than [`space::MAX_SPACE_GROUP`] links of any one law, no connection
//! point, no audio-rate parameter) is compiled by `jit/space.rs` the same way, with x, x̃ and
//! F of every point on each of the three axes in SSA values: the avatars (stage 1 a), the
//! runs' update with its rest offset and locked axes (stage 2), every law of the 3-D table
//! through `jit/arith.rs` on the same one source as the scalar and lane paths, the force
//! inputs (stage 4) and the outputs, microphones included (stage 6), each in the order of
//! `sim/space/`. It reads every derived value (the runs' A, B, 1/M, G and a, the unit
//! directions, P⊥, the `osc` rest positions and the microphones' frozen weights) from the
//! engine's arrays and takes no identity, so it has no bail-out and no coefficient to watch:
//! [`NativeCode::fits`] checks only that the engine still has the model the code was made
//! for (tests `tests/space_jit.rs`).
//!
//! The code lives in executable pages owned by a [`JITModule`]; the engine's copies (voices)
//! share it through an `Arc`, and the last one frees it, off the audio thread like every
//! engine drop. Where Cranelift has no back end for the CPU, or the system refuses executable
//! memory, the model runs on the interpreter.

use crate::sim::compiled::Compiled;
use crate::sim::flush::FLUSH_INTERVAL;
use crate::sim::kernels::links::Interactions;
use crate::sim::kernels::macros::Macros;
use crate::sim::kernels::masses::SingleMasses;
use crate::sim::kernels::proxies::Proxies;
use crate::sim::kernels::Points;
use cranelift_codegen::isa::OwnedTargetIsa;
use cranelift_codegen::settings::{self, Configurable};
use cranelift_jit::JITModule;
use std::sync::{Mutex, OnceLock};

pub(crate) mod arith;
mod emit;
mod sample;
mod space;

/// The most points plus interactions a model compiled to native code may have. Beyond that
/// the state no longer fits in registers and the interpreter's vector loops win: on the Zen 3
/// build machine, element-by-element strings of 22, 32 and 48 masses (45, 65 and 97 points
/// and links) ran 1.3×, 0.9× and 0.8× as fast on native code as on the interpreter, meshes
/// of 5 × 5 and 6 × 6 nodes (65 and 96) 1.4× and 0.6× (docs/design/simulation.md, "Native code for
/// small models").
pub(crate) const MAX_ELEMENTS: usize = 60;

/// What the generated function reads: the engine's arrays and the block's buffers.
#[repr(C)]
pub(crate) struct Frame {
    pub x: *mut f64,
    pub xp: *mut f64,
    pub f: *mut f64,
    pub args: *const f64,
    pub a: *const f64,
    pub b: *const f64,
    pub inv_m: *const f64,
    pub gravity: *const f64,
    /// Input channel c at `inputs[c·frames ..]`, for c < `in_channels`.
    pub inputs: *const f64,
    /// Output channel c at `outputs[c·frames ..]`, for c < `out_channels`.
    pub outputs: *mut f64,
    pub frames: usize,
    pub in_channels: usize,
    pub out_channels: usize,
    pub limit: f64,
    /// −0: its bits flip a sign.
    pub sign: f64,
    /// [`SPARE`] zeros, read by an input channel the block does not have.
    pub zero: *const f64,
    /// [`SPARE`] values written by an output channel the block does not have.
    pub sink: *mut f64,
    /// A 3-D model's x and y axes (x, x̃, F of each; its z axis is `x`, `xp`, `f`), what
    /// its controls derive (`Space::coef` as [`RunCoef`](crate::sim::space::RunCoef)s, the
    /// unit directions and the line avatars' P⊥ as three f64 each) and what its stage 0
    /// froze (the `osc` rest positions, the microphones' weights and directions). Null for a
    /// 1-D model.
    pub axes: [[*mut f64; 3]; 2],
    pub coef: *const f64,
    pub units: *const f64,
    pub perp: *const f64,
    pub rest: *const f64,
    pub mic_weights: *const f64,
    pub mic_dirs: *const f64,
}

/// The most samples one call of the generated function runs, and the length of the spare
/// channels (`Frame::zero`, `Frame::sink`).
pub(crate) const SPARE: usize = FLUSH_INTERVAL as usize;

/// The spare input channel.
pub(crate) static ZEROS: [f64; SPARE] = [0.0; SPARE];

/// The generated function: runs samples `start..end` and returns `end`; or the first sample
/// whose outputs the guard rejects (its state stored, as after that sample); or, with
/// [`BAIL`] set, the first sample whose state the code does not handle (a non-finite input,
/// ground position or force on a ground, or a ground at −0), its state stored as before it.
pub(crate) type Entry = unsafe extern "C" fn(*const Frame, i64, i64) -> i64;

/// The flag of a bail-out in the generated function's result.
pub(crate) const BAIL: i64 = 1 << 62;

/// A model's sample loop as machine code.
pub(crate) struct NativeCode {
    entry: Entry,
    /// Per single mass: whether the code runs the plain update.
    plain: Vec<bool>,
    /// Per single mass: whether the code takes 1/M as exactly 1 (a plain mass of M = 1 that
    /// no parameter moves).
    unit: Vec<bool>,
    /// The lengths of the arrays the code indexes: points, arguments, single masses.
    points: usize,
    args: usize,
    singles: usize,
    /// A 3-D model's lengths the code indexes ([`space::Shape`]); `None` for a 1-D model.
    space: Option<space::Shape>,
    /// Bytes of machine code.
    size: usize,
    /// The pages `entry` lives in; freed when the last engine copy lets go.
    module: Mutex<Option<JITModule>>,
}

impl std::fmt::Debug for NativeCode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NativeCode")
            .field("points", &self.points)
            .field("size", &self.size)
            .finish()
    }
}

impl Drop for NativeCode {
    fn drop(&mut self) {
        let module = self.module.get_mut().map(Option::take);
        if let Ok(Some(module)) = module {
            // SAFETY: `entry` points into this module and no copy of it outlives `self`: the
            // engines that call it hold this value through an `Arc`.
            unsafe { module.free_memory() };
        }
    }
}

/// The host's Cranelift target, made once: `None` where Cranelift has no back end for it.
pub(crate) fn isa() -> Option<OwnedTargetIsa> {
    static ISA: OnceLock<Option<OwnedTargetIsa>> = OnceLock::new();
    ISA.get_or_init(|| {
        let mut flags = settings::builder();
        flags.set("opt_level", "speed").ok()?;
        flags.set("is_pic", "false").ok()?;
        // Cranelift's check of the IR this module builds: in debug builds (the tests).
        let verify = if cfg!(debug_assertions) {
            "true"
        } else {
            "false"
        };
        flags.set("enable_verifier", verify).ok()?;
        cranelift_native::builder()
            .ok()?
            .finish(settings::Flags::new(flags))
            .ok()
    })
    .clone()
}

/// What the native code is made from and checked against: the compiled model and the parts
/// of a running copy's state that shape the loop (an [`Engine`](crate::Engine) lends them).
pub(crate) struct Parts<'a> {
    pub model: &'a Compiled,
    pub points: &'a Points,
    pub args: &'a [f64],
    pub singles: &'a SingleMasses,
    pub macros: &'a Macros,
    pub proxies: &'a Proxies,
    pub interactions: &'a Interactions,
    /// The bindings of the control arguments (`ControlArgs::bindings`).
    pub control_bindings: &'a [crate::sim::compiled::Binding],
    /// A 3-D model's x and y axes and derived values; `None` for a 1-D model.
    pub space: Option<&'a crate::sim::space::Space>,
}

/// Whether this model is one the native code compiles (its kinds and size; see the module
/// documentation).
pub(crate) fn fits(engine: &Parts<'_>) -> bool {
    match engine.space {
        Some(_) => space::fits(engine),
        None => emit::fits(engine),
    }
}

impl NativeCode {
    /// Compiles `engine`'s sample loop, or returns `None` when the model is not one this
    /// compiles (see the module documentation) or Cranelift fails.
    pub(crate) fn build(engine: &Parts<'_>) -> Option<NativeCode> {
        if !fits(engine) {
            return None;
        }
        // A failure anywhere in Cranelift (a back-end limit, memory protection) leaves the
        // model on its interpreter; it must never take the host down with it.
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match engine.space {
            Some(_) => space::compile(engine),
            None => emit::compile(engine),
        }))
        .ok()
        .flatten()
    }

    /// Whether the code runs `engine` exactly: every mass it updates as plain is plain now,
    /// and every mass it takes as a unit mass still has 1/M = 1.
    pub(crate) fn fits(&self, engine: &Parts<'_>) -> bool {
        if let Some(shape) = &self.space {
            return engine.points.x.len() == self.points
                && engine.args.len() == self.args
                && engine.space.is_some_and(|s| shape.fits(s));
        }
        let s = &engine.singles;
        engine.points.x.len() == self.points
            && engine.args.len() == self.args
            && s.len() == self.singles
            && (0..self.singles).all(|i| {
                (!self.plain[i] || s.is_plain(i))
                    && (!self.unit[i] || s.inv_m[i].to_bits() == 1f64.to_bits())
            })
    }

    /// Bytes of machine code.
    pub(crate) fn size(&self) -> usize {
        self.size
    }

    /// The generated function. Calling it is safe when its [`Frame`] points into arrays of
    /// the lengths [`NativeCode::fits`] checked, and into block buffers that hold
    /// `in_channels` input and `out_channels` output channels of `frames` samples, for a call
    /// of at most [`SPARE`] samples ending at or before `frames`.
    pub(crate) fn entry(&self) -> Entry {
        self.entry
    }
}

#[cfg(test)]
mod tests {
    use crate::{compile, parse, CompileOptions};

    /// States no script starts from but a blow-up or a host can leave (−0 on a ground, NaN
    /// and infinite positions and forces, huge values), poked into both engines: the native
    /// code still gives the interpreter's bits, NaNs included, and trips the guard at the
    /// same sample.
    #[test]
    fn odd_states_give_the_interpreter_bits() {
        let text = "@g ground 0.\n@g2 ground 0.1\n@m mass 1. 0. 0.\n@n mass 2. 0. 0.\n\
                    @l springDamper @g @m 0.1 0.001\n@j springDamper @m @n 0.1 0.001\n\
                    @k springDamper @n @g2 0.1 0.001\n@c contact @g @n 0.1 0.001 0.\n\
                    @in1 frcInput @m\n@out1 posOutput @n\n@out2 frcOutput @g\n";
        let spec = parse(text).spec.expect("parses");
        let native = compile(&spec, &CompileOptions::at(48_000.0)).expect("compiles");
        let interpreted = compile(
            &spec,
            &CompileOptions {
                jit: false,
                ..CompileOptions::at(48_000.0)
            },
        )
        .expect("compiles");
        assert!(native.native_code_bytes().is_some());
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let values = [
            -0.0,
            f64::NAN,
            -f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e300,
        ];
        let mut input = vec![0.0; 8];
        input[3] = 0.01;
        for point in 0..native.points.x.len() {
            for array in 0..3 {
                for &value in &values {
                    let (mut a, mut b) = (native.clone(), interpreted.clone());
                    for e in [&mut a, &mut b] {
                        let p = &mut e.points;
                        [&mut p.x, &mut p.xp, &mut p.f][array][point] = value;
                    }
                    let (mut oa, mut ob) = (vec![0.0; 16], vec![0.0; 16]);
                    let ra = a.process(8, &input, &mut oa);
                    let rb = b.process(8, &input, &mut ob);
                    let at = format!("point {point}, array {array}, {value:e}");
                    assert_eq!(bits(&oa), bits(&ob), "{at}");
                    assert_eq!(ra, rb, "{at}");
                    assert_eq!(a.guard, b.guard, "{at}");
                    assert_eq!(bits(&a.points.x), bits(&b.points.x), "{at}");
                    assert_eq!(bits(&a.points.xp), bits(&b.points.xp), "{at}");
                    assert_eq!(bits(&a.points.f), bits(&b.points.f), "{at}");
                }
            }
        }
    }
}
