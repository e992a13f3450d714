//! One sample of the generated function: stages 1 a, 2 a, 4 and 6 of spec §1.5 with the
//! interpreter's IEEE operations in its order (`Engine::step`, `Engine::write_outputs`).
//!
//! Where an operation is an identity for the values a sample almost always has, the code
//! takes the identity and leaves the operation off the chain of dependent operations that
//! bounds a small model's sample:
//! - the first force a point receives is added to +0, and +0 ± c is ±c unless c is a zero or
//!   a NaN (the operation itself runs on a cold block, [`Emitter::unless`]);
//! - F + in is F for a silent input (in = +0; F is never −0);
//! - a ground's X[n+1] = (1·X + 0·X̃) + (F − 0)·0 is X while X is not −0 and X, X̃, F are
//!   finite.
//!
//! States the code does not handle at all (a non-finite input, a non-finite force on a
//! ground) are tested before the sample changes anything; they leave it for its bail-out
//! block, which stores the state, and the driver runs that sample on the interpreter.

use super::arith;
use super::emit::{Emitter, Setup, FLAGS};
use super::BAIL;
use cranelift_codegen::ir::condcodes::{FloatCC, IntCC};
use cranelift_codegen::ir::{types, Block, InstBuilder, MemFlags, Value};

impl Emitter<'_, '_> {
    /// Sample `k` of the block, the `j`-th of the call. Leaves for `bad` (with `k`) when the
    /// guard rejects an output; `arrays` are the state's base pointers, for the bail-out.
    pub(super) fn sample(
        &mut self,
        k: Value,
        j: Value,
        setup: &Setup,
        bad: Block,
        arrays: (Value, Value, Value),
    ) {
        let e = self.e;
        let bail = self.b.create_block();
        self.b.set_cold_block(bail);
        self.bail = Some(bail);
        let offset = self.b.ins().ishl_imm(j, 3);

        // The states the code does not handle are all seen here, before the sample changes
        // anything, so the bail-out stores the state as it stands. Each input channel is
        // read once; the interpreter, which runs a sample with a non-finite input, reads it
        // as 0. A ground's update needs its force to be finite (see `Emitter::ground`).
        let mut read = Vec::with_capacity(setup.inputs.len());
        for &(channel, base) in &setup.inputs {
            let at = self.b.ins().iadd(base, offset);
            let v = self.b.ins().load(types::F64, FLAGS, at, 0);
            let finite = self.finite(v);
            self.bail_unless(finite);
            read.push((channel, v));
        }
        for i in (0..e.singles.len()).filter(|&i| e.singles.fixed[i]) {
            let f = self.b.use_var(self.state.f[i]);
            let finite = self.finite(f);
            self.bail_unless(finite);
        }
        let zero = self.constant(0.0);
        let input = |ch: u32| read.iter().find(|r| r.0 == ch).map_or(zero, |r| r.1);

        // Stage 1 a: avatars take their input; their force is cleared.
        for r in &e.model.avatars {
            let p = r.index as usize;
            let old = self.b.use_var(self.state.x[p]);
            self.b.def_var(self.state.xp[p], old);
            self.b.def_var(self.state.x[p], input(r.channel));
            self.b.def_var(self.state.f[p], zero);
        }
        self.masses(setup, zero);
        let mut touched = self.links(setup);
        // F + in is F when in is +0 (F is never −0), which a silent input usually is.
        for r in &e.model.force_inputs {
            let p = r.index as usize;
            let v = input(r.channel);
            let f = self.b.use_var(self.state.f[p]);
            let f = if touched[p] {
                let bits = self.b.ins().bitcast(types::I64, MemFlags::new(), v);
                let silent = self.b.ins().icmp_imm(IntCC::Equal, bits, 0);
                self.unless(silent, &[f], |me| vec![me.b.ins().fadd(f, v)])[0]
            } else {
                touched[p] = true;
                self.b.ins().fadd(f, v)
            };
            self.b.def_var(self.state.f[p], f);
        }
        self.outputs(k, offset, setup, bad);

        // The sample goes on in a block of its own (a model without outputs has not started
        // one), so the bail-out can be filled now: the state as before the sample.
        let next = self.b.create_block();
        self.b.ins().jump(next, &[]);
        self.b.seal_block(next);
        self.b.seal_block(bail);
        self.b.switch_to_block(bail);
        let (x, xp, f) = arrays;
        self.store_state(x, xp, f);
        let bailed = self.b.ins().bor_imm(k, BAIL);
        self.b.ins().return_(&[bailed]);
        self.b.switch_to_block(next);
    }

    /// Stage 2 a: single masses (`kernels::masses`): plain X[n+1] = (2·X − X̃) + F·(1/M),
    /// general a·X + b·X̃ + (F − g)·(1/M), grounds as [`Emitter::ground`].
    fn masses(&mut self, setup: &Setup, zero: Value) {
        let e = self.e;
        let [a, b, inv_m, g] = setup.arrays;
        for i in 0..e.singles.len() {
            let x = self.b.use_var(self.state.x[i]);
            let xp = self.b.use_var(self.state.xp[i]);
            let f = self.b.use_var(self.state.f[i]);
            let next = if e.singles.fixed[i] {
                self.ground(x)
            } else if setup.masses.plain[i] {
                // 2·X, as X + X (the same value, no constant to load).
                let two_x = self.b.ins().fadd(x, x);
                let inertia = self.b.ins().fsub(two_x, xp);
                // F·1 is F: a unit mass leaves the multiplication out of the chain.
                let push = if setup.masses.unit[i] {
                    f
                } else {
                    let inv_m = self.load(inv_m, i);
                    self.b.ins().fmul(f, inv_m)
                };
                self.b.ins().fadd(inertia, push)
            } else {
                let (a, b, inv_m, g) = (
                    self.load(a, i),
                    self.load(b, i),
                    self.load(inv_m, i),
                    self.load(g, i),
                );
                let ax = self.b.ins().fmul(a, x);
                let bxp = self.b.ins().fmul(b, xp);
                let inertia = self.b.ins().fadd(ax, bxp);
                let net = self.b.ins().fsub(f, g);
                let push = self.b.ins().fmul(net, inv_m);
                self.b.ins().fadd(inertia, push)
            };
            self.b.def_var(self.state.xp[i], x);
            self.b.def_var(self.state.x[i], next);
            self.b.def_var(self.state.f[i], zero);
        }
    }

    /// Stage 4's links: every link of every group in list order (the interpreter's bands
    /// give the link-by-link scatter's bits), F₁ −= f, F₂ += f. Returns which points
    /// received a force.
    fn links(&mut self, setup: &Setup) -> Vec<bool> {
        let e = self.e;
        // Whether a point's F has received a force yet in this sample (it is +0 until then).
        let mut touched = vec![false; e.points.x.len()];
        for (law, g) in super::emit::groups(e) {
            for i in 0..g.len() {
                let (pa, pb) = (g.a[i] as usize, g.b[i] as usize);
                let (xa, xpa) = (
                    self.b.use_var(self.state.x[pa]),
                    self.b.use_var(self.state.xp[pa]),
                );
                let (xb, xpb) = (
                    self.b.use_var(self.state.x[pb]),
                    self.b.use_var(self.state.xp[pb]),
                );
                let dx = self.b.ins().fsub(xa, xb);
                let va = self.b.ins().fsub(xa, xpa);
                let vb = self.b.ins().fsub(xb, xpb);
                let dv = self.b.ins().fsub(va, vb);
                let args: Vec<Value> = (0..law.arity())
                    .map(|c| self.load(setup.args, g.cols[c] + i))
                    .collect();
                let force = arith::emit(self.b, law, dx, dv, &args, self.callees);
                self.link_forces(pa, pb, force, setup.sign, &mut touched);
            }
        }
        touched
    }

    /// F[a] −= c, then F[b] += c, the interpreter's operations. A point's first force in a
    /// sample is added to +0, and +0 ± c is ±c unless c is a zero or a NaN, so the usual path
    /// takes ±c (−c by flipping the sign bit) and a cold block does +0 ± c; one test of c
    /// serves both ends.
    fn link_forces(&mut self, a: usize, b: usize, c: Value, sign: Value, touched: &mut [bool]) {
        let first = [!touched[a], a != b && !touched[b]];
        touched[a] = true;
        touched[b] = true;
        let (fa, fb) = (
            self.b.use_var(self.state.f[a]),
            self.b.use_var(self.state.f[b]),
        );
        if first == [false, false] {
            let fa = self.b.ins().fsub(fa, c);
            self.b.def_var(self.state.f[a], fa);
            let fb = if a == b { fa } else { fb };
            let fb = self.b.ins().fadd(fb, c);
            self.b.def_var(self.state.f[b], fb);
            return;
        }
        let zero = self.constant(0.0);
        let ordinary = self.b.ins().fcmp(FloatCC::OrderedNotEqual, c, zero);
        let minus_c = self.b.ins().bxor(c, sign);
        let fast = [
            if first[0] {
                minus_c
            } else {
                self.b.ins().fsub(fa, c)
            },
            if first[1] {
                c
            } else if a == b {
                zero // unused: a self-link's second end is its first
            } else {
                self.b.ins().fadd(fb, c)
            },
        ];
        let [new_a, new_b] = self.unless(ordinary, &fast, |me| {
            let zero = me.constant(0.0);
            let new_a = me.b.ins().fsub(if first[0] { zero } else { fa }, c);
            let new_b = if a == b {
                zero
            } else {
                me.b.ins().fadd(if first[1] { zero } else { fb }, c)
            };
            vec![new_a, new_b]
        })[..] else {
            unreachable!("two values")
        };
        self.b.def_var(self.state.f[a], new_a);
        if a == b {
            // F[a] was first: +0 − c, then + c.
            let f = self.b.ins().fadd(new_a, c);
            self.b.def_var(self.state.f[a], f);
        } else {
            self.b.def_var(self.state.f[b], new_b);
        }
    }

    /// Stage 6: writes sample `k` of every output, in `Engine::write_outputs`' order
    /// (positions, then forces summed from −0 as `Iterator::sum` does), and leaves for `bad`
    /// with `k` when one fails the guard: |v| ≤ limit, tested as −limit ≤ v ≤ limit.
    fn outputs(&mut self, k: Value, offset: Value, setup: &Setup, bad: Block) {
        let e = self.e;
        let mut values = Vec::new();
        for r in &e.model.pos_outputs {
            values.push((r.channel, self.b.use_var(self.state.x[r.index as usize])));
        }
        for &(channel, start, len) in &e.model.frc_outputs {
            let mut total = self.constant(-0.0);
            for &p in &e.model.frc_sources[start as usize..(start + len) as usize] {
                let f = self.b.use_var(self.state.f[p as usize]);
                total = self.b.ins().fadd(total, f);
            }
            values.push((channel, total));
        }
        for &(channel, v) in &values {
            let base = setup
                .outputs
                .iter()
                .find(|o| o.0 == channel)
                .expect("every output's channel has an address")
                .1;
            let at = self.b.ins().iadd(base, offset);
            self.b.ins().store(FLAGS, v, at, 0);
        }
        for &(_, v) in &values {
            for (cc, bound) in [
                (FloatCC::LessThanOrEqual, setup.limit),
                (FloatCC::GreaterThanOrEqual, setup.neg_limit),
            ] {
                let within = self.b.ins().fcmp(cc, v, bound);
                let go_on = self.b.create_block();
                self.b.ins().brif(within, go_on, &[], bad, &[k.into()]);
                self.b.seal_block(go_on);
                self.b.switch_to_block(go_on);
            }
        }
    }

    /// `fast` when `usual` holds, else what `slow` computes, on a cold block of its own: the
    /// same values as a `select`, but the sample's usual path neither computes the slow values
    /// nor waits for them (the branch is predicted).
    pub(super) fn unless(
        &mut self,
        usual: Value,
        fast: &[Value],
        slow: impl FnOnce(&mut Self) -> Vec<Value>,
    ) -> Vec<Value> {
        let cold = self.b.create_block();
        let join = self.b.create_block();
        let results: Vec<Value> = fast
            .iter()
            .map(|_| self.b.append_block_param(join, types::F64))
            .collect();
        self.b.set_cold_block(cold);
        let args: Vec<_> = fast.iter().map(|&v| v.into()).collect();
        self.b.ins().brif(usual, join, &args, cold, &[]);
        self.b.seal_block(cold);
        self.b.switch_to_block(cold);
        let values = slow(self);
        let args: Vec<_> = values.iter().map(|&v| v.into()).collect();
        self.b.ins().jump(join, &args);
        self.b.seal_block(join);
        self.b.switch_to_block(join);
        results
    }

    /// Whether `v` is finite: v − v is +0 for a finite v and NaN otherwise.
    pub(super) fn finite(&mut self, v: Value) -> Value {
        let d = self.b.ins().fsub(v, v);
        self.b.ins().fcmp(FloatCC::Ordered, d, d)
    }

    /// Leaves the sample for its bail-out block unless `usual` holds.
    fn bail_unless(&mut self, usual: Value) {
        let bail = self.bail.expect("inside a sample");
        let go_on = self.b.create_block();
        self.b.ins().brif(usual, go_on, &[], bail, &[]);
        self.b.seal_block(go_on);
        self.b.switch_to_block(go_on);
    }

    /// A ground's update, the general one with its constant coefficients (a, b, 1/M, g) =
    /// (1, 0, 0, 0): X[n+1] = (1·X + 0·X̃) + (F − 0)·0. That is X itself when X is not −0 and
    /// X, X̃ and F are finite (the products are zeros, and X + ±0 = X). The function checks X
    /// and X̃ on entry, and they stay as they are while it runs; the sample checked F before
    /// it began.
    fn ground(&mut self, x: Value) -> Value {
        x
    }
}
