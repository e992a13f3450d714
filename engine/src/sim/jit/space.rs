//! The generated function of a small 3-D model (3-D spec §1.5): the loop of `jit/emit.rs`
//! with three axes of SSA values per point, and a sample (`jit/space/sample.rs`) that runs
//! stages 1 a, 2, 4 and 6 with the scalar engine's IEEE operations in its order
//! (`sim/space/`: `io.rs`, `masses.rs`, `links.rs`), every law of the 3-D table through
//! [`Ir`](super::arith::Ir).
//!
//! ```text
//! entry:   load the state (x, x̃, F of every point on x, y and z) into variables; per input
//!          and output channel, the address of the call's first sample
//! header:  j = end − start? → exit
//! body:    two samples, each of which may leave for `bad` (its outputs rejected, state
//!          after it)
//! exit:    store the state, return end
//! ```
//!
//! What the controls derive (the runs' coefficients A, B, 1/M, G and a; the unit directions
//! and the line avatars' P⊥) and what stage 0 freezes (the `osc` rest positions, the
//! microphones' weights and directions) is read from the engine's arrays at every sample,
//! as the laws' arguments are: a parameter or gain change needs no new code, and the code
//! takes no value as known. So it computes every operation the interpreter computes, the
//! identities included (a `mass` without air friction still multiplies by A = 2 and
//! B = 1), and there is no state it cannot run: unlike the 1-D code it never bails out. A
//! non-finite input sample reads as +0, as the interpreter reads it (a `select`).
//!
//! What the code fixes is the model's shape, which no control moves ([`SpaceModel`], shared
//! by every copy): the points and their runs and locked axes, the links of each law, the
//! inputs, outputs and microphones. [`Shape::fits`] checks that an engine still has that
//! model and arrays of those lengths.

use super::arith::Callees;
use super::emit::{channels, define, sorted_unique, FLAGS};
use super::{Frame, NativeCode, Parts};
use crate::laws::space::SpaceLawKind;
use crate::sim::space::{Avatar, ForceInput, Output3, Space, SpaceModel};
use cranelift_codegen::ir::condcodes::IntCC;
use cranelift_codegen::ir::{types, Block, InstBuilder, Value};
use cranelift_frontend::{FunctionBuilder, Variable};
use std::mem::offset_of;
use std::sync::{Arc, Mutex};

mod sample;

/// The most points plus interactions a 3-D model compiled to native code may have: a 3-D
/// point is three axes of state and a 3-D link a few dozen operations, so fewer fit in
/// registers than in 1-D ([`super::MAX_ELEMENTS`]). The `ELEMENTS` script of
/// `tests/space_jit.rs` (10 points, 23 links of 17 laws) fits, and ran 1.4–1.8× as fast
/// natively as on the interpreter.
pub(crate) const MAX_SPACE_ELEMENTS: usize = 48;

/// The most links of one law a 3-D model compiled to native code may have, plus one. From
/// eight links of a law on, the interpreter evaluates that law eight links at a time on the
/// CPU's vectors (`space::links::apply_vector`, AVX-512), and the scalar native code loses:
/// on the build machine (AMD EPYC, AVX-512; one run each, loaded), 3-D chains of 3, 5 and 6
/// masses (4, 6 and 7 `springDamper`s) ran 2.2×, 2.4× and 1.2× as fast natively, chains of
/// 7, 10 and 16 masses (8, 11 and 17 links) 0.88×, 0.87× and 0.68× (`bench_small_3d_models_
/// native_against_the_interpreter`). On AVX2 the vector path starts at four links; the
/// crossover there is not measured.
pub(crate) const MAX_SPACE_GROUP: usize = 8;

/// Samples per trip round the loop, as in 1-D (`jit/emit.rs`).
const UNROLL: usize = 2;

/// What the code of a 3-D model was made for: the model and the lengths of the arrays it
/// indexes.
#[derive(Clone, Debug)]
pub(crate) struct Shape {
    model: Arc<SpaceModel>,
    lens: [usize; 8],
}

impl Shape {
    fn of(s: &Space) -> Shape {
        Shape {
            model: Arc::clone(&s.model),
            lens: lengths(s),
        }
    }

    /// Whether `s` runs the model the code was made for, with arrays of the same lengths.
    pub(crate) fn fits(&self, s: &Space) -> bool {
        Arc::ptr_eq(&self.model, &s.model) && lengths(s) == self.lens
    }
}

/// The lengths of the arrays of `s` the code reads by pointer: each axis's x, x̃ and F
/// (checked equal by [`fits`]), the coefficients, directions, P⊥, rest positions and the
/// microphones' weights and directions.
fn lengths(s: &Space) -> [usize; 8] {
    let axis = |p: &crate::sim::kernels::Points| {
        if p.xp.len() == p.x.len() && p.f.len() == p.x.len() {
            p.x.len()
        } else {
            usize::MAX
        }
    };
    [
        axis(&s.ax),
        axis(&s.ay),
        s.coef.len(),
        s.directions.units.len(),
        s.directions.perp.len(),
        s.rest.len(),
        s.mic_weights.len(),
        s.mic_dirs.len(),
    ]
}

/// Whether `e` is a 3-D model this compiles: no connection point, no audio-rate parameter,
/// small enough (in all and per law: [`MAX_SPACE_ELEMENTS`], [`MAX_SPACE_GROUP`]), every
/// index inside the arrays it reads.
pub(super) fn fits(e: &Parts<'_>) -> bool {
    let Some(s) = e.space else {
        return false;
    };
    let m = &*s.model;
    let n = m.len;
    let links: usize = m.groups.iter().map(|g| g.len()).sum();
    let inside = |p: u32| (p as usize) < n;
    let [ax, ay, coef, units, perp, rest, weights, dirs] = lengths(s);
    let z = &e.points;
    let dir = |d: u32| (d as usize) < units;
    let slots = e.args.len() as u64;
    e.model.audio_params.is_empty()
        && e.model.audio_bindings.is_empty()
        && m.audio_runs.is_empty()
        && m.audio_proxies.is_empty()
        && !m.audio_directions
        && m.proxies.is_empty()
        && n + links <= MAX_SPACE_ELEMENTS
        && m.groups.iter().all(|g| g.len() < MAX_SPACE_GROUP)
        && [ax, ay, z.x.len(), z.xp.len(), z.f.len()]
            .iter()
            .all(|&l| l == n)
        && coef == m.runs.len()
        && weights == dirs
        && m.groups.len() == SpaceLawKind::COUNT
        && m.runs.iter().all(|r| {
            r.first as usize + r.count as usize <= n && r.rest.is_none_or(|i| (i as usize) < rest)
        })
        && m.still.iter().all(|&p| inside(p))
        && m.avatars.iter().all(|a| match *a {
            Avatar::Line {
                point,
                dir: d,
                perp: q,
                ..
            } => inside(point) && dir(d) && (q as usize) < perp,
            Avatar::Xyz { point, .. } => inside(point),
        })
        && m.force_inputs.iter().all(|f| match *f {
            ForceInput::Line { point, dir: d, .. } => inside(point) && dir(d),
            ForceInput::Xyz { point, .. } => inside(point),
        })
        && m.outputs.iter().all(|o| match *o {
            Output3::Point { point, dir: d, .. } => inside(point) && dir(d),
            Output3::Distance { a, b, .. } => inside(a) && inside(b),
            Output3::Mic { mic, .. } => (mic as usize) < m.mics.len(),
        })
        && m.mics.iter().all(|mic| {
            mic.members.iter().all(|&p| inside(p))
                && mic.offset as usize + mic.members.len() <= weights
        })
        && SpaceLawKind::ALL.iter().all(|&kind| {
            let g = &m.groups[kind.index()];
            g.a.len() == g.b.len()
                && g.a.iter().chain(&g.b).all(|&p| inside(p))
                && g.segments.iter().all(|seg| {
                    let last = seg.len.saturating_sub(1) as u64;
                    seg.start as usize + seg.len as usize <= g.len()
                        && (0..kind.row().slots()).all(|c| {
                            seg.len == 0 || seg.base[c] as u64 + seg.step[c] as u64 * last < slots
                        })
                })
        })
}

/// Compiles the 3-D model of `e` (which [`fits`]); `None` if Cranelift refuses it.
pub(super) fn compile(e: &Parts<'_>) -> Option<NativeCode> {
    let s = e.space?;
    let (module, entry, size, ()) = define(|b, callees| {
        Emitter3::new(&s.model, b, callees).function();
    })?;
    Some(NativeCode {
        entry,
        plain: Vec::new(),
        unit: Vec::new(),
        points: e.points.x.len(),
        args: e.args.len(),
        singles: 0,
        space: Some(Shape::of(s)),
        size,
        module: Mutex::new(Some(module)),
    })
}

/// The state of every point on each axis (0 x, 1 y, 2 z) as variables of the function.
struct State3 {
    x: [Vec<Variable>; 3],
    xp: [Vec<Variable>; 3],
    f: [Vec<Variable>; 3],
}

/// What a sample reads besides the state: base pointers loaded at the function's entry.
struct Setup3 {
    args: Value,
    /// `Space::coef`, nine f64 per run (`RunCoef` in C layout).
    coef: Value,
    units: Value,
    perp: Value,
    rest: Value,
    mic_weights: Value,
    mic_dirs: Value,
    /// Per input and per output channel: (channel number, address of the call's first
    /// sample).
    inputs: Vec<(u32, Value)>,
    outputs: Vec<(u32, Value)>,
    /// The guard's bounds: `limit` and −`limit`.
    limit: Value,
    neg_limit: Value,
}

struct Emitter3<'a, 'b> {
    m: &'a SpaceModel,
    b: &'a mut FunctionBuilder<'b>,
    callees: Callees,
    frame: Value,
    state: State3,
}

impl<'a, 'b> Emitter3<'a, 'b> {
    fn new(m: &'a SpaceModel, b: &'a mut FunctionBuilder<'b>, callees: Callees) -> Self {
        let entry = b.create_block();
        b.append_block_params_for_function_params(entry);
        b.switch_to_block(entry);
        let frame = b.block_params(entry)[0];
        let n = m.len;
        let mut axes = || -> [Vec<Variable>; 3] {
            [0, 1, 2].map(|_| (0..n).map(|_| b.declare_var(types::F64)).collect())
        };
        let state = State3 {
            x: axes(),
            xp: axes(),
            f: axes(),
        };
        Emitter3 {
            m,
            b,
            callees,
            frame,
            state,
        }
    }

    /// A pointer-sized field of the frame at `offset`.
    fn field(&mut self, offset: usize) -> Value {
        self.b
            .ins()
            .load(types::I64, FLAGS, self.frame, offset as i32)
    }

    /// Element `i` of the f64 array at `base`.
    fn load(&mut self, base: Value, i: usize) -> Value {
        self.b.ins().load(types::F64, FLAGS, base, (8 * i) as i32)
    }

    /// The base pointers of axis `c`'s x, x̃ and F: the frame's `axes` for x and y, its
    /// `x`, `xp`, `f` for z.
    fn axis_arrays(&mut self, c: usize) -> [Value; 3] {
        if c == 2 {
            return [
                self.field(offset_of!(Frame, x)),
                self.field(offset_of!(Frame, xp)),
                self.field(offset_of!(Frame, f)),
            ];
        }
        let axes = offset_of!(Frame, axes) + 3 * 8 * c;
        [0, 1, 2].map(|k| self.field(axes + 8 * k))
    }

    fn function(mut self) {
        let m = self.m;
        let n = m.len;
        let entry = self.b.current_block().expect("the entry block");
        let (start, end) = (self.b.block_params(entry)[1], self.b.block_params(entry)[2]);
        let arrays = [0, 1, 2].map(|c| self.axis_arrays(c));
        for (c, [x, xp, f]) in arrays.into_iter().enumerate() {
            for p in 0..n {
                let (vx, vxp, vf) = (self.load(x, p), self.load(xp, p), self.load(f, p));
                self.b.def_var(self.state.x[c][p], vx);
                self.b.def_var(self.state.xp[c][p], vxp);
                self.b.def_var(self.state.f[c][p], vf);
            }
        }
        let mut fields = |offset| self.field(offset);
        let (args, coef, units, perp, rest, mic_weights, mic_dirs) = (
            fields(offset_of!(Frame, args)),
            fields(offset_of!(Frame, coef)),
            fields(offset_of!(Frame, units)),
            fields(offset_of!(Frame, perp)),
            fields(offset_of!(Frame, rest)),
            fields(offset_of!(Frame, mic_weights)),
            fields(offset_of!(Frame, mic_dirs)),
        );
        let input_numbers = sorted_unique(
            m.avatars
                .iter()
                .flat_map(|a| match *a {
                    Avatar::Line { channel, .. } => channel..channel + 1,
                    Avatar::Xyz { channel, .. } => channel..channel + 3,
                })
                .chain(m.force_inputs.iter().flat_map(|f| match *f {
                    ForceInput::Line { channel, .. } => channel..channel + 1,
                    ForceInput::Xyz { channel, .. } => channel..channel + 3,
                })),
        );
        let output_numbers = sorted_unique(m.outputs.iter().map(Output3::channel));
        let inputs = channels(self.b, self.frame, &input_numbers, start, true);
        let outputs = channels(self.b, self.frame, &output_numbers, start, false);
        let limit = self.b.ins().load(
            types::F64,
            FLAGS,
            self.frame,
            offset_of!(Frame, limit) as i32,
        );
        let neg_limit = self.b.ins().fneg(limit);
        let setup = Setup3 {
            args,
            coef,
            units,
            perp,
            rest,
            mic_weights,
            mic_dirs,
            inputs,
            outputs,
            limit,
            neg_limit,
        };

        let header = self.b.create_block();
        let exit = self.b.create_block();
        let bad = self.b.create_block();
        let bad_k = self.b.append_block_param(bad, types::I64);
        self.b.set_cold_block(bad);
        let count = self.b.ins().isub(end, start);
        let j_var = self.b.declare_var(types::I64);
        let zero = self.b.ins().iconst(types::I64, 0);
        self.b.def_var(j_var, zero);
        self.b.ins().jump(header, &[]);
        self.b.seal_block(entry);

        self.b.switch_to_block(header);
        let mut j = self.b.use_var(j_var);
        for copy in 0..UNROLL {
            let go_on = self.b.create_block();
            let done = self.b.ins().icmp(IntCC::SignedGreaterThanOrEqual, j, count);
            self.b.ins().brif(done, exit, &[], go_on, &[]);
            self.b.seal_block(go_on);
            self.b.switch_to_block(go_on);
            let k = self.b.ins().iadd(start, j);
            self.sample(k, j, &setup, bad);
            j = self.b.ins().iadd_imm(j, 1);
            self.b.def_var(j_var, j);
            if copy + 1 == UNROLL {
                self.b.ins().jump(header, &[]);
            }
        }
        self.b.seal_block(header);
        self.b.seal_block(exit);
        self.b.seal_block(bad);

        // `bad`: the guard rejected sample k's outputs; the state is as after it.
        self.b.switch_to_block(bad);
        self.store_state(&arrays);
        self.b.ins().return_(&[bad_k]);

        self.b.switch_to_block(exit);
        self.store_state(&arrays);
        self.b.ins().return_(&[end]);
    }

    fn store_state(&mut self, arrays: &[[Value; 3]; 3]) {
        for (c, &[x, xp, f]) in arrays.iter().enumerate() {
            for p in 0..self.m.len {
                for (var, base) in [
                    (self.state.x[c][p], x),
                    (self.state.xp[c][p], xp),
                    (self.state.f[c][p], f),
                ] {
                    let v = self.b.use_var(var);
                    self.b.ins().store(FLAGS, v, base, (8 * p) as i32);
                }
            }
        }
    }

    /// Leaves for `bad` with `k` unless `ok` holds.
    fn guard(&mut self, ok: Value, bad: Block, k: Value) {
        let go_on = self.b.create_block();
        self.b.ins().brif(ok, go_on, &[], bad, &[k.into()]);
        self.b.seal_block(go_on);
        self.b.switch_to_block(go_on);
    }
}

#[cfg(test)]
mod tests {
    use crate::{compile, parse, CompileOptions};

    /// States no script starts from but a blow-up can leave (−0, NaN and infinite positions,
    /// delayed positions and forces, huge values), poked into each axis of both engines: the
    /// native code still gives the interpreter's bits, NaNs included, and trips the guard at
    /// the same sample.
    #[test]
    fn odd_3d_states_give_the_interpreter_bits() {
        let text = "~dim 3\n@g ground [0 0 0]\n@m mass 1. [0.1 0 0.2] [0 0 0]\n\
                    @n osc 2. 0.01 0.001 [1 0 0] [0 0 0]\n@z massZ 1. [0 1 0] [0 0 0]\n\
                    @l springDamper @g @m 0.1 0.001 auto\n@j contact @m @n 0.1 0.001 1.\n\
                    @k nlBow @n @z 0.005 0.0001 1\n@in1 frcInputXYZ @m\n\
                    @out1 posOutput @n [0 1 0]\n@out2 frcOutput @g\n@out3 velOutput @z\n";
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
        let values = [-0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300];
        let mut input = vec![0.0; 24];
        input[3] = 0.01;
        for axis in 0..3 {
            for point in 0..native.points.x.len() {
                for array in 0..3 {
                    for &value in &values {
                        let (mut a, mut b) = (native.clone(), interpreted.clone());
                        for e in [&mut a, &mut b] {
                            let space = e.space.as_deref_mut().expect("a 3-D model");
                            let p = match axis {
                                0 => &mut space.ax,
                                1 => &mut space.ay,
                                _ => &mut e.points,
                            };
                            [&mut p.x, &mut p.xp, &mut p.f][array][point] = value;
                        }
                        let (mut oa, mut ob) = (vec![0.0; 24], vec![0.0; 24]);
                        let ra = a.process(8, &input, &mut oa);
                        let rb = b.process(8, &input, &mut ob);
                        let at = format!("axis {axis}, point {point}, array {array}, {value:e}");
                        assert_eq!(bits(&oa), bits(&ob), "{at}");
                        assert_eq!(ra, rb, "{at}");
                        assert_eq!(a.guard, b.guard, "{at}");
                        for c in 0..3 {
                            for k in 0..3 {
                                assert_eq!(
                                    bits(a.axis_state(c)[k]),
                                    bits(b.axis_state(c)[k]),
                                    "{at}: axis {c}, array {k}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}
