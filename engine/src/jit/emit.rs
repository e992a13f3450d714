//! The generated function of [`super::NativeCode`]: a loop over samples whose body is the
//! model, point by point and link by link, in the interpreter's order.
//!
//! ```text
//! entry:  load the state (x, x̃, F of every point), the mass coefficients and the link
//!         arguments; per input and output channel, its buffer and stride
//! header: k = end? → exit
//! body:   stage 1 a (avatars), 2 a (single masses), 4 (links, then force inputs),
//!         6 (outputs and their guard) → header with k + 1, or → bad
//! bad:    store the state, return k        exit: store the state, return end
//! ```

use super::laws::{self, Callees, Law};
use super::{Frame, NativeCode, MAX_LINKS, MAX_POINTS};
use crate::engine::Engine;
use crate::kernels::links::Group;
use cranelift_codegen::ir::condcodes::{FloatCC, IntCC};
use cranelift_codegen::ir::{
    types, AbiParam, InstBuilder, MemFlags, Signature, UserFuncName, Value,
};
use cranelift_codegen::Context;
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext, Variable};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{default_libcall_names, Linkage, Module};
use std::mem::offset_of;
use std::sync::Mutex;

/// The groups of the engine's stage 4, in their order, with their laws.
fn groups(engine: &Engine) -> [(Law, &Group); 8] {
    let i = &engine.interactions;
    [
        (Law::SpringDamper, &i.linear),
        (Law::Contact, &i.contact),
        (Law::NlContact, &i.nl_contact),
        (Law::NlSpring2, &i.nl_spring2),
        (Law::NlSpring3, &i.nl_spring3),
        (Law::NlSpringDamper, &i.nl_spring_damper),
        (Law::Pluck, &i.pluck),
        (Law::Bow, &i.bow),
    ]
}

/// Whether `engine` is a model this compiles: single masses, avatars and links only, no
/// audio-rate parameter, small enough, every index inside the state.
pub(super) fn fits(engine: &Engine) -> bool {
    let n = engine.points.x.len();
    let links: usize = groups(engine).iter().map(|(_, g)| g.len()).sum();
    let inside = |p: u32| (p as usize) < n;
    let m = &engine.macros;
    m.lines.is_empty()
        && m.stiff.is_empty()
        && m.meshes.is_empty()
        && engine.proxies.len() == 0
        && engine.audio_params.is_empty()
        && engine.audio_bindings.is_empty()
        && n <= MAX_POINTS
        && links <= MAX_LINKS
        && n == engine.singles.len() + engine.avatars.len()
        && engine
            .avatars
            .iter()
            .all(|r| r.index as usize >= engine.singles.len() && inside(r.index))
        && engine.force_inputs.iter().all(|r| inside(r.index))
        && engine.pos_outputs.iter().all(|r| inside(r.index))
        && engine.frc_sources.iter().all(|&p| inside(p))
        && engine
            .frc_outputs
            .iter()
            .all(|&(_, start, len)| (start + len) as usize <= engine.frc_sources.len())
        && groups(engine).iter().all(|(law, g)| {
            g.cols.len() == law.arity()
                && g.a.iter().chain(&g.b).all(|&p| inside(p))
                && g.cols.iter().all(|&c| c + g.len() <= engine.args.len())
        })
        && engine
            .singles
            .cols
            .iter()
            .all(|&c| c + engine.singles.len() <= engine.args.len())
}

/// Compiles `engine` (which [`fits`]); `None` if Cranelift refuses it.
pub(super) fn compile(engine: &Engine) -> Option<NativeCode> {
    let isa = super::isa()?;
    let mut module = JITModule::new(JITBuilder::with_isa(isa, default_libcall_names()));
    let call_conv = module.isa().default_call_conv();
    let ptr = module.target_config().pointer_type();
    if ptr != types::I64 {
        return None;
    }
    let mut ctx = Context::new();
    let sig = &mut ctx.func.signature;
    sig.call_conv = call_conv;
    sig.params.push(AbiParam::new(ptr));
    sig.params.push(AbiParam::new(types::I64));
    sig.params.push(AbiParam::new(types::I64));
    sig.returns.push(AbiParam::new(types::I64));
    let id = module
        .declare_function("samples", Linkage::Local, &ctx.func.signature)
        .ok()?;
    ctx.func.name = UserFuncName::user(0, id.as_u32());
    let mut fctx = FunctionBuilderContext::new();
    let masses = {
        let mut b = FunctionBuilder::new(&mut ctx.func, &mut fctx);
        let mut exp_sig = Signature::new(call_conv);
        exp_sig.params.push(AbiParam::new(types::F64));
        exp_sig.returns.push(AbiParam::new(types::F64));
        let callees = Callees {
            exp_sig: b.import_signature(exp_sig),
            exp_addr: laws::exp as *const () as usize as i64,
        };
        let masses = Emitter::new(engine, &mut b, callees).function();
        b.seal_all_blocks();
        b.finalize();
        masses
    };
    module.define_function(id, &mut ctx).ok()?;
    let size = ctx.compiled_code().map_or(0, |c| c.code_buffer().len());
    if let Ok(path) = std::env::var("RESSORT_JIT_DUMP") {
        let _ = std::fs::write(path, ctx.compiled_code().unwrap().code_buffer());
    }
    module.finalize_definitions().ok()?;
    let code = module.get_finalized_function(id);
    // SAFETY: the function was declared with `Entry`'s signature in the target's C calling
    // convention, and lives as long as `module`, which the `NativeCode` owns.
    let entry = unsafe { std::mem::transmute::<*const u8, super::Entry>(code) };
    Some(NativeCode {
        entry,
        plain: masses.plain,
        unit: masses.unit,
        points: engine.points.x.len(),
        args: engine.args.len(),
        singles: engine.singles.len(),
        size,
        module: Mutex::new(Some(module)),
    })
}

/// Which single masses the code updates as plain (a = 2, b = −1, g = +0) and, of those, as
/// unit masses (1/M = 1, left out of the multiplication); see [`NativeCode::fits`].
pub(super) struct Masses {
    pub plain: Vec<bool>,
    pub unit: Vec<bool>,
}

/// Whether single mass `i` has 1/M = 1 now and always: its mass argument reads no parameter
/// (a constant; M takes no class gain).
fn unit_mass(e: &Engine, i: usize) -> bool {
    let slot = e.singles.cols[0] + i;
    e.singles.inv_m[i].to_bits() == 1f64.to_bits()
        && e.control
            .bindings
            .iter()
            .filter(|b| b.slot as usize == slot)
            .all(|b| e.program.params_read(b.expr).next().is_none())
}

/// A channel's buffer in the block: the address of sample 0 and the stride in bytes (0 for
/// a channel the block does not have, which reads `Frame::zero` or writes `Frame::sink`).
#[derive(Clone, Copy)]
struct Channel {
    number: u32,
    base: Value,
    stride: Value,
}

/// The state of every point as variables of the function being built.
struct State {
    x: Vec<Variable>,
    xp: Vec<Variable>,
    f: Vec<Variable>,
}

struct Emitter<'a, 'b> {
    e: &'a Engine,
    b: &'a mut FunctionBuilder<'b>,
    callees: Callees,
    frame: Value,
    state: State,
}

const FLAGS: MemFlags = MemFlags::trusted();

impl<'a, 'b> Emitter<'a, 'b> {
    fn new(e: &'a Engine, b: &'a mut FunctionBuilder<'b>, callees: Callees) -> Self {
        let entry = b.create_block();
        b.append_block_params_for_function_params(entry);
        b.switch_to_block(entry);
        let frame = b.block_params(entry)[0];
        let n = e.points.x.len();
        let mut vars = |_| b.declare_var(types::F64);
        let state = State {
            x: (0..n).map(&mut vars).collect(),
            xp: (0..n).map(&mut vars).collect(),
            f: (0..n).map(&mut vars).collect(),
        };
        Emitter {
            e,
            b,
            callees,
            frame,
            state,
        }
    }

    /// A pointer field of the frame.
    fn field(&mut self, offset: usize) -> Value {
        self.b
            .ins()
            .load(types::I64, FLAGS, self.frame, offset as i32)
    }

    /// Element `i` of the f64 array at `base`.
    fn load(&mut self, base: Value, i: usize) -> Value {
        self.b.ins().load(types::F64, FLAGS, base, (8 * i) as i32)
    }

    fn constant(&mut self, v: f64) -> Value {
        self.b.ins().f64const(v)
    }

    /// The function's body; returns the single masses it updates as plain and as unit masses.
    fn function(mut self) -> Masses {
        let e = self.e;
        let n = e.points.x.len();
        let start = self.b.block_params(self.b.current_block().unwrap())[1];
        let end = self.b.block_params(self.b.current_block().unwrap())[2];

        // Entry: the state, the coefficients, the channels.
        let (x, xp, f) = (
            self.field(offset_of!(Frame, x)),
            self.field(offset_of!(Frame, xp)),
            self.field(offset_of!(Frame, f)),
        );
        for p in 0..n {
            let (vx, vxp, vf) = (self.load(x, p), self.load(xp, p), self.load(f, p));
            self.b.def_var(self.state.x[p], vx);
            self.b.def_var(self.state.xp[p], vxp);
            self.b.def_var(self.state.f[p], vf);
        }
        let singles = e.singles.len();
        let plain: Vec<bool> = (0..singles).map(|i| e.singles.is_plain(i)).collect();
        let unit: Vec<bool> = (0..singles).map(|i| plain[i] && unit_mass(e, i)).collect();
        let arrays = [
            self.field(offset_of!(Frame, a)),
            self.field(offset_of!(Frame, b)),
            self.field(offset_of!(Frame, inv_m)),
            self.field(offset_of!(Frame, gravity)),
        ];
        let args = self.field(offset_of!(Frame, args));
        let input_numbers =
            sorted_unique(e.avatars.iter().chain(&e.force_inputs).map(|r| r.channel));
        let output_numbers = sorted_unique(
            e.pos_outputs
                .iter()
                .map(|r| r.channel)
                .chain(e.frc_outputs.iter().map(|o| o.0)),
        );
        let inputs = self.channels(&input_numbers, true);
        let outputs = self.channels(&output_numbers, false);
        let limit = self.b.ins().load(
            types::F64,
            FLAGS,
            self.frame,
            offset_of!(Frame, limit) as i32,
        );

        let header = self.b.create_block();
        let body = self.b.create_block();
        let bad = self.b.create_block();
        let exit = self.b.create_block();
        self.b.set_cold_block(bad);
        let k_var = self.b.declare_var(types::I64);
        self.b.def_var(k_var, start);
        self.b.ins().jump(header, &[]);
        let entry = self.b.current_block().expect("the entry block");
        self.b.seal_block(entry);

        self.b.switch_to_block(header);
        let k = self.b.use_var(k_var);
        let done = self.b.ins().icmp(IntCC::SignedGreaterThanOrEqual, k, end);
        self.b.ins().brif(done, exit, &[], body, &[]);
        self.b.seal_block(body);
        self.b.seal_block(exit);

        self.b.switch_to_block(body);
        // Coefficients and arguments are loaded in the loop, where they are used: held
        // across it they crowd the registers, and Cranelift's allocator then spills them and
        // stores them back at every sample.
        let coefficients = self.mass_coefficients(&plain, &unit, arrays);
        let mut link_args = Vec::new();
        for (law, g) in groups(e) {
            for i in 0..g.len() {
                let values: Vec<Value> = (0..law.arity())
                    .map(|c| self.load(args, g.cols[c] + i))
                    .collect();
                link_args.push(values);
            }
        }
        let sample = self.sample(k, &inputs, &plain, &unit, &coefficients, &link_args);
        let ok = self.outputs(k, &outputs, limit, &sample);
        let next = self.b.ins().iadd_imm(k, 1);
        self.b.def_var(k_var, next);
        self.b.ins().brif(ok, header, &[], bad, &[]);
        self.b.seal_block(header);
        self.b.seal_block(bad);

        self.b.switch_to_block(bad);
        self.store_state(x, xp, f);
        self.b.ins().return_(&[k]);

        self.b.switch_to_block(exit);
        self.store_state(x, xp, f);
        self.b.ins().return_(&[end]);
        Masses { plain, unit }
    }

    /// Per single mass, what its update reads: nothing for a ground (its coefficients are
    /// constants) or a unit mass, 1/M for a plain one, (a, b, 1/M, g) otherwise (unread ones
    /// as 0).
    fn mass_coefficients(
        &mut self,
        plain: &[bool],
        unit: &[bool],
        arrays: [Value; 4],
    ) -> Vec<[Value; 4]> {
        let zero = self.constant(0.0);
        (0..plain.len())
            .map(|i| {
                if self.e.singles.fixed[i] || unit[i] {
                    [zero; 4]
                } else if plain[i] {
                    [zero, zero, self.load(arrays[2], i), zero]
                } else {
                    [
                        self.load(arrays[0], i),
                        self.load(arrays[1], i),
                        self.load(arrays[2], i),
                        self.load(arrays[3], i),
                    ]
                }
            })
            .collect()
    }

    /// Each channel's buffer: channel c at `buffer + 8·c·frames`, stride 8, when the block
    /// has it (c < its channel count), else `zero` or `sink` with stride 0.
    fn channels(&mut self, numbers: &[u32], inputs: bool) -> Vec<Channel> {
        if numbers.is_empty() {
            return Vec::new();
        }
        let (buffer, count, spare) = if inputs {
            (
                offset_of!(Frame, inputs),
                offset_of!(Frame, in_channels),
                offset_of!(Frame, zero),
            )
        } else {
            (
                offset_of!(Frame, outputs),
                offset_of!(Frame, out_channels),
                offset_of!(Frame, sink),
            )
        };
        let (buffer, count, spare) = (self.field(buffer), self.field(count), self.field(spare));
        let frames = self.field(offset_of!(Frame, frames));
        let eight = self.b.ins().iconst(types::I64, 8);
        let nothing = self.b.ins().iconst(types::I64, 0);
        numbers
            .iter()
            .map(|&c| {
                let number = self.b.ins().iconst(types::I64, c as i64);
                let present = self.b.ins().icmp(IntCC::UnsignedLessThan, number, count);
                let bytes = self.b.ins().imul_imm(frames, 8 * c as i64);
                let at = self.b.ins().iadd(buffer, bytes);
                Channel {
                    number: c,
                    base: self.b.ins().select(present, at, spare),
                    stride: self.b.ins().select(present, eight, nothing),
                }
            })
            .collect()
    }

    /// The address of sample `k` of a channel.
    fn address(&mut self, channel: &Channel, k: Value) -> Value {
        let offset = self.b.ins().imul(k, channel.stride);
        self.b.ins().iadd(channel.base, offset)
    }

    /// One sample: stages 1 a, 2 a and 4 of spec §1.5. Returns the outputs' values, in the
    /// order of `Engine::write_outputs`, as (channel, value).
    fn sample(
        &mut self,
        k: Value,
        inputs: &[Channel],
        plain: &[bool],
        unit: &[bool],
        coefficients: &[[Value; 4]],
        link_args: &[Vec<Value>],
    ) -> Vec<(u32, Value)> {
        let e = self.e;
        // Each input channel read once: a non-finite sample counts as 0 (`Engine::sample`).
        let zero = self.constant(0.0);
        let mut read = Vec::with_capacity(inputs.len());
        for channel in inputs {
            let at = self.address(channel, k);
            let v = self.b.ins().load(types::F64, FLAGS, at, 0);
            let finite = self.finite(v);
            let v = self.unless(finite, v, |me| me.constant(0.0));
            read.push((channel.number, v));
        }
        let input = |ch: u32| read.iter().find(|r| r.0 == ch).map(|r| r.1);

        // Stage 1 a: avatars take their input; their force is cleared.
        for r in &e.avatars {
            let p = r.index as usize;
            let old = self.b.use_var(self.state.x[p]);
            self.b.def_var(self.state.xp[p], old);
            self.b
                .def_var(self.state.x[p], input(r.channel).unwrap_or(zero));
            self.b.def_var(self.state.f[p], zero);
        }
        // Stage 2 a: single masses (`kernels::masses`):
        // plain X[n+1] = (2·X − X̃) + F·(1/M); general a·X + b·X̃ + (F − g)·(1/M).
        let two = self.constant(2.0);
        for (i, &[a, b, inv_m, g]) in coefficients.iter().enumerate() {
            let x = self.b.use_var(self.state.x[i]);
            let xp = self.b.use_var(self.state.xp[i]);
            let f = self.b.use_var(self.state.f[i]);
            let next = if e.singles.fixed[i] {
                self.ground(x, xp, f)
            } else if plain[i] {
                let two_x = self.b.ins().fmul(two, x);
                let inertia = self.b.ins().fsub(two_x, xp);
                // F·1 is F: a unit mass leaves the multiplication out of the chain.
                let push = if unit[i] {
                    f
                } else {
                    self.b.ins().fmul(f, inv_m)
                };
                self.b.ins().fadd(inertia, push)
            } else {
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
        // Stage 4: every link of every group in list order (the bands of the interpreter
        // give the link-by-link scatter's bits), F₁ −= f, F₂ += f; then the force inputs.
        let mut args = link_args.iter();
        // Whether a point's F has received a force yet in this sample (it is +0 until then).
        let mut touched = vec![false; e.points.x.len()];
        for (law, g) in groups(e) {
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
                let a = args.next().expect("one argument list per link");
                let force = laws::emit(self.b, law, dx, dv, a, self.callees);
                self.add_force(pa, force, true, &mut touched);
                self.add_force(pb, force, false, &mut touched);
            }
        }
        // F + in is F when in is +0 (F is never −0), which a silent input usually is: the
        // add leaves the sample's chain of dependent operations.
        for r in &e.force_inputs {
            let p = r.index as usize;
            let v = input(r.channel).unwrap_or(zero);
            let f = self.b.use_var(self.state.f[p]);
            let f = if touched[p] {
                let bits = self.b.ins().bitcast(types::I64, MemFlags::new(), v);
                let silent = self.b.ins().icmp_imm(IntCC::Equal, bits, 0);
                self.unless(silent, f, |me| me.b.ins().fadd(f, v))
            } else {
                touched[p] = true;
                self.b.ins().fadd(f, v)
            };
            self.b.def_var(self.state.f[p], f);
        }
        // Stage 6's values: positions, and forces summed from −0 as `Iterator::sum` does.
        let mut values = Vec::new();
        for r in &e.pos_outputs {
            let x = self.b.use_var(self.state.x[r.index as usize]);
            values.push((r.channel, x));
        }
        for &(channel, start, len) in &e.frc_outputs {
            let mut total = self.constant(-0.0);
            for &p in &e.frc_sources[start as usize..(start + len) as usize] {
                let f = self.b.use_var(self.state.f[p as usize]);
                total = self.b.ins().fadd(total, f);
            }
            values.push((channel, total));
        }
        values
    }

    /// `fast` when `usual` holds, else what `slow` computes, on a cold block of its own: the
    /// same value as a `select`, but the sample's usual path neither computes the slow value
    /// nor waits for it (the branch is predicted).
    fn unless(
        &mut self,
        usual: Value,
        fast: Value,
        slow: impl FnOnce(&mut Self) -> Value,
    ) -> Value {
        let cold = self.b.create_block();
        let join = self.b.create_block();
        let result = self.b.append_block_param(join, types::F64);
        self.b.set_cold_block(cold);
        self.b.ins().brif(usual, join, &[fast.into()], cold, &[]);
        self.b.seal_block(cold);
        self.b.switch_to_block(cold);
        let v = slow(self);
        self.b.ins().jump(join, &[v.into()]);
        self.b.seal_block(join);
        self.b.switch_to_block(join);
        result
    }

    /// Whether `v` is finite: v − v is +0 for a finite v and NaN otherwise.
    fn finite(&mut self, v: Value) -> Value {
        let d = self.b.ins().fsub(v, v);
        self.b.ins().fcmp(FloatCC::Ordered, d, d)
    }

    /// A ground's update, the general one with its constant coefficients (a, b, 1/M, g) =
    /// (1, 0, 0, 0): X[n+1] = (1·X + 0·X̃) + (F − 0)·0. That is X itself when X is not −0 and
    /// X̃ and F are finite (the products are zeros, and X + ±0 = X), the usual case: the
    /// ground's position leaves the chain of dependent operations through the forces on it.
    fn ground(&mut self, x: Value, xp: Value, f: Value) -> Value {
        let bits = self.b.ins().bitcast(types::I64, MemFlags::new(), x);
        let negative_zero = (-0.0f64).to_bits() as i64;
        let not_negative_zero = self.b.ins().icmp_imm(IntCC::NotEqual, bits, negative_zero);
        let sum = self.b.ins().fadd(xp, f);
        // Both finite exactly when their sum's self-difference is not NaN, except when they
        // are infinities of opposite signs, whose sum is NaN too: a test that errs only
        // towards the slow path.
        let finite = self.finite(sum);
        let usual = self.b.ins().band(not_negative_zero, finite);
        self.unless(usual, x, |me| {
            let (one, zero) = (me.constant(1.0), me.constant(0.0));
            let ax = me.b.ins().fmul(one, x);
            let bxp = me.b.ins().fmul(zero, xp);
            let inertia = me.b.ins().fadd(ax, bxp);
            let net = me.b.ins().fsub(f, zero);
            let push = me.b.ins().fmul(net, zero);
            me.b.ins().fadd(inertia, push)
        })
    }

    /// F[p] −= c (`negative`) or F[p] += c, the interpreter's operation. The first force a
    /// point receives in a sample is added to +0, and +0 ± c is ±c unless c is a zero or a
    /// NaN, the usual case: the add leaves the chain of dependent operations.
    fn add_force(&mut self, p: usize, c: Value, negative: bool, touched: &mut [bool]) {
        let f = if touched[p] {
            let f = self.b.use_var(self.state.f[p]);
            if negative {
                self.b.ins().fsub(f, c)
            } else {
                self.b.ins().fadd(f, c)
            }
        } else {
            touched[p] = true;
            let zero = self.constant(0.0);
            let ordinary = self.b.ins().fcmp(FloatCC::OrderedNotEqual, c, zero);
            let fast = if negative { self.b.ins().fneg(c) } else { c };
            self.unless(ordinary, fast, |me| {
                let zero = me.constant(0.0);
                if negative {
                    me.b.ins().fsub(zero, c)
                } else {
                    me.b.ins().fadd(zero, c)
                }
            })
        };
        self.b.def_var(self.state.f[p], f);
    }

    /// Stage 6: writes sample `k` of every output, in order. Returns a condition that holds
    /// when every value passes the guard (|v| ≤ limit, which a NaN fails).
    fn outputs(
        &mut self,
        k: Value,
        channels: &[Channel],
        limit: Value,
        values: &[(u32, Value)],
    ) -> Value {
        let mut ok = self.b.ins().iconst(types::I8, 1);
        for &(channel, v) in values {
            let c = channels
                .iter()
                .find(|c| c.number == channel)
                .copied()
                .expect("every output's channel has a buffer");
            let at = self.address(&c, k);
            self.b.ins().store(FLAGS, v, at, 0);
            let magnitude = self.b.ins().fabs(v);
            let within = self
                .b
                .ins()
                .fcmp(FloatCC::LessThanOrEqual, magnitude, limit);
            ok = self.b.ins().band(ok, within);
        }
        ok
    }

    fn store_state(&mut self, x: Value, xp: Value, f: Value) {
        for p in 0..self.state.x.len() {
            for (var, base) in [
                (self.state.x[p], x),
                (self.state.xp[p], xp),
                (self.state.f[p], f),
            ] {
                let v = self.b.use_var(var);
                self.b.ins().store(FLAGS, v, base, (8 * p) as i32);
            }
        }
    }
}

fn sorted_unique(channels: impl Iterator<Item = u32>) -> Vec<u32> {
    let mut v: Vec<u32> = channels.collect();
    v.sort_unstable();
    v.dedup();
    v
}
