//! The interaction laws of [`crate::laws`] (spec §2.3–§2.6) as Cranelift IR: every branch of
//! the scalar law computed with the same IEEE operations in the same order, and the law's
//! branch chosen by a comparison and a `select`, so the generated code gives the scalar law's
//! bits (unit tests below, over every branch, ±0, infinities and NaN). `nlBow`'s smooth
//! profile calls the same `exp` as the scalar law, on a branch of its own.
//!
//! Conditions are Cranelift's `i8` truth values (0 or 1): they are combined with `band`,
//! `bor` and `bxor_imm(c, 1)` (`bnot` would turn 1 into 0xfe, which `select` reads as true).

use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{types, InstBuilder, SigRef, Value};
use cranelift_frontend::FunctionBuilder;

use crate::laws::LawKind;

/// What a law's code needs besides the builder: the signature of `exp` (for the bow) and its
/// address.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Callees {
    pub exp_sig: SigRef,
    pub exp_addr: i64,
}

/// `exp` as the scalar bow computes it, for the generated code to call.
pub(crate) extern "C" fn exp(x: f64) -> f64 {
    x.exp()
}

/// Emits `law(Δx, Δv, args)` and returns the force f (the caller applies F₁ −= f, F₂ += f).
pub(crate) fn emit(
    b: &mut FunctionBuilder,
    law: LawKind,
    dx: Value,
    dv: Value,
    a: &[Value],
    callees: Callees,
) -> Value {
    match law {
        LawKind::SpringDamper => spring_damper(b, dx, dv, a[0], a[1]),
        LawKind::Contact => contact(b, dx, dv, a[0], a[1], a[2]),
        LawKind::NlContact => nl_contact(b, dx, dv, a[0], a[1], a[2], a[3], a[4]),
        LawKind::NlSpring2 => nl_spring2(b, dx, dv, a[0], a[1], a[2]),
        LawKind::NlSpring3 => nl_spring3(b, dx, dv, a[0], a[1], a[2]),
        LawKind::NlSpringDamper => nl_spring_damper(b, dx, dv, a[0], a[1], a[2], a[3]),
        LawKind::Pluck => nl_pluck(b, dx, dv, a[0], a[1], a[2]),
        LawKind::Bow => nl_bow(b, dv, a[0], a[1], a[2], callees),
    }
}

fn not(b: &mut FunctionBuilder, c: Value) -> Value {
    b.ins().bxor_imm(c, 1)
}

/// `laws::spring_damper` (spec §2.3): f = K·Δx + Z·Δv.
fn spring_damper(b: &mut FunctionBuilder, dx: Value, dv: Value, k: Value, z: Value) -> Value {
    let elastic = b.ins().fmul(k, dx);
    let damping = b.ins().fmul(z, dv);
    b.ins().fadd(elastic, damping)
}

/// `laws::contact` (spec §2.4.1): f = K(Δx + θ) + Z·Δv where Δx > −θ, else 0.
fn contact(b: &mut FunctionBuilder, dx: Value, dv: Value, k: Value, z: Value, t: Value) -> Value {
    let d = b.ins().fadd(dx, t);
    let elastic = b.ins().fmul(k, d);
    let damping = b.ins().fmul(z, dv);
    let f = b.ins().fadd(elastic, damping);
    let minus_t = b.ins().fneg(t);
    let engaged = b.ins().fcmp(FloatCC::GreaterThan, dx, minus_t);
    let zero = b.ins().f64const(0.0);
    b.ins().select(engaged, f, zero)
}

/// `laws::bounded_cubic`: (force, the bounded branch as a condition).
///
/// * c = 0: s·d (not bounded);
/// * s ≥ k or c < 0: k·d (bounded);
/// * c·d² ≤ k − s: d(s + c·d²) (not bounded), else k·d (bounded).
fn bounded_cubic(
    b: &mut FunctionBuilder,
    d: Value,
    s: Value,
    c: Value,
    k: Value,
) -> (Value, Value) {
    let zero = b.ins().f64const(0.0);
    let cd = b.ins().fmul(c, d);
    let cdd = b.ins().fmul(cd, d);
    let s_cdd = b.ins().fadd(s, cdd);
    let cubic = b.ins().fmul(d, s_cdd);
    let linear_s = b.ins().fmul(s, d);
    let linear_k = b.ins().fmul(k, d);
    let c_zero = b.ins().fcmp(FloatCC::Equal, c, zero);
    // s ≥ k is k ≤ s (both false for a NaN), so the bounded branch whatever d.
    let s_ge_k = b.ins().fcmp(FloatCC::LessThanOrEqual, k, s);
    let c_neg = b.ins().fcmp(FloatCC::LessThan, c, zero);
    let flat = b.ins().bor(s_ge_k, c_neg);
    let k_minus_s = b.ins().fsub(k, s);
    let within = b.ins().fcmp(FloatCC::LessThanOrEqual, cdd, k_minus_s);
    let beyond = not(b, within);
    let some = b.ins().bor(flat, beyond);
    let c_nonzero = not(b, c_zero);
    let bounded = b.ins().band(c_nonzero, some);
    let k_or_cubic = b.ins().select(bounded, linear_k, cubic);
    (b.ins().select(c_zero, linear_s, k_or_cubic), bounded)
}

/// `laws::nl_contact` (spec §2.4.2): with d = Δx + θ, the bounded cubic of d (k < s: k ← s,
/// c ← 0) plus Z·Δv where d > 0, else 0.
#[allow(clippy::too_many_arguments)]
fn nl_contact(
    b: &mut FunctionBuilder,
    dx: Value,
    dv: Value,
    s: Value,
    c: Value,
    k: Value,
    z: Value,
    t: Value,
) -> Value {
    let zero = b.ins().f64const(0.0);
    let d = b.ins().fadd(dx, t);
    let swap = b.ins().fcmp(FloatCC::LessThan, k, s);
    let k = b.ins().select(swap, s, k);
    let c = b.ins().select(swap, zero, c);
    let (elastic, _) = bounded_cubic(b, d, s, c, k);
    let damping = b.ins().fmul(z, dv);
    let f = b.ins().fadd(elastic, damping);
    let engaged = b.ins().fcmp(FloatCC::GreaterThan, d, zero);
    b.ins().select(engaged, f, zero)
}

/// `laws::nl_spring2` (spec §2.5.1): f = K·Δx + Q·Δx·|Δx| + Z·Δv.
fn nl_spring2(
    b: &mut FunctionBuilder,
    dx: Value,
    dv: Value,
    k: Value,
    q: Value,
    z: Value,
) -> Value {
    let elastic = b.ins().fmul(k, dx);
    let qdx = b.ins().fmul(q, dx);
    let adx = b.ins().fabs(dx);
    let quadratic = b.ins().fmul(qdx, adx);
    let sum = b.ins().fadd(elastic, quadratic);
    let damping = b.ins().fmul(z, dv);
    b.ins().fadd(sum, damping)
}

/// `laws::nl_spring3` (spec §2.5.2): f = K·Δx + Q·Δx³ + Z·Δv.
fn nl_spring3(
    b: &mut FunctionBuilder,
    dx: Value,
    dv: Value,
    k: Value,
    q: Value,
    z: Value,
) -> Value {
    let elastic = b.ins().fmul(k, dx);
    let qdx = b.ins().fmul(q, dx);
    let qdx2 = b.ins().fmul(qdx, dx);
    let cubic = b.ins().fmul(qdx2, dx);
    let sum = b.ins().fadd(elastic, cubic);
    let damping = b.ins().fmul(z, dv);
    b.ins().fadd(sum, damping)
}

/// `laws::nl_spring_damper` (spec §2.5.3): the bounded cubic of Δx plus Z·Δv, with Z + 0.3·k
/// in the bounded branch (normative).
fn nl_spring_damper(
    b: &mut FunctionBuilder,
    dx: Value,
    dv: Value,
    s: Value,
    c: Value,
    k: Value,
    z: Value,
) -> Value {
    let (elastic, bounded) = bounded_cubic(b, dx, s, c, k);
    let three_tenths = b.ins().f64const(0.3);
    let extra = b.ins().fmul(three_tenths, k);
    let bounded_z = b.ins().fadd(z, extra);
    let z = b.ins().select(bounded, bounded_z, z);
    let damping = b.ins().fmul(z, dv);
    b.ins().fadd(elastic, damping)
}

/// `laws::nl_pluck` (spec §2.6.1): −(K − K_e)·Δx inside d_t, −sgn(Δx)·d_t·K + K_e·Δx + Z·Δv
/// inside the scale, 0 beyond (d_t = scale/σ, K_e = K/σ). sgn(Δx) is `f64::signum` in every
/// band a value can reach (a NaN Δx reaches none), so it is 1 with Δx's sign.
fn nl_pluck(
    b: &mut FunctionBuilder,
    dx: Value,
    dv: Value,
    k: Value,
    scale: Value,
    z: Value,
) -> Value {
    let sharpness = b.ins().f64const(crate::laws::PLUCK_SHARPNESS);
    let d_t = b.ins().fdiv(scale, sharpness);
    let k_e = b.ins().fdiv(k, sharpness);
    let adx = b.ins().fabs(dx);
    let k_minus = b.ins().fsub(k, k_e);
    let neg = b.ins().fneg(k_minus);
    let inner = b.ins().fmul(neg, dx);
    let one = b.ins().f64const(1.0);
    let sign = b.ins().fcopysign(one, dx);
    let minus_sign = b.ins().fneg(sign);
    let sd = b.ins().fmul(minus_sign, d_t);
    let band = b.ins().fmul(sd, k);
    let ked = b.ins().fmul(k_e, dx);
    let sum = b.ins().fadd(band, ked);
    let damping = b.ins().fmul(z, dv);
    let outer = b.ins().fadd(sum, damping);
    let zero = b.ins().f64const(0.0);
    let within_scale = b.ins().fcmp(FloatCC::LessThan, adx, scale);
    let beyond = b.ins().select(within_scale, outer, zero);
    let within_tent = b.ins().fcmp(FloatCC::LessThan, adx, d_t);
    b.ins().select(within_tent, inner, beyond)
}

/// `laws::nl_bow` (spec §2.6.2), a friction force of Δv:
///
/// * smooth ≥ 1: f = 0.63·Z·Δv·exp(−4(Δv/scale)² + ½), on a branch of its own (the call);
/// * otherwise, with v_t = scale/3 and Z_e = Z/3: (Z − Z_e)·Δv below v_t, sgn(Δv)·v_t·Z −
///   Z_e·Δv below the scale, 0 beyond;
///
/// and 0 whatever the profile when the scale is not positive.
fn nl_bow(
    b: &mut FunctionBuilder,
    dv: Value,
    z: Value,
    scale: Value,
    smooth: Value,
    callees: Callees,
) -> Value {
    let one = b.ins().f64const(1.0);
    let is_smooth = b.ins().fcmp(FloatCC::GreaterThanOrEqual, smooth, one);
    let smooth_block = b.create_block();
    let piecewise_block = b.create_block();
    let join = b.create_block();
    let force = b.append_block_param(join, types::F64);
    b.ins()
        .brif(is_smooth, smooth_block, &[], piecewise_block, &[]);
    b.seal_block(smooth_block);
    b.seal_block(piecewise_block);

    b.switch_to_block(smooth_block);
    let r = b.ins().fdiv(dv, scale);
    let minus_four = b.ins().f64const(-4.0);
    let r4 = b.ins().fmul(minus_four, r);
    let rr = b.ins().fmul(r4, r);
    let half = b.ins().f64const(0.5);
    let exponent = b.ins().fadd(rr, half);
    let callee = b.ins().iconst(types::I64, callees.exp_addr);
    let call = b.ins().call_indirect(callees.exp_sig, callee, &[exponent]);
    let e = b.inst_results(call)[0];
    let c = b.ins().f64const(0.63);
    let cz = b.ins().fmul(c, z);
    let czdv = b.ins().fmul(cz, dv);
    let f = b.ins().fmul(czdv, e);
    b.ins().jump(join, &[f.into()]);

    b.switch_to_block(piecewise_block);
    let sharpness = b.ins().f64const(crate::laws::BOW_SHARPNESS);
    let v_t = b.ins().fdiv(scale, sharpness);
    let z_e = b.ins().fdiv(z, sharpness);
    let adv = b.ins().fabs(dv);
    let z_minus = b.ins().fsub(z, z_e);
    let stick = b.ins().fmul(z_minus, dv);
    let sign = b.ins().fcopysign(one, dv);
    let sv = b.ins().fmul(sign, v_t);
    let svz = b.ins().fmul(sv, z);
    let zedv = b.ins().fmul(z_e, dv);
    let slip = b.ins().fsub(svz, zedv);
    let zero = b.ins().f64const(0.0);
    let within_scale = b.ins().fcmp(FloatCC::LessThan, adv, scale);
    let beyond = b.ins().select(within_scale, slip, zero);
    let sticking = b.ins().fcmp(FloatCC::LessThan, adv, v_t);
    let f = b.ins().select(sticking, stick, beyond);
    b.ins().jump(join, &[f.into()]);
    b.seal_block(join);

    b.switch_to_block(join);
    let zero = b.ins().f64const(0.0);
    let positive = b.ins().fcmp(FloatCC::GreaterThan, scale, zero);
    b.ins().select(positive, force, zero)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jit::isa;
    use crate::laws;
    use cranelift_codegen::ir::{AbiParam, UserFuncName};
    use cranelift_codegen::Context;
    use cranelift_frontend::FunctionBuilderContext;
    use cranelift_jit::{JITBuilder, JITModule};
    use cranelift_module::{default_libcall_names, Linkage, Module};

    /// Values that reach every branch: both signs, zeros, tiny and huge, infinities, NaN.
    const VALUES: [f64; 16] = [
        0.0,
        -0.0,
        0.3,
        -0.3,
        1e-3,
        -1e-3,
        2.5,
        -2.5,
        0.05,
        -0.05,
        1e-310,
        1e200,
        -1e200,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
    ];

    /// A deterministic stream of picks from VALUES and of ordinary numbers, 1e-3 to 10.
    struct Picks(u64);

    impl Picks {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            let r = self.0 % 64;
            if r < 32 {
                VALUES[r as usize % 16]
            } else {
                let u = (self.0 >> 11) as f64 / (1u64 << 53) as f64;
                let m = 10f64.powf(-3.0 + 4.0 * u);
                if r.is_multiple_of(2) {
                    m
                } else {
                    -m
                }
            }
        }
    }

    type LawFn = unsafe extern "C" fn(f64, f64, f64, f64, f64, f64, f64) -> f64;

    /// Compiles `law` alone as `fn(Δx, Δv, a0 … a4) -> f`.
    fn compile_law(law: LawKind) -> (JITModule, LawFn) {
        let isa = isa().expect("this CPU has a Cranelift back end");
        let mut module = JITModule::new(JITBuilder::with_isa(isa, default_libcall_names()));
        let mut ctx = Context::new();
        let call_conv = module.isa().default_call_conv();
        ctx.func.signature.call_conv = call_conv;
        for _ in 0..7 {
            ctx.func.signature.params.push(AbiParam::new(types::F64));
        }
        ctx.func.signature.returns.push(AbiParam::new(types::F64));
        let id = module
            .declare_function("law", Linkage::Local, &ctx.func.signature)
            .unwrap();
        ctx.func.name = UserFuncName::user(0, id.as_u32());
        let mut fctx = FunctionBuilderContext::new();
        {
            let mut b = FunctionBuilder::new(&mut ctx.func, &mut fctx);
            let entry = b.create_block();
            b.append_block_params_for_function_params(entry);
            b.switch_to_block(entry);
            let p = b.block_params(entry).to_vec();
            let mut exp_sig = cranelift_codegen::ir::Signature::new(call_conv);
            exp_sig.params.push(AbiParam::new(types::F64));
            exp_sig.returns.push(AbiParam::new(types::F64));
            let callees = Callees {
                exp_sig: b.import_signature(exp_sig),
                exp_addr: exp as *const () as usize as i64,
            };
            let f = emit(&mut b, law, p[0], p[1], &p[2..], callees);
            b.ins().return_(&[f]);
            b.seal_all_blocks();
            b.finalize();
        }
        module.define_function(id, &mut ctx).unwrap();
        module.finalize_definitions().unwrap();
        let code = module.get_finalized_function(id);
        // SAFETY: the function was declared with this signature and the module outlives it.
        let f = unsafe { std::mem::transmute::<*const u8, LawFn>(code) };
        (module, f)
    }

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    fn compare(law: LawKind, scalar: impl Fn(f64, f64, &[f64]) -> f64) {
        let (module, f) = compile_law(law);
        let mut picks = Picks(0x9e37_79b9_7f4a_7c15);
        let mut mismatches = 0;
        for _ in 0..40_000 {
            let v: [f64; 7] = std::array::from_fn(|_| picks.next());
            // SAFETY: `f` is the function compiled above, with this signature.
            let got = unsafe { f(v[0], v[1], v[2], v[3], v[4], v[5], v[6]) };
            let want = scalar(v[0], v[1], &v[2..2 + law.arity()]);
            if !same(got, want) {
                mismatches += 1;
                if mismatches < 5 {
                    eprintln!("{law:?}: {v:?}: {got:e}, want {want:e}");
                }
            }
        }
        // SAFETY: no pointer into the module is used after this.
        unsafe { module.free_memory() };
        assert_eq!(mismatches, 0, "{law:?} differs from its scalar law");
    }

    #[test]
    fn every_law_equals_the_scalar_law() {
        compare(LawKind::SpringDamper, |dx, dv, a| {
            laws::spring_damper(dx, dv, a[0], a[1])
        });
        compare(LawKind::Contact, |dx, dv, a| {
            laws::contact(dx, dv, a[0], a[1], a[2])
        });
        compare(LawKind::NlContact, |dx, dv, a| {
            laws::nl_contact(dx, dv, a[0], a[1], a[2], a[3], a[4])
        });
        compare(LawKind::NlSpring2, |dx, dv, a| {
            laws::nl_spring2(dx, dv, a[0], a[1], a[2])
        });
        compare(LawKind::NlSpring3, |dx, dv, a| {
            laws::nl_spring3(dx, dv, a[0], a[1], a[2])
        });
        compare(LawKind::NlSpringDamper, |dx, dv, a| {
            laws::nl_spring_damper(dx, dv, a[0], a[1], a[2], a[3])
        });
        compare(LawKind::Pluck, |dx, dv, a| {
            laws::nl_pluck(dx, dv, a[0], a[1], a[2])
        });
    }

    /// The bow, both profiles: `smooth` drawn from 0, 1 and the picks.
    #[test]
    fn the_bow_equals_the_scalar_law() {
        compare(LawKind::Bow, |_dx, dv, a| {
            laws::nl_bow(dv, a[0], a[1], a[2])
        });
        let (module, f) = compile_law(LawKind::Bow);
        let mut picks = Picks(7);
        for i in 0..20_000 {
            let (dv, z, scale) = (picks.next() * 1e-3, picks.next(), picks.next().abs());
            let smooth = (i % 2) as f64;
            // SAFETY: `f` is the function compiled above, with this signature.
            let got = unsafe { f(0.0, dv, z, scale, smooth, 0.0, 0.0) };
            let want = laws::nl_bow(dv, z, scale, smooth);
            assert!(
                same(got, want),
                "{dv:e} {z:e} {scale:e} {smooth}: {got:e} {want:e}"
            );
        }
        // SAFETY: no pointer into the module is used after this.
        unsafe { module.free_memory() };
    }
}
