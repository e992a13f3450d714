//! Lane-wise f64 arithmetic on [`Lanes`], written with the CPU's own vectors: one 512-bit
//! register per [`Lanes`] with AVX-512, two 256-bit ones with AVX2, [`LANES`] scalars
//! otherwise (pulp's `Simd`).
//!
//! Why not plain loops over the lanes: with eight lanes, LLVM vectorises the loop over points
//! instead of the lanes, with gathers and scatters at a 64-byte stride, several times slower
//! (docs/design/simulation.md, voice lanes). Each operation here is one IEEE operation per
//! lane (no fused multiply-add), so a kernel written with them computes the same bits as the
//! lane-by-lane loop it replaces, and as the plain engine (engine test `lanes`).
//!
//! Every function that takes [`Ops`] is `#[inline(always)]`, and laws are trait methods, not
//! closures: a function or closure compiled on its own lacks the instruction set of the
//! `pulp` dispatch that calls it, and each of its vector operations becomes a call (a 15 × 15
//! mesh in lanes ran 25 times slower that way).

use super::Lanes;
use crate::laws::LawKind;
use pulp::Simd;

/// The lane-wise operations of one instruction set `S`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ops<S>(pub S);

/// A binary operation of `S` applied to every native vector of two [`Lanes`].
macro_rules! lanewise {
    ($(#[$doc:meta] $name:ident => $op:ident;)*) => {
        $(
            #[$doc]
            #[inline(always)]
            pub fn $name(self, a: Lanes, b: Lanes) -> Lanes {
                let mut out = Lanes::ZERO;
                let (o, _) = S::as_mut_simd_f64s(&mut out.0);
                let (a, _) = S::as_simd_f64s(&a.0);
                let (b, _) = S::as_simd_f64s(&b.0);
                for ((o, a), b) in o.iter_mut().zip(a).zip(b) {
                    *o = self.0.$op(*a, *b);
                }
                out
            }
        )*
    };
}

impl<S: Simd> Ops<S> {
    lanewise! {
        /// a + b.
        add => add_f64s;
        /// a − b.
        sub => sub_f64s;
        /// a · b.
        mul => mul_f64s;
    }

    /// −a (the sign flipped, as unary minus: −0 for +0).
    #[inline(always)]
    pub fn neg(self, a: Lanes) -> Lanes {
        let mut out = Lanes::ZERO;
        let (o, _) = S::as_mut_simd_f64s(&mut out.0);
        let (a, _) = S::as_simd_f64s(&a.0);
        for (o, a) in o.iter_mut().zip(a) {
            *o = self.0.neg_f64s(*a);
        }
        out
    }

    /// The largest of `level` and |d| in each lane; a NaN `d` leaves `level` (as `f64::max`
    /// does, for a `level` that is never NaN).
    #[inline(always)]
    pub fn max_abs(self, d: Lanes, level: Lanes) -> Lanes {
        let mut out = Lanes::ZERO;
        let (o, _) = S::as_mut_simd_f64s(&mut out.0);
        let (d, _) = S::as_simd_f64s(&d.0);
        let (level, _) = S::as_simd_f64s(&level.0);
        for ((o, d), level) in o.iter_mut().zip(d).zip(level) {
            // maxpd returns its second operand when either is NaN.
            *o = self.0.max_f64s(self.0.abs_f64s(*d), *level);
        }
        out
    }

    /// 0 in each lane where |v| < `below`, else v (a NaN stays).
    #[inline(always)]
    pub fn zero_below(self, v: Lanes, below: Lanes) -> Lanes {
        let mut out = Lanes::ZERO;
        let (o, _) = S::as_mut_simd_f64s(&mut out.0);
        let (v, _) = S::as_simd_f64s(&v.0);
        let (below, _) = S::as_simd_f64s(&below.0);
        let zero = self.0.splat_f64s(0.0);
        for ((o, v), below) in o.iter_mut().zip(v).zip(below) {
            let tiny = self.0.less_than_f64s(self.0.abs_f64s(*v), *below);
            *o = self.0.select_f64s(tiny, zero, *v);
        }
        out
    }

    /// 1 in each lane where |x| ≤ `limit` fails (|x| beyond it, or NaN), else `flags`' lane.
    #[inline(always)]
    pub fn flag_beyond(self, x: Lanes, limit: f64, flags: Lanes) -> Lanes {
        let mut out = Lanes::ZERO;
        let (o, _) = S::as_mut_simd_f64s(&mut out.0);
        let (x, _) = S::as_simd_f64s(&x.0);
        let (flags, _) = S::as_simd_f64s(&flags.0);
        let (limit, one) = (self.0.splat_f64s(limit), self.0.splat_f64s(1.0));
        for ((o, x), flags) in o.iter_mut().zip(x).zip(flags) {
            let within = self.0.less_than_or_equal_f64s(self.0.abs_f64s(*x), limit);
            *o = self.0.select_f64s(within, *flags, one);
        }
        out
    }
}

/// `spring`, `damper`, `springDamper` in every lane: f = K·Δx + Z·Δv, the table's law on
/// each native vector (the strings and meshes of `structures.rs`).
#[inline(always)]
pub(super) fn spring_damper<S: Simd>(o: Ops<S>, dx: Lanes, dv: Lanes, k: Lanes, z: Lanes) -> Lanes {
    let a = super::arith::Native(o.0);
    let mut out = Lanes::ZERO;
    let (out_v, _) = S::as_mut_simd_f64s(&mut out.0);
    let (dx, dv) = (S::as_simd_f64s(&dx.0).0, S::as_simd_f64s(&dv.0).0);
    let (k, z) = (S::as_simd_f64s(&k.0).0, S::as_simd_f64s(&z.0).0);
    for i in 0..out_v.len() {
        out_v[i] = LawKind::SpringDamper.force(&a, dx[i], dv[i], &[k[i], z[i]]);
    }
    out
}

/// Δx = x_a − x_b and Δv = (x_a − x̃_a) − (x_b − x̃_b) in every lane (spec §1.3).
#[inline(always)]
pub(super) fn deltas<S: Simd>(
    o: Ops<S>,
    xa: Lanes,
    xb: Lanes,
    xpa: Lanes,
    xpb: Lanes,
) -> (Lanes, Lanes) {
    (o.sub(xa, xb), o.sub(o.sub(xa, xpa), o.sub(xb, xpb)))
}
