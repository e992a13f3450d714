//! The generated function of [`super::NativeCode`]: a loop over samples whose body is the
//! model, point by point and link by link, in the interpreter's order (`jit/sample.rs`).
//!
//! ```text
//! entry:   load the state (x, x̃, F of every point) into variables; per input and output
//!          channel, the address of the call's first sample; the grounds' check → refuse
//! header:  j = end − start? → exit
//! body:    two samples (stages 1 a, 2 a, 4, 6), each of which may leave for its bail-out
//!          block (state before it) or for `bad` (its outputs rejected, state after it)
//! exit:    store the state, return end       refuse: return start | BAIL
//! ```
//!
//! A call runs at most [`FLUSH_INTERVAL`] samples (the driver ends calls where the flush is
//! due), so a channel the block does not have reads `Frame::zero` or writes `Frame::sink`,
//! each that long, and every channel is addressed as base + 8·j.

use super::arith::Callees;
use super::Parts;
use super::{Frame, NativeCode, BAIL, MAX_ELEMENTS};
use crate::laws::LawKind;
use crate::sim::flush::FLUSH_INTERVAL;
use crate::sim::kernels::links::Group;
use cranelift_codegen::ir::condcodes::IntCC;
use cranelift_codegen::ir::{types, AbiParam, Block, InstBuilder, MemFlags, UserFuncName, Value};
use cranelift_codegen::Context;
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext, Variable};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{default_libcall_names, Linkage, Module};
use std::mem::offset_of;
use std::sync::Mutex;

/// Samples per trip round the loop: two, so that x and x̃ trade registers from one sample to
/// the next instead of moving at the end of each.
const UNROLL: usize = 2;

/// The groups of the engine's stage 4, in their order, with their laws: every law of
/// [`LawKind::ALL`], so the native code covers every link of the model.
pub(super) fn groups<'a>(engine: &Parts<'a>) -> impl Iterator<Item = (LawKind, &'a Group)> {
    engine.interactions.by_law()
}

/// Whether `engine` is a model this compiles: single masses, avatars and links only, no
/// audio-rate parameter, small enough, every index inside the state.
pub(super) fn fits(engine: &Parts<'_>) -> bool {
    let n = engine.points.x.len();
    let links: usize = groups(engine).map(|(_, g)| g.len()).sum();
    let inside = |p: u32| (p as usize) < n;
    let m = &engine.macros;
    m.lines.is_empty()
        && m.stiff.is_empty()
        && m.meshes.is_empty()
        && engine.proxies.len() == 0
        && engine.model.audio_params.is_empty()
        && engine.model.audio_bindings.is_empty()
        && n + links <= MAX_ELEMENTS
        && n == engine.singles.len() + engine.model.avatars.len()
        && engine
            .model
            .avatars
            .iter()
            .all(|r| r.index as usize >= engine.singles.len() && inside(r.index))
        && engine.model.force_inputs.iter().all(|r| inside(r.index))
        && engine.model.pos_outputs.iter().all(|r| inside(r.index))
        && engine.model.frc_sources.iter().all(|&p| inside(p))
        && engine
            .model
            .frc_outputs
            .iter()
            .all(|&(_, start, len)| (start + len) as usize <= engine.model.frc_sources.len())
        && groups(engine).all(|(law, g)| {
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
pub(super) fn compile(engine: &Parts<'_>) -> Option<NativeCode> {
    let (module, entry, size, masses) = define(|b, callees| {
        let masses = Emitter::new(engine, b, callees).function();
        masses
    })?;
    Some(NativeCode {
        entry,
        plain: masses.plain,
        unit: masses.unit,
        points: engine.points.x.len(),
        args: engine.args.len(),
        singles: engine.singles.len(),
        space: None,
        size,
        module: Mutex::new(Some(module)),
    })
}

/// Declares a function of [`super::Entry`]'s signature, has `body` emit it, and compiles it: the module that owns the code, the entry, the bytes
/// of machine code and what `body` returned. `None` if Cranelift refuses it. Shared by the
/// 1-D emitter and the 3-D one (`jit/space.rs`).
pub(super) fn define<T>(
    body: impl FnOnce(&mut FunctionBuilder, Callees) -> T,
) -> Option<(JITModule, super::Entry, usize, T)> {
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
    let made = {
        let mut b = FunctionBuilder::new(&mut ctx.func, &mut fctx);
        let callees = Callees::import(&mut b, call_conv);
        let made = body(&mut b, callees);
        b.seal_all_blocks();
        b.finalize();
        made
    };
    module.define_function(id, &mut ctx).ok()?;
    let size = ctx.compiled_code().map_or(0, |c| c.code_buffer().len());
    // For engineers: the machine code, to read with `objdump -D -b binary -m i386:x86-64`.
    if let (Ok(path), Some(code)) = (std::env::var("RESSORT_JIT_DUMP"), ctx.compiled_code()) {
        let _ = std::fs::write(path, code.code_buffer());
    }
    module.finalize_definitions().ok()?;
    let code = module.get_finalized_function(id);
    // SAFETY: the function was declared with `Entry`'s signature in the target's C calling
    // convention, and lives as long as `module`, which the `NativeCode` owns.
    let entry = unsafe { std::mem::transmute::<*const u8, super::Entry>(code) };
    Some((module, entry, size, made))
}

/// Which single masses the code updates as plain (a = 2, b = −1, g = +0) and, of those, as
/// unit masses (1/M = 1, left out of the multiplication); see [`NativeCode::fits`].
pub(super) struct Masses {
    pub plain: Vec<bool>,
    pub unit: Vec<bool>,
}

/// Whether single mass `i` has 1/M = 1 now and always: its mass argument reads no parameter
/// (a constant; M takes no class gain).
fn unit_mass(e: &Parts<'_>, i: usize) -> bool {
    let slot = e.singles.cols[0] + i;
    e.singles.inv_m[i].to_bits() == 1f64.to_bits()
        && e.control_bindings
            .iter()
            .filter(|b| b.slot as usize == slot)
            .all(|b| e.model.program.params_read(b.expr).next().is_none())
}

/// The state of every point as variables of the function being built.
pub(super) struct State {
    pub x: Vec<Variable>,
    pub xp: Vec<Variable>,
    pub f: Vec<Variable>,
}

/// What a sample reads besides the state, loaded or computed at the function's entry.
pub(super) struct Setup {
    /// The base pointers of `Engine::args` and of the singles' a, b, 1/M and g.
    pub args: Value,
    pub arrays: [Value; 4],
    /// Per input and per output channel: (channel number, address of the call's first
    /// sample).
    pub inputs: Vec<(u32, Value)>,
    pub outputs: Vec<(u32, Value)>,
    /// The guard's bounds: `limit` and −`limit`.
    pub limit: Value,
    pub neg_limit: Value,
    /// −0, whose bits flip a sign.
    pub sign: Value,
    pub masses: Masses,
}

pub(super) struct Emitter<'a, 'b> {
    pub e: &'a Parts<'a>,
    pub b: &'a mut FunctionBuilder<'b>,
    pub callees: Callees,
    pub frame: Value,
    pub state: State,
    /// The block the sample being emitted leaves for when its state is not one the code
    /// handles.
    pub bail: Option<Block>,
}

pub(super) const FLAGS: MemFlags = MemFlags::trusted();

impl<'a, 'b> Emitter<'a, 'b> {
    fn new(e: &'a Parts<'a>, b: &'a mut FunctionBuilder<'b>, callees: Callees) -> Self {
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
            bail: None,
        }
    }

    /// A pointer-sized field of the frame.
    fn field(&mut self, offset: usize) -> Value {
        self.b
            .ins()
            .load(types::I64, FLAGS, self.frame, offset as i32)
    }

    fn f64_field(&mut self, offset: usize) -> Value {
        self.b
            .ins()
            .load(types::F64, FLAGS, self.frame, offset as i32)
    }

    /// Element `i` of the f64 array at `base`.
    pub fn load(&mut self, base: Value, i: usize) -> Value {
        self.b.ins().load(types::F64, FLAGS, base, (8 * i) as i32)
    }

    pub fn constant(&mut self, v: f64) -> Value {
        self.b.ins().f64const(v)
    }

    /// The function; returns the single masses it updates as plain and as unit masses.
    fn function(mut self) -> Masses {
        let e = self.e;
        let n = e.points.x.len();
        let entry = self.b.current_block().expect("the entry block");
        let (start, end) = (self.b.block_params(entry)[1], self.b.block_params(entry)[2]);
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
        let input_numbers = sorted_unique(
            e.model
                .avatars
                .iter()
                .chain(&e.model.force_inputs)
                .map(|r| r.channel),
        );
        let output_numbers = sorted_unique(
            e.model
                .pos_outputs
                .iter()
                .map(|r| r.channel)
                .chain(e.model.frc_outputs.iter().map(|o| o.0)),
        );
        let inputs = self.channels(&input_numbers, start, true);
        let outputs = self.channels(&output_numbers, start, false);
        let limit = self.f64_field(offset_of!(Frame, limit));
        let neg_limit = self.b.ins().fneg(limit);
        let sign = self.f64_field(offset_of!(Frame, sign));
        let setup = Setup {
            args,
            arrays,
            inputs,
            outputs,
            limit,
            neg_limit,
            sign,
            masses: Masses { plain, unit },
        };

        let header = self.b.create_block();
        let exit = self.b.create_block();
        let bad = self.b.create_block();
        let bad_k = self.b.append_block_param(bad, types::I64);
        let refuse = self.b.create_block();
        for cold in [bad, refuse] {
            self.b.set_cold_block(cold);
        }
        let count = self.b.ins().isub(end, start);
        let j_var = self.b.declare_var(types::I64);
        let zero = self.b.ins().iconst(types::I64, 0);
        self.b.def_var(j_var, zero);
        // Grounds keep their position on the usual path, so their position and delayed
        // position are checked once, here (see `Emitter::ground`).
        let mut usual = self.b.ins().iconst(types::I8, 1);
        for i in (0..singles).filter(|&i| e.singles.fixed[i]) {
            let (gx, gxp) = (
                self.b.use_var(self.state.x[i]),
                self.b.use_var(self.state.xp[i]),
            );
            let bits = self.b.ins().bitcast(types::I64, MemFlags::new(), gx);
            let negative_zero = (-0.0f64).to_bits() as i64;
            let not_negative_zero = self.b.ins().icmp_imm(IntCC::NotEqual, bits, negative_zero);
            let (x_finite, xp_finite) = (self.finite(gx), self.finite(gxp));
            for c in [not_negative_zero, x_finite, xp_finite] {
                usual = self.b.ins().band(usual, c);
            }
        }
        self.b.ins().brif(usual, header, &[], refuse, &[]);
        self.b.seal_block(entry);
        self.b.seal_block(refuse);
        self.b.switch_to_block(refuse);
        let refused = self.b.ins().bor_imm(start, BAIL);
        self.b.ins().return_(&[refused]);

        self.b.switch_to_block(header);
        let mut j = self.b.use_var(j_var);
        for copy in 0..UNROLL {
            let go_on = self.b.create_block();
            let done = self.b.ins().icmp(IntCC::SignedGreaterThanOrEqual, j, count);
            self.b.ins().brif(done, exit, &[], go_on, &[]);
            self.b.seal_block(go_on);
            self.b.switch_to_block(go_on);
            let k = self.b.ins().iadd(start, j);
            self.sample(k, j, &setup, bad, (x, xp, f));
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
        self.store_state(x, xp, f);
        self.b.ins().return_(&[bad_k]);

        self.b.switch_to_block(exit);
        self.store_state(x, xp, f);
        self.b.ins().return_(&[end]);
        setup.masses
    }

    fn channels(&mut self, numbers: &[u32], start: Value, inputs: bool) -> Vec<(u32, Value)> {
        channels(self.b, self.frame, numbers, start, inputs)
    }

    pub(super) fn store_state(&mut self, x: Value, xp: Value, f: Value) {
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

const _: () = assert!(FLUSH_INTERVAL <= super::SPARE as u64);

/// Each channel's address at the call's first sample: channel c at `buffer + 8·(c·frames +
/// start)` when the block has it (c below its channel count), else the frame's spare channel
/// (`zero` for inputs, `sink` for outputs).
pub(super) fn channels(
    b: &mut FunctionBuilder,
    frame: Value,
    numbers: &[u32],
    start: Value,
    inputs: bool,
) -> Vec<(u32, Value)> {
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
    let mut field = |offset: usize| b.ins().load(types::I64, FLAGS, frame, offset as i32);
    let (buffer, count, spare) = (field(buffer), field(count), field(spare));
    let frames = field(offset_of!(Frame, frames));
    let first = b.ins().ishl_imm(start, 3);
    let buffer = b.ins().iadd(buffer, first);
    numbers
        .iter()
        .map(|&c| {
            let number = b.ins().iconst(types::I64, c as i64);
            let present = b.ins().icmp(IntCC::UnsignedLessThan, number, count);
            let bytes = b.ins().imul_imm(frames, 8 * c as i64);
            let at = b.ins().iadd(buffer, bytes);
            (c, b.ins().select(present, at, spare))
        })
        .collect()
}

pub(super) fn sorted_unique(channels: impl Iterator<Item = u32>) -> Vec<u32> {
    let mut v: Vec<u32> = channels.collect();
    v.sort_unstable();
    v.dedup();
    v
}
