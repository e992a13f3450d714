//! The laws of [`crate::laws`] in every lane: [`Arith`] on the CPU's native vectors, so each
//! lane runs the scalar law's IEEE operations in the same order. A law's branches are all
//! computed and each lane's chosen by a comparison mask (a select), so each lane gets the
//! scalar law's bits (the differential test below, every law over every branch, ±0,
//! infinities and NaN). `exp` and `pow` run lane by lane through `f64`'s own, and a
//! [`Arith::branch`] computes only the side every lane takes (`nlBow`'s profiles).

use super::vector::Ops;
use super::Lanes;
use crate::laws::{Arith, Law, LawKind};
use pulp::Simd;
use std::marker::PhantomData;

/// [`Arith`] on one native vector of the instruction set `S`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Native<S>(pub S);

impl<S: Simd> Native<S> {
    /// `op` on each element of `v`, through memory.
    #[inline(always)]
    fn each(self, v: S::f64s, w: S::f64s, op: impl Fn(f64, f64) -> f64) -> S::f64s {
        let (mut a, mut b) = (Lanes::ZERO, Lanes::ZERO);
        S::as_mut_simd_f64s(&mut a.0).0[0] = v;
        S::as_mut_simd_f64s(&mut b.0).0[0] = w;
        for (a, b) in a.0[..S::F64_LANES].iter_mut().zip(&b.0) {
            *a = op(*a, *b);
        }
        S::as_simd_f64s(&a.0).0[0]
    }

    /// No lane holds `c`.
    #[inline(always)]
    fn none(self, c: S::m64s) -> bool {
        self.0.first_true_m64s(c) >= S::F64_LANES
    }
}

impl<S: Simd> Arith for Native<S> {
    type F = S::f64s;
    type M = S::m64s;

    #[inline(always)]
    fn num(&self, c: f64) -> S::f64s {
        self.0.splat_f64s(c)
    }
    #[inline(always)]
    fn add(&self, a: S::f64s, b: S::f64s) -> S::f64s {
        self.0.add_f64s(a, b)
    }
    #[inline(always)]
    fn sub(&self, a: S::f64s, b: S::f64s) -> S::f64s {
        self.0.sub_f64s(a, b)
    }
    #[inline(always)]
    fn mul(&self, a: S::f64s, b: S::f64s) -> S::f64s {
        self.0.mul_f64s(a, b)
    }
    #[inline(always)]
    fn div(&self, a: S::f64s, b: S::f64s) -> S::f64s {
        self.0.div_f64s(a, b)
    }
    #[inline(always)]
    fn neg(&self, a: S::f64s) -> S::f64s {
        self.0.neg_f64s(a)
    }
    #[inline(always)]
    fn abs(&self, a: S::f64s) -> S::f64s {
        self.0.abs_f64s(a)
    }
    #[inline(always)]
    fn sign(&self, a: S::f64s) -> S::f64s {
        // 1 with a's sign bit: (a & −0) | 1.
        let v = self.0;
        v.or_f64s(v.and_f64s(a, v.splat_f64s(-0.0)), v.splat_f64s(1.0))
    }
    #[inline(always)]
    fn sqrt(&self, a: S::f64s) -> S::f64s {
        self.0.sqrt_f64s(a)
    }
    #[inline(always)]
    fn exp(&self, a: S::f64s) -> S::f64s {
        self.each(a, a, |x, _| x.exp())
    }
    #[inline(always)]
    fn pow(&self, a: S::f64s, b: S::f64s) -> S::f64s {
        self.each(a, b, f64::powf)
    }
    #[inline(always)]
    fn lt(&self, a: S::f64s, b: S::f64s) -> S::m64s {
        self.0.less_than_f64s(a, b)
    }
    #[inline(always)]
    fn le(&self, a: S::f64s, b: S::f64s) -> S::m64s {
        self.0.less_than_or_equal_f64s(a, b)
    }
    #[inline(always)]
    fn gt(&self, a: S::f64s, b: S::f64s) -> S::m64s {
        self.0.greater_than_f64s(a, b)
    }
    #[inline(always)]
    fn ge(&self, a: S::f64s, b: S::f64s) -> S::m64s {
        self.0.greater_than_or_equal_f64s(a, b)
    }
    #[inline(always)]
    fn eq(&self, a: S::f64s, b: S::f64s) -> S::m64s {
        self.0.equal_f64s(a, b)
    }
    #[inline(always)]
    fn and(&self, a: S::m64s, b: S::m64s) -> S::m64s {
        self.0.and_m64s(a, b)
    }
    #[inline(always)]
    fn or(&self, a: S::m64s, b: S::m64s) -> S::m64s {
        self.0.or_m64s(a, b)
    }
    #[inline(always)]
    fn not(&self, a: S::m64s) -> S::m64s {
        self.0.not_m64s(a)
    }
    #[inline(always)]
    fn select(&self, c: S::m64s, yes: S::f64s, no: S::f64s) -> S::f64s {
        self.0.select_f64s(c, yes, no)
    }
    #[inline(always)]
    fn branch(
        &self,
        c: S::m64s,
        yes: impl FnOnce(&Self) -> S::f64s,
        no: impl FnOnce(&Self) -> S::f64s,
    ) -> S::f64s {
        if self.none(c) {
            no(self)
        } else if self.none(self.not(c)) {
            yes(self)
        } else {
            let (y, n) = (yes(self), no(self));
            self.select(c, y, n)
        }
    }
}

const _: () = assert!(LawKind::MAX_ARITY == 5, "TableLaw reads five columns");

/// The law `L` on a group's links in every lane: its argument columns, one [`Lanes`] per link.
pub(super) struct TableLaw<'a, L> {
    pub cols: [&'a [Lanes]; LawKind::MAX_ARITY],
    pub law: PhantomData<L>,
}

impl<L: Law> super::links::LaneLaw for TableLaw<'_, L> {
    type Args = [Lanes; LawKind::MAX_ARITY];

    #[inline(always)]
    fn args(&self, i: usize) -> Self::Args {
        // Element by element, not `array::from_fn`: this way the unused columns' zeros and
        // the copies fold away (from_fn's loop kept the array in memory, 3 % more
        // instructions in a bank of Drunk Triangles voices).
        let arity = L::ROW.columns.len();
        let get = |c: usize| {
            if c < arity {
                self.cols[c][i]
            } else {
                Lanes::ZERO
            }
        };
        [get(0), get(1), get(2), get(3), get(4)]
    }

    #[inline(always)]
    fn force<S: Simd>(&self, o: Ops<S>, args: Self::Args, dx: Lanes, dv: Lanes) -> Lanes {
        law_in_lanes::<S, L>(o.0, dx, dv, &args)
    }
}

/// `L`'s force in every lane, native vector by native vector.
#[inline(always)]
fn law_in_lanes<S: Simd, L: Law>(
    simd: S,
    dx: Lanes,
    dv: Lanes,
    args: &[Lanes; LawKind::MAX_ARITY],
) -> Lanes {
    let a = Native(simd);
    let mut out = Lanes::ZERO;
    let (out_v, _) = S::as_mut_simd_f64s(&mut out.0);
    let (dx, _) = S::as_simd_f64s(&dx.0);
    let (dv, _) = S::as_simd_f64s(&dv.0);
    let p = |c: usize| S::as_simd_f64s(&args[c].0).0;
    let (p0, p1, p2, p3, p4) = (p(0), p(1), p(2), p(3), p(4));
    for i in 0..out_v.len() {
        let arg = |c: usize| match c {
            0 => p0[i],
            1 => p1[i],
            2 => p2[i],
            3 => p3[i],
            _ => p4[i],
        };
        out_v[i] = L::force(&a, dx[i], dv[i], arg);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::picks::{check, check_every_law, draws, Draw, Path};
    use crate::sim::lanes::LANES;

    /// Runs a law on one [`Lanes`] of draws.
    struct Run<'a, L> {
        draws: &'a [Draw],
        law: PhantomData<L>,
    }

    impl<L: Law> pulp::WithSimd for Run<'_, L> {
        type Output = Lanes;
        #[inline(always)]
        fn with_simd<S: Simd>(self, simd: S) -> Lanes {
            let column = |c: usize| Lanes(std::array::from_fn(|l| self.draws[l][c]));
            let args = std::array::from_fn(|c| column(2 + c));
            law_in_lanes::<S, L>(simd, column(0), column(1), &args)
        }
    }

    /// Every law on the CPU's instruction set and on pulp's scalar one, against `f64`.
    struct InLanes;

    impl Path for InLanes {
        fn check_law<L: Law>(&mut self, name: &str) {
            let draws = draws(LANES * 4000);
            let (mut native, mut scalar) = (Vec::new(), Vec::new());
            for chunk in draws.chunks_exact(LANES) {
                let run = || Run::<L> {
                    draws: chunk,
                    law: PhantomData,
                };
                native.extend(pulp::Arch::new().dispatch(run()).0);
                scalar.extend(pulp::Scalar::new().vectorize(run()).0);
            }
            check::<L>(name, "lanes (this CPU)", &draws, &native);
            check::<L>(name, "lanes (scalar)", &draws, &scalar);
        }
    }

    #[test]
    fn every_law_in_lanes_equals_the_law_on_f64() {
        check_every_law(&mut InLanes);
    }
}
