//! The laws of [`crate::laws`] as Cranelift IR: [`Arith`] on Cranelift values, so the native
//! code runs each law's IEEE operations in the scalar law's order. A law's branches are
//! computed and chosen by a comparison and a `select`; [`Arith::branch`] is a jump to a
//! block per side and a join (`nlBow`'s `exp`). `exp` and `pow` call `f64`'s own. The
//! differential test below runs every law of the table against the law on `f64`.
//!
//! Conditions are Cranelift's `i8` truth values (0 or 1): they are combined with `band`,
//! `bor` and `bxor_imm(c, 1)` (`bnot` would turn 1 into 0xfe, which `select` reads as true).

use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{types, AbiParam, InstBuilder, SigRef, Signature, Value};
use cranelift_codegen::isa::CallConv;
use cranelift_frontend::FunctionBuilder;
use std::cell::RefCell;

use crate::laws::{Arith, LawKind};

/// The signatures of the functions a law's code calls: f64 → f64 (`exp`) and
/// (f64, f64) → f64 (`pow`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Callees {
    unary: SigRef,
    binary: SigRef,
}

impl Callees {
    /// Imports the signatures into the function `b` builds.
    pub(crate) fn import(b: &mut FunctionBuilder, call_conv: CallConv) -> Self {
        let mut sig = |params: usize| {
            let mut s = Signature::new(call_conv);
            s.params
                .extend((0..params).map(|_| AbiParam::new(types::F64)));
            s.returns.push(AbiParam::new(types::F64));
            b.import_signature(s)
        };
        Callees {
            unary: sig(1),
            binary: sig(2),
        }
    }
}

/// `exp` as the scalar laws compute it, for the generated code to call.
extern "C" fn exp(x: f64) -> f64 {
    x.exp()
}

/// `powf` as the scalar laws compute it, for the generated code to call.
extern "C" fn pow(x: f64, y: f64) -> f64 {
    x.powf(y)
}

/// [`Arith`] emitting into the function a builder builds (each operation appends its
/// instruction to the current block).
pub(crate) struct Ir<'a, 'b> {
    b: RefCell<&'a mut FunctionBuilder<'b>>,
    callees: Callees,
}

impl<'a, 'b> Ir<'a, 'b> {
    pub(crate) fn new(b: &'a mut FunctionBuilder<'b>, callees: Callees) -> Self {
        Ir {
            b: RefCell::new(b),
            callees,
        }
    }

    fn call(&self, sig: SigRef, f: i64, args: &[Value]) -> Value {
        let mut b = self.b.borrow_mut();
        let callee = b.ins().iconst(types::I64, f);
        let call = b.ins().call_indirect(sig, callee, args);
        b.inst_results(call)[0]
    }

    fn cmp(&self, cc: FloatCC, a: Value, c: Value) -> Value {
        self.b.borrow_mut().ins().fcmp(cc, a, c)
    }
}

/// Emits `law(Δx, Δv, args)` and returns the force f (the caller applies F₁ −= f, F₂ += f).
pub(crate) fn emit(
    b: &mut FunctionBuilder,
    law: LawKind,
    dx: Value,
    dv: Value,
    args: &[Value],
    callees: Callees,
) -> Value {
    law.force(&Ir::new(b, callees), dx, dv, args)
}

impl Arith for Ir<'_, '_> {
    type F = Value;
    type M = Value;

    fn num(&self, c: f64) -> Value {
        self.b.borrow_mut().ins().f64const(c)
    }
    fn add(&self, a: Value, c: Value) -> Value {
        self.b.borrow_mut().ins().fadd(a, c)
    }
    fn sub(&self, a: Value, c: Value) -> Value {
        self.b.borrow_mut().ins().fsub(a, c)
    }
    fn mul(&self, a: Value, c: Value) -> Value {
        self.b.borrow_mut().ins().fmul(a, c)
    }
    fn div(&self, a: Value, c: Value) -> Value {
        self.b.borrow_mut().ins().fdiv(a, c)
    }
    fn neg(&self, a: Value) -> Value {
        self.b.borrow_mut().ins().fneg(a)
    }
    fn abs(&self, a: Value) -> Value {
        self.b.borrow_mut().ins().fabs(a)
    }
    fn sign(&self, a: Value) -> Value {
        let one = self.num(1.0);
        self.b.borrow_mut().ins().fcopysign(one, a)
    }
    fn sqrt(&self, a: Value) -> Value {
        self.b.borrow_mut().ins().sqrt(a)
    }
    fn exp(&self, a: Value) -> Value {
        self.call(self.callees.unary, exp as *const () as usize as i64, &[a])
    }
    fn pow(&self, a: Value, c: Value) -> Value {
        self.call(
            self.callees.binary,
            pow as *const () as usize as i64,
            &[a, c],
        )
    }
    fn lt(&self, a: Value, c: Value) -> Value {
        self.cmp(FloatCC::LessThan, a, c)
    }
    fn le(&self, a: Value, c: Value) -> Value {
        self.cmp(FloatCC::LessThanOrEqual, a, c)
    }
    fn gt(&self, a: Value, c: Value) -> Value {
        self.cmp(FloatCC::GreaterThan, a, c)
    }
    fn ge(&self, a: Value, c: Value) -> Value {
        self.cmp(FloatCC::GreaterThanOrEqual, a, c)
    }
    fn eq(&self, a: Value, c: Value) -> Value {
        self.cmp(FloatCC::Equal, a, c)
    }
    fn and(&self, a: Value, c: Value) -> Value {
        self.b.borrow_mut().ins().band(a, c)
    }
    fn or(&self, a: Value, c: Value) -> Value {
        self.b.borrow_mut().ins().bor(a, c)
    }
    fn not(&self, a: Value) -> Value {
        self.b.borrow_mut().ins().bxor_imm(a, 1)
    }
    fn select(&self, c: Value, yes: Value, no: Value) -> Value {
        self.b.borrow_mut().ins().select(c, yes, no)
    }
    fn branch(
        &self,
        c: Value,
        yes: impl FnOnce(&Self) -> Value,
        no: impl FnOnce(&Self) -> Value,
    ) -> Value {
        let (yes_block, no_block, join, force) = {
            let mut b = self.b.borrow_mut();
            let (yes_block, no_block, join) =
                (b.create_block(), b.create_block(), b.create_block());
            let force = b.append_block_param(join, types::F64);
            b.ins().brif(c, yes_block, &[], no_block, &[]);
            b.seal_block(yes_block);
            b.seal_block(no_block);
            b.switch_to_block(yes_block);
            (yes_block, no_block, join, force)
        };
        let _ = yes_block;
        let y = yes(self);
        {
            let mut b = self.b.borrow_mut();
            b.ins().jump(join, &[y.into()]);
            b.switch_to_block(no_block);
        }
        let n = no(self);
        let mut b = self.b.borrow_mut();
        b.ins().jump(join, &[n.into()]);
        b.seal_block(join);
        b.switch_to_block(join);
        force
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::picks::{check, check_every_law, draws, Path};
    use crate::laws::Law;
    use crate::sim::jit::isa;
    use cranelift_codegen::ir::UserFuncName;
    use cranelift_codegen::Context;
    use cranelift_frontend::FunctionBuilderContext;
    use cranelift_jit::{JITBuilder, JITModule};
    use cranelift_module::{default_libcall_names, Linkage, Module};

    type LawFn = unsafe extern "C" fn(f64, f64, f64, f64, f64, f64, f64) -> f64;

    /// Compiles `L` alone as `fn(Δx, Δv, a0 … a4) -> f`.
    fn compile_law<L: Law>() -> (JITModule, LawFn) {
        let isa = isa().expect("this CPU has a Cranelift back end");
        let mut module = JITModule::new(JITBuilder::with_isa(isa, default_libcall_names()));
        let mut ctx = Context::new();
        let call_conv = module.isa().default_call_conv();
        ctx.func.signature.call_conv = call_conv;
        for _ in 0..2 + LawKind::MAX_ARITY {
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
            let callees = Callees::import(&mut b, call_conv);
            let f = L::force(&Ir::new(&mut b, callees), p[0], p[1], |c| p[2 + c]);
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

    /// Every law compiled alone, against `f64`.
    struct Native;

    impl Path for Native {
        fn check_law<L: Law>(&mut self, name: &str) {
            let (module, f) = compile_law::<L>();
            let draws = draws(40_000);
            let got: Vec<f64> = draws
                .iter()
                // SAFETY: `f` is the function compiled above, with this signature.
                .map(|d| unsafe { f(d[0], d[1], d[2], d[3], d[4], d[5], d[6]) })
                .collect();
            // SAFETY: no pointer into the module is used after this.
            unsafe { module.free_memory() };
            check::<L>(name, "native code", &draws, &got);
        }
    }

    #[test]
    fn every_law_in_native_code_equals_the_law_on_f64() {
        check_every_law(&mut Native);
    }
}
