//! The nonlinear springs in 3-D (3-D spec §2.4): `nlSpring2` (alias `nlSpring`),
//! `nlSpring3` and `nlSpringDamper`, each the 1-D law of spec §2.5 ([`crate::laws`]) applied
//! to the elongation e = ℓ − L and the distance rate ė, along the link. Each takes a trailing
//! rest length L. With L = 0 they are the 1-D laws on the z axis (§1.8); with L > 0 their
//! material nonlinearity adds to the geometric one every 3-D spring has (§7.5).
//!
//! Analyses: the 1-D law's slope at e as k_t, its force at rest as T (§5.1), its damping; the
//! bounds are the 1-D laws' (none for the quadratic and cubic terms, which the rule notes).

use super::table::{col, len, SpaceRow, K, Z};
use super::vector::{central, central_block, norm, sub};
use super::{Arith, Ends, Linear3, SpaceLaw, V3};
use crate::laws::linear::Linear;
use crate::laws::{Law, Scalar};

/// `nlSpring2`.
pub(crate) struct NlSpring2;
/// `nlSpring3`.
pub(crate) struct NlSpring3;
/// `nlSpringDamper`.
pub(crate) struct NlSpringDamper;

/// The radial form of the 1-D law `L`, whose columns are the 3-D law's but its last (L).
#[inline(always)]
fn radial<L: Law, A: Arith>(
    a: &A,
    e: &Ends<A::F>,
    p: impl Fn(usize) -> A::F,
    rest_slot: usize,
) -> V3<A::F> {
    let rest = p(rest_slot);
    central::<A, true>(a, e, |a, _, l, edot| L::force(a, a.sub(l, rest), edot, &p))
}

/// The blocks of the radial form of `L` at rest.
fn radial_block<L: Law>(p: &[f64], rest_slot: usize, x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
    let d = sub(x1, x2);
    let e = norm(d) - p[rest_slot];
    let one = &p[..rest_slot];
    let (k_t, z) = match L::linearise(one, Some(e)) {
        Linear::Link { k, z } => (k, z),
        Linear::Open | Linear::Free => (0.0, 0.0),
    };
    let t = L::force(&Scalar, e, 0.0, |i| one[i]);
    Linear3::Link(central_block(d, k_t, t, z))
}

/// The 1-D law's bound.
fn radial_bound<L: Law>(p: &[f64], rest_slot: usize) -> (f64, f64, bool) {
    let one = &p[..rest_slot];
    let exact = L::bound_note(one).is_none();
    match L::linearise(one, None) {
        Linear::Link { k, z } => (k.abs(), z.abs(), exact),
        Linear::Open | Linear::Free => (0.0, 0.0, exact),
    }
}

impl SpaceLaw for NlSpring2 {
    const ROW: SpaceRow = SpaceRow {
        keyword: "nlSpring2",
        columns: &[col("K", K), col("Q", K), col("Z", Z), len("L")],
        required: 4,
        signature: "m1 m2 K Q Z L",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        radial::<crate::laws::nl_spring2::NlSpring2, A>(a, e, p, 3)
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        radial_block::<crate::laws::nl_spring2::NlSpring2>(p, 3, x1, x2)
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        radial_bound::<crate::laws::nl_spring2::NlSpring2>(p, 3)
    }
}

impl SpaceLaw for NlSpring3 {
    const ROW: SpaceRow = SpaceRow {
        keyword: "nlSpring3",
        columns: &[col("K", K), col("Q", K), col("Z", Z), len("L")],
        required: 4,
        signature: "m1 m2 K Q Z L",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        radial::<crate::laws::nl_spring3::NlSpring3, A>(a, e, p, 3)
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        radial_block::<crate::laws::nl_spring3::NlSpring3>(p, 3, x1, x2)
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        radial_bound::<crate::laws::nl_spring3::NlSpring3>(p, 3)
    }
}

impl SpaceLaw for NlSpringDamper {
    const ROW: SpaceRow = SpaceRow {
        keyword: "nlSpringDamper",
        columns: &[col("s", K), col("c", K), col("k", K), col("Z", Z), len("L")],
        required: 5,
        signature: "m1 m2 s c k Z L",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        radial::<crate::laws::nl_spring_damper::NlSpringDamper, A>(a, e, p, 4)
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        radial_block::<crate::laws::nl_spring_damper::NlSpringDamper>(p, 4, x1, x2)
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        radial_bound::<crate::laws::nl_spring_damper::NlSpringDamper>(p, 4)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::force;
    use super::*;

    /// With L = 0 on the z axis each is its 1-D law (3-D spec §1.8).
    #[test]
    fn zero_length_on_the_axis_is_the_1d_law() {
        let (x1, xp1, x2, xp2): (f64, f64, f64, f64) = (0.9, 0.85, 0.2, 0.21);
        let (dx, dv) = (x1 - x2, (x1 - xp1) - (x2 - xp2));
        let g2 = force::<NlSpring2>(
            [0.0, 0.0, x1],
            [0.0, 0.0, xp1],
            [0.0, 0.0, x2],
            [0.0, 0.0, xp2],
            &[0.1, 2.0, 0.01, 0.0],
        );
        let w2 =
            crate::laws::nl_spring2::NlSpring2::force(&Scalar, dx, dv, |i| [0.1, 2.0, 0.01][i]);
        assert!((g2[2] - w2).abs() < 1e-14);
        let g3 = force::<NlSpring3>(
            [0.0, 0.0, x1],
            [0.0, 0.0, xp1],
            [0.0, 0.0, x2],
            [0.0, 0.0, xp2],
            &[0.1, 2.0, 0.01, 0.0],
        );
        let w3 =
            crate::laws::nl_spring3::NlSpring3::force(&Scalar, dx, dv, |i| [0.1, 2.0, 0.01][i]);
        assert!((g3[2] - w3).abs() < 1e-14);
        let p = [0.01, 0.1, 0.4, 0.002];
        let gd = force::<NlSpringDamper>(
            [0.0, 0.0, x1],
            [0.0, 0.0, xp1],
            [0.0, 0.0, x2],
            [0.0, 0.0, xp2],
            &[p[0], p[1], p[2], p[3], 0.0],
        );
        let wd = crate::laws::nl_spring_damper::NlSpringDamper::force(&Scalar, dx, dv, |i| p[i]);
        assert!((gd[2] - wd).abs() < 1e-14);
    }
}
