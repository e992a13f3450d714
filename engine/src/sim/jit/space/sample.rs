//! One sample of a 3-D model's generated function: stages 1 a, 2, 4 and 6 of 3-D spec §1.5
//! with the scalar engine's IEEE operations in its order, stage by stage the code of
//! `sim/space/` it mirrors (no connection points: stages 3 and 5 have nothing to do).

use super::super::arith::Ir;
use super::{Emitter3, Setup3};
use crate::laws::space::{Ends, SpaceLawKind};
use crate::sim::space::{Avatar, ForceInput, Output3, Probe3, RunCoef};
use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{types, Block, InstBuilder, Value};
use std::mem::{offset_of, size_of};

/// A run's coefficient at byte `offset` of its [`RunCoef`], as an index into `Space::coef`
/// read as f64s.
fn coef_index(run: usize, offset: usize) -> usize {
    (run * size_of::<RunCoef>() + offset) / 8
}

impl Emitter3<'_, '_> {
    /// Sample `k` of the block, the `j`-th of the call. Leaves for `bad` (with `k`) when the
    /// guard rejects an output.
    pub(super) fn sample(&mut self, k: Value, j: Value, setup: &Setup3, bad: Block) {
        let offset = self.b.ins().ishl_imm(j, 3);
        let zero = self.b.ins().f64const(0.0);
        // Each input channel is read once; a non-finite sample reads as +0 (`Engine::sample`'s
        // `input`), a channel the block does not have reads the frame's zeros.
        let mut read = Vec::with_capacity(setup.inputs.len());
        for &(channel, base) in &setup.inputs {
            let at = self.b.ins().iadd(base, offset);
            let v = self.b.ins().load(types::F64, super::FLAGS, at, 0);
            let d = self.b.ins().fsub(v, v);
            let finite = self.b.ins().fcmp(FloatCC::Ordered, d, d);
            read.push((channel, self.b.ins().select(finite, v, zero)));
        }
        let input = |ch: u32| read.iter().find(|r| r.0 == ch).map_or(zero, |r| r.1);

        self.avatars(setup, &input, zero);
        self.masses(setup, zero);
        self.links(setup);
        self.force_inputs(setup, &input);
        self.outputs(k, offset, setup, bad);
    }

    /// Component `c` of unit direction `dir` (`Directions::units`).
    fn unit(&mut self, setup: &Setup3, dir: u32, c: usize) -> Value {
        self.load(setup.units, 3 * dir as usize + c)
    }

    /// Stage 1 a (`space::io::avatars`, 3-D spec §3.1): x̃ ← x, x ← P⊥ + in·â (`posInput`)
    /// or (in_N, in_N+1, in_N+2) (`posInputXYZ`), F ← 0.
    fn avatars(&mut self, setup: &Setup3, input: &impl Fn(u32) -> Value, zero: Value) {
        for av in &self.m.avatars {
            let (point, target) = match *av {
                Avatar::Line {
                    point,
                    channel,
                    dir,
                    perp,
                } => {
                    let s = input(channel);
                    let target = [0, 1, 2].map(|c| {
                        let a = self.unit(setup, dir, c);
                        let p = self.load(setup.perp, 3 * perp as usize + c);
                        let along = self.b.ins().fmul(s, a);
                        self.b.ins().fadd(p, along)
                    });
                    (point, target)
                }
                Avatar::Xyz { point, channel } => (
                    point,
                    [input(channel), input(channel + 1), input(channel + 2)],
                ),
            };
            let p = point as usize;
            for (c, v) in target.into_iter().enumerate() {
                let old = self.b.use_var(self.state.x[c][p]);
                self.b.def_var(self.state.xp[c][p], old);
                self.b.def_var(self.state.x[c][p], v);
                self.b.def_var(self.state.f[c][p], zero);
            }
        }
    }

    /// Stage 2 (`space::masses::step`, 3-D spec §2.1): every run in script order, on each
    /// free axis c, Y_new = ((A·Y) − (B·Ỹ)) + (F + G)·(1/M) + a with Y = x − P_rest (an
    /// `osc`; Y = x otherwise), x̃ ← x, x ← Y_new (+ P_rest), F ← 0; on a locked axis F ← 0
    /// alone. Then the still points' F ← 0. (The interpreter updates merged runs as one loop,
    /// [`masses::merge`](crate::sim::space::masses::merge): the same operations on the same
    /// values, each point's update reading its own state only.)
    fn masses(&mut self, setup: &Setup3, zero: Value) {
        let m = self.m;
        for (i, run) in m.runs.iter().enumerate() {
            let points = run.first as usize..(run.first + run.count) as usize;
            for c in 0..3 {
                if !run.axes[c] {
                    for p in points.clone() {
                        self.b.def_var(self.state.f[c][p], zero);
                    }
                    continue;
                }
                let mut coef = |offset| self.load(setup.coef, coef_index(i, offset));
                let (a, b, inv_m, g, acc) = (
                    coef(offset_of!(RunCoef, a)),
                    coef(offset_of!(RunCoef, b)),
                    coef(offset_of!(RunCoef, inv_m)),
                    coef(offset_of!(RunCoef, g) + 8 * c),
                    coef(offset_of!(RunCoef, acc) + 8 * c),
                );
                let at = run.rest.map(|r| self.load(setup.rest, 3 * r as usize + c));
                for p in points.clone() {
                    let x = self.b.use_var(self.state.x[c][p]);
                    let xp = self.b.use_var(self.state.xp[c][p]);
                    let f = self.b.use_var(self.state.f[c][p]);
                    let (y, yp) = match at {
                        Some(at) => (self.b.ins().fsub(x, at), self.b.ins().fsub(xp, at)),
                        None => (x, xp),
                    };
                    let ay = self.b.ins().fmul(a, y);
                    let byp = self.b.ins().fmul(b, yp);
                    let inertia = self.b.ins().fsub(ay, byp);
                    let net = self.b.ins().fadd(f, g);
                    let push = self.b.ins().fmul(net, inv_m);
                    let moved = self.b.ins().fadd(inertia, push);
                    let mut next = self.b.ins().fadd(moved, acc);
                    if let Some(at) = at {
                        next = self.b.ins().fadd(next, at);
                    }
                    self.b.def_var(self.state.xp[c][p], x);
                    self.b.def_var(self.state.x[c][p], next);
                    self.b.def_var(self.state.f[c][p], zero);
                }
            }
        }
        for &p in &m.still {
            for c in 0..3 {
                self.b.def_var(self.state.f[c][p as usize], zero);
            }
        }
    }

    /// Stage 4's interactions (`space::links`, 3-D spec §1.5, §2.2–§2.5): every group in
    /// table order, every segment's links in order, argument slot c of link i at
    /// `base[c] + step[c]·i`; g by the law's one source on [`Ir`], then F₁ −= g and, for a
    /// two-endpoint law, F₂ += g, axis by axis (the vector path of the interpreter gives the
    /// same bits: `links::apply_vector`).
    fn links(&mut self, setup: &Setup3) {
        let m = self.m;
        for kind in SpaceLawKind::ALL {
            let g = &m.groups[kind.index()];
            let row = kind.row();
            for seg in &g.segments {
                for i in 0..seg.len {
                    let l = (seg.start + i) as usize;
                    let (a, b) = (g.a[l] as usize, g.b[l] as usize);
                    let args: Vec<Value> = (0..row.slots())
                        .map(|c| {
                            let slot = seg.base[c] + seg.step[c] * i;
                            self.load(setup.args, slot as usize)
                        })
                        .collect();
                    let mut at = |p: usize| {
                        [0, 1, 2].map(|c| {
                            (
                                self.b.use_var(self.state.x[c][p]),
                                self.b.use_var(self.state.xp[c][p]),
                            )
                        })
                    };
                    let (one, two) = (at(a), at(b));
                    let ends = Ends {
                        x1: one.map(|v| v.0),
                        xp1: one.map(|v| v.1),
                        x2: two.map(|v| v.0),
                        xp2: two.map(|v| v.1),
                    };
                    let force = kind.force(&Ir::new(self.b, self.callees), &ends, &args);
                    for (c, &gc) in force.iter().enumerate() {
                        let fa = self.b.use_var(self.state.f[c][a]);
                        let fa = self.b.ins().fsub(fa, gc);
                        self.b.def_var(self.state.f[c][a], fa);
                    }
                    if row.endpoints != 1 {
                        for (c, &gc) in force.iter().enumerate() {
                            let fb = self.b.use_var(self.state.f[c][b]);
                            let fb = self.b.ins().fadd(fb, gc);
                            self.b.def_var(self.state.f[c][b], fb);
                        }
                    }
                }
            }
        }
    }

    /// Stage 4's force inputs (`space::io::force_inputs`, 3-D spec §3.2), after the
    /// interactions: F += in·â (`frcInput`) or (in_N, in_N+1, in_N+2) (`frcInputXYZ`).
    fn force_inputs(&mut self, setup: &Setup3, input: &impl Fn(u32) -> Value) {
        for fi in &self.m.force_inputs {
            let (point, force) = match *fi {
                ForceInput::Line {
                    point,
                    channel,
                    dir,
                } => {
                    let s = input(channel);
                    let force = [0, 1, 2].map(|c| {
                        let a = self.unit(setup, dir, c);
                        self.b.ins().fmul(s, a)
                    });
                    (point, force)
                }
                ForceInput::Xyz { point, channel } => (
                    point,
                    [input(channel), input(channel + 1), input(channel + 2)],
                ),
            };
            let p = point as usize;
            for (c, v) in force.into_iter().enumerate() {
                let f = self.b.use_var(self.state.f[c][p]);
                let f = self.b.ins().fadd(f, v);
                self.b.def_var(self.state.f[c][p], f);
            }
        }
    }

    /// u·v = (u_x v_x + u_y v_y) + u_z v_z, as `space::io::dot`.
    fn dot(&mut self, u: [Value; 3], v: [Value; 3]) -> Value {
        let xx = self.b.ins().fmul(u[0], v[0]);
        let yy = self.b.ins().fmul(u[1], v[1]);
        let zz = self.b.ins().fmul(u[2], v[2]);
        let xy = self.b.ins().fadd(xx, yy);
        self.b.ins().fadd(xy, zz)
    }

    /// Point `p`'s velocity x − x̃ on each axis.
    fn velocity(&mut self, p: usize) -> [Value; 3] {
        [0, 1, 2].map(|c| {
            let x = self.b.use_var(self.state.x[c][p]);
            let xp = self.b.use_var(self.state.xp[c][p]);
            self.b.ins().fsub(x, xp)
        })
    }

    /// Stage 6 (`space::io::output`, 3-D spec §3.3, §3.4): writes sample `k` of every output
    /// in script order, then leaves for `bad` with `k` when one fails the guard: |v| ≤ limit,
    /// tested as −limit ≤ v ≤ limit (a NaN fails both).
    fn outputs(&mut self, k: Value, offset: Value, setup: &Setup3, bad: Block) {
        let m = self.m;
        let mut values = Vec::with_capacity(m.outputs.len());
        for o in &m.outputs {
            let v = match *o {
                Output3::Point {
                    probe, point, dir, ..
                } => {
                    let p = point as usize;
                    let v = match probe {
                        Probe3::Position => [0, 1, 2].map(|c| self.b.use_var(self.state.x[c][p])),
                        Probe3::Force => [0, 1, 2].map(|c| self.b.use_var(self.state.f[c][p])),
                        Probe3::Velocity => self.velocity(p),
                    };
                    let u = [0, 1, 2].map(|c| self.unit(setup, dir, c));
                    self.dot(v, u)
                }
                Output3::Distance { a, b, .. } => {
                    let d = [0, 1, 2].map(|c| {
                        let xa = self.b.use_var(self.state.x[c][a as usize]);
                        let xb = self.b.use_var(self.state.x[c][b as usize]);
                        self.b.ins().fsub(xa, xb)
                    });
                    let q = self.dot(d, d);
                    self.b.ins().sqrt(q)
                }
                Output3::Mic { mic, .. } => {
                    let mic = &m.mics[mic as usize];
                    let mut sum = self.b.ins().f64const(0.0);
                    for (j, &p) in mic.members.iter().enumerate() {
                        let at = mic.offset as usize + j;
                        let v = self.velocity(p as usize);
                        let e = [0, 1, 2].map(|c| self.load(setup.mic_dirs, 3 * at + c));
                        let w = self.load(setup.mic_weights, at);
                        let along = self.dot(v, e);
                        let term = self.b.ins().fmul(w, along);
                        sum = self.b.ins().fadd(sum, term);
                    }
                    sum
                }
            };
            values.push((o.channel(), v));
        }
        for &(channel, v) in &values {
            let base = setup
                .outputs
                .iter()
                .find(|o| o.0 == channel)
                .expect("every output's channel has an address")
                .1;
            let at = self.b.ins().iadd(base, offset);
            self.b.ins().store(super::FLAGS, v, at, 0);
        }
        for &(_, v) in &values {
            for (cc, bound) in [
                (FloatCC::LessThanOrEqual, setup.limit),
                (FloatCC::GreaterThanOrEqual, setup.neg_limit),
            ] {
                let within = self.b.ins().fcmp(cc, v, bound);
                self.guard(within, bad, k);
            }
        }
    }
}
