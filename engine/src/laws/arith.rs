//! The arithmetic the interaction laws are written in, so that each law's force is written
//! once and runs on every path of the engine:
//!
//! | implementation | value | condition | where |
//! |---|---|---|---|
//! | [`Scalar`] | `f64` | `bool` | the reference kernels (`kernels/`) |
//! | `lanes::arith::Native<S>` | one native vector of `S` | its mask | the voice lanes |
//! | `jit::laws::Ir` | a Cranelift `Value` (`f64`) | a Cranelift `i8` | the native code |
//!
//! Every operation is one IEEE operation (no fused multiply-add, no reassociation), so the
//! three give the same bits for the same law (the differential tests in `jit/laws.rs` and
//! `lanes/arith.rs` run every law of [`super::LawKind::ALL`] over every branch, ±0,
//! infinities and NaN). A law's branches are computed and chosen by [`Arith::select`], which
//! vectors and native code do without a jump; [`Arith::branch`] is for a side too costly to
//! compute when it is not taken (`nlBow`'s `exp`).

/// The operations a law may use. Methods take `&self` so that a law reads as the formula
/// (`a.add(a.mul(k, dx), a.mul(z, dv))`); the native-code builder keeps its mutable state
/// inside.
pub trait Arith {
    /// A number (f64 in every lane).
    type F: Copy;
    /// A condition, from a comparison.
    type M: Copy;

    /// The constant `c`.
    fn num(&self, c: f64) -> Self::F;
    /// a + b.
    fn add(&self, a: Self::F, b: Self::F) -> Self::F;
    /// a − b.
    fn sub(&self, a: Self::F, b: Self::F) -> Self::F;
    /// a · b.
    fn mul(&self, a: Self::F, b: Self::F) -> Self::F;
    /// a / b.
    fn div(&self, a: Self::F, b: Self::F) -> Self::F;
    /// −a (the sign flipped: −0 for +0).
    fn neg(&self, a: Self::F) -> Self::F;
    /// |a|.
    fn abs(&self, a: Self::F) -> Self::F;
    /// 1 with the sign of a (`f64::signum` for every a but NaN: ±1 for ±0 too).
    fn sign(&self, a: Self::F) -> Self::F;
    /// √a.
    fn sqrt(&self, a: Self::F) -> Self::F;
    /// eᵃ, as `f64::exp` computes it.
    fn exp(&self, a: Self::F) -> Self::F;
    /// aᵇ, as `f64::powf` computes it.
    fn pow(&self, a: Self::F, b: Self::F) -> Self::F;

    /// a < b (false when either is NaN, as every comparison here).
    fn lt(&self, a: Self::F, b: Self::F) -> Self::M;
    /// a ≤ b.
    fn le(&self, a: Self::F, b: Self::F) -> Self::M;
    /// a > b.
    fn gt(&self, a: Self::F, b: Self::F) -> Self::M;
    /// a ≥ b.
    fn ge(&self, a: Self::F, b: Self::F) -> Self::M;
    /// a = b.
    fn eq(&self, a: Self::F, b: Self::F) -> Self::M;
    /// Both.
    fn and(&self, a: Self::M, b: Self::M) -> Self::M;
    /// Either.
    fn or(&self, a: Self::M, b: Self::M) -> Self::M;
    /// Not.
    fn not(&self, a: Self::M) -> Self::M;

    /// `yes` where `c` holds, else `no` (both already computed).
    fn select(&self, c: Self::M, yes: Self::F, no: Self::F) -> Self::F;

    /// `yes()` where `c` holds, else `no()`, computing a side only where it is needed: a jump
    /// for scalars and native code, both sides and a select for a vector whose lanes differ.
    fn branch(
        &self,
        c: Self::M,
        yes: impl FnOnce(&Self) -> Self::F,
        no: impl FnOnce(&Self) -> Self::F,
    ) -> Self::F;

    /// [`Arith::branch`] for a vector of `N` values: `yes()` where `c` holds, else `no()`.
    /// By default both sides are computed and selected (what vectors whose lanes differ do);
    /// scalars jump.
    #[inline(always)]
    fn branch_v<const N: usize>(
        &self,
        c: Self::M,
        yes: impl FnOnce(&Self) -> [Self::F; N],
        no: impl FnOnce(&Self) -> [Self::F; N],
    ) -> [Self::F; N] {
        let (y, n) = (yes(self), no(self));
        std::array::from_fn(|i| self.select(c, y[i], n[i]))
    }
}

/// The plain `f64` arithmetic of the reference kernels.
#[derive(Clone, Copy, Debug, Default)]
pub struct Scalar;

impl Arith for Scalar {
    type F = f64;
    type M = bool;

    #[inline(always)]
    fn num(&self, c: f64) -> f64 {
        c
    }
    #[inline(always)]
    fn add(&self, a: f64, b: f64) -> f64 {
        a + b
    }
    #[inline(always)]
    fn sub(&self, a: f64, b: f64) -> f64 {
        a - b
    }
    #[inline(always)]
    fn mul(&self, a: f64, b: f64) -> f64 {
        a * b
    }
    #[inline(always)]
    fn div(&self, a: f64, b: f64) -> f64 {
        a / b
    }
    #[inline(always)]
    fn neg(&self, a: f64) -> f64 {
        -a
    }
    #[inline(always)]
    fn abs(&self, a: f64) -> f64 {
        a.abs()
    }
    #[inline(always)]
    fn sign(&self, a: f64) -> f64 {
        1f64.copysign(a)
    }
    #[inline(always)]
    fn sqrt(&self, a: f64) -> f64 {
        a.sqrt()
    }
    #[inline(always)]
    fn exp(&self, a: f64) -> f64 {
        a.exp()
    }
    #[inline(always)]
    fn pow(&self, a: f64, b: f64) -> f64 {
        a.powf(b)
    }
    #[inline(always)]
    fn lt(&self, a: f64, b: f64) -> bool {
        a < b
    }
    #[inline(always)]
    fn le(&self, a: f64, b: f64) -> bool {
        a <= b
    }
    #[inline(always)]
    fn gt(&self, a: f64, b: f64) -> bool {
        a > b
    }
    #[inline(always)]
    fn ge(&self, a: f64, b: f64) -> bool {
        a >= b
    }
    #[inline(always)]
    fn eq(&self, a: f64, b: f64) -> bool {
        a == b
    }
    #[inline(always)]
    fn and(&self, a: bool, b: bool) -> bool {
        a & b
    }
    #[inline(always)]
    fn or(&self, a: bool, b: bool) -> bool {
        a | b
    }
    #[inline(always)]
    fn not(&self, a: bool) -> bool {
        !a
    }
    #[inline(always)]
    fn select(&self, c: bool, yes: f64, no: f64) -> f64 {
        if c {
            yes
        } else {
            no
        }
    }
    #[inline(always)]
    fn branch(
        &self,
        c: bool,
        yes: impl FnOnce(&Self) -> f64,
        no: impl FnOnce(&Self) -> f64,
    ) -> f64 {
        if c {
            yes(self)
        } else {
            no(self)
        }
    }
    #[inline(always)]
    fn branch_v<const N: usize>(
        &self,
        c: bool,
        yes: impl FnOnce(&Self) -> [f64; N],
        no: impl FnOnce(&Self) -> [f64; N],
    ) -> [f64; N] {
        if c {
            yes(self)
        } else {
            no(self)
        }
    }
}

/// The differential tests' harness: draws of (Δx, Δv, arguments…) that reach every branch of
/// every law, and the check of another path's forces against the law on `f64`. The voice
/// lanes (`lanes/arith.rs`) and the native code (`jit/laws.rs`) run every law through it.
#[cfg(test)]
pub(crate) mod picks {
    use super::{Arith, Scalar};
    use crate::laws::linear::Linear;
    use crate::laws::{Law, LawKind, LawRow, LawVisitor};

    /// Both signs, zeros, tiny and huge, infinities, NaN.
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

    /// A deterministic stream of picks: half from the values above (so that arguments are
    /// often equal, s = k), half ordinary numbers of either sign from 1e-3 to 10.
    pub(crate) struct Picks(pub u64);

    impl Picks {
        pub(crate) fn next(&mut self) -> f64 {
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

    /// One draw: Δx, Δv, then the arguments.
    pub(crate) type Draw = [f64; 2 + LawKind::MAX_ARITY];

    /// `n` draws: half from the picks, half as a model plays (Δx and Δv a thousandth of a
    /// pick, each argument 0, 1 or a positive pick, so that flags such as the bow's
    /// `smooth` take both values with the scales positive).
    pub(crate) fn draws(n: usize) -> Vec<Draw> {
        let mut picks = Picks(0x9e37_79b9_7f4a_7c15);
        (0..n)
            .map(|i| {
                let mut d: Draw = std::array::from_fn(|_| picks.next());
                if i % 2 == 1 {
                    d[0] *= 1e-3;
                    d[1] *= 1e-3;
                    for v in &mut d[2..] {
                        *v = match picks.0 % 4 {
                            0 => 0.0,
                            1 => 1.0,
                            _ => v.abs(),
                        };
                        picks.next();
                    }
                }
                d
            })
            .collect()
    }

    /// Bit-equal, or both NaN.
    pub(crate) fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// Checks `got[i]`, the force `path` computed for `draws[i]`, against `L`'s law on `f64`,
    /// bit for bit.
    pub(crate) fn check<L: Law>(name: &str, path: &str, draws: &[Draw], got: &[f64]) {
        assert_eq!(draws.len(), got.len());
        let mut mismatches = 0;
        for (d, &got) in draws.iter().zip(got) {
            let want = L::force(&Scalar, d[0], d[1], |c| d[2 + c]);
            if !same(got, want) {
                mismatches += 1;
                if mismatches < 5 {
                    eprintln!("{name} on {path}: {d:?}: {got:e}, want {want:e}");
                }
            }
        }
        assert_eq!(
            mismatches, 0,
            "{name} on {path} differs from its law on f64"
        );
    }

    /// A path of the engine that the differential test runs laws on.
    pub(crate) trait Path {
        /// Runs `L` on this path over [`draws`] and [`check`]s it.
        fn check_law<L: Law>(&mut self, name: &str);
    }

    /// Runs `path` on every law of the table, then on [`EveryOperation`].
    pub(crate) fn check_every_law(path: &mut impl Path) {
        struct Visit<'a, P>(&'a mut P, usize);
        impl<P: Path> LawVisitor for Visit<'_, P> {
            fn visit<L: Law>(&mut self, kind: LawKind) {
                self.0.check_law::<L>(&format!("{kind:?}"));
                self.1 += 1;
            }
        }
        let mut visit = Visit(path, 0);
        LawKind::visit_all(&mut visit);
        assert_eq!(visit.1, LawKind::COUNT);
        path.check_law::<EveryOperation>("every operation");
    }

    /// A formula that uses every operation of [`Arith`], checked like a law on every path,
    /// so that an operation no law uses yet is tested too.
    pub(crate) struct EveryOperation;

    impl Law for EveryOperation {
        const ROW: LawRow = LawRow {
            keyword: "everyOperation",
            columns: &[],
            required: 0,
            signature: "m1 m2",
            odd: false,
            bounded: false,
        };

        fn force<A: Arith>(a: &A, x: A::F, y: A::F, p: impl Fn(usize) -> A::F) -> A::F {
            let (u, v, w) = (p(0), p(1), p(2));
            let s = a.add(a.sub(a.mul(x, u), a.div(y, v)), a.neg(w));
            let r = a.add(a.sqrt(a.abs(x)), a.mul(a.sign(y), a.pow(a.abs(u), v)));
            let e = a.exp(a.mul(a.num(1e-3), w));
            let c = a.or(
                a.and(a.lt(x, y), a.le(u, v)),
                a.not(a.or(a.gt(w, x), a.ge(u, y))),
            );
            let t = a.select(a.eq(v, w), e, a.select(c, s, r));
            a.branch(a.gt(p(3), p(4)), |a| a.mul(t, t), |a| a.add(t, a.num(2.0)))
        }

        fn linearise(_p: &[f64], _rest_dx: Option<f64>) -> Linear {
            Linear::Free
        }
    }
}
