//! `rope m1 m2 K Z L` (3-D spec §2.2.5) and `bubble m1 m2 K Z R` (§2.2.6): a spring-damper
//! engaged only beyond its length. The rope is engaged iff L ≥ 0 and q > L·L (strict), or
//! L < 0; then f = (K·e) + (Z·ė), else nothing. The bubble is the rope's law with L = R: it
//! keeps m2 inside a sphere of radius R about m1. The damping is not clamped (compat): a taut
//! rope that shortens can briefly push.
//!
//! Analyses: at rest, the spring-damper's blocks when engaged, else open; bounds K and Z.

use super::table::{col, len, SpaceRow, K, Z};
use super::vector::{central_block, central_if, norm, sub};
use super::{Arith, Ends, Linear3, SpaceLaw, V3};
use crate::laws::Law;

/// The rope.
pub(crate) struct Rope;

/// The bubble: the rope with its length called a radius.
pub(crate) struct Bubble;

/// Engaged iff (L ≥ 0 and q > L·L) or L < 0.
#[inline(always)]
fn taut<A: Arith>(a: &A, q: A::F, rest: A::F) -> A::M {
    let zero = a.num(0.0);
    a.or(
        a.and(a.ge(rest, zero), a.gt(q, a.mul(rest, rest))),
        a.lt(rest, zero),
    )
}

#[inline(always)]
fn rope_force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
    let rest = p(2);
    central_if::<A, true>(
        a,
        e,
        |a, q| taut(a, q, rest),
        |a, _, l, edot| {
            crate::laws::spring_damper::SpringDamper::force(a, a.sub(l, rest), edot, &p)
        },
    )
}

fn rope_linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
    let (k, z, rest) = (p[0], p[1], p[2]);
    let d = sub(x1, x2);
    let l = norm(d);
    if (rest >= 0.0 && l * l > rest * rest) || rest < 0.0 {
        Linear3::Link(central_block(d, k, k * (l - rest), z))
    } else {
        Linear3::Open
    }
}

impl SpaceLaw for Rope {
    const ROW: SpaceRow = SpaceRow {
        keyword: "rope",
        columns: &[col("K", K), col("Z", Z), len("L")],
        required: 3,
        signature: "m1 m2 K Z L",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        rope_force(a, e, p)
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        rope_linearise(p, x1, x2)
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        (p[0].abs(), p[1].abs(), true)
    }
}

impl SpaceLaw for Bubble {
    const ROW: SpaceRow = SpaceRow {
        keyword: "bubble",
        columns: &[col("K", K), col("Z", Z), len("R")],
        required: 3,
        signature: "m1 m2 K Z R",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        rope_force(a, e, p)
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        rope_linearise(p, x1, x2)
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        (p[0].abs(), p[1].abs(), true)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::force;
    use super::*;

    #[test]
    fn slack_inside_taut_beyond() {
        let p = [0.5, 0.0, 1.0];
        assert_eq!(
            force::<Rope>([0.9, 0.0, 0.0], [0.9, 0.0, 0.0], [0.0; 3], [0.0; 3], &p),
            [0.0; 3]
        );
        // Exactly at its length: slack (strict).
        assert_eq!(
            force::<Rope>([1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0; 3], [0.0; 3], &p),
            [0.0; 3]
        );
        let g = force::<Rope>([1.5, 0.0, 0.0], [1.5, 0.0, 0.0], [0.0; 3], [0.0; 3], &p);
        assert!((g[0] - 0.25).abs() < 1e-15);
        // A negative length is always engaged.
        let g = force::<Rope>(
            [0.5, 0.0, 0.0],
            [0.5, 0.0, 0.0],
            [0.0; 3],
            [0.0; 3],
            &[0.5, 0.0, -1.0],
        );
        assert!((g[0] - 0.75).abs() < 1e-15);
        assert_eq!(
            force::<Bubble>([1.5, 0.0, 0.0], [1.5, 0.0, 0.0], [0.0; 3], [0.0; 3], &p),
            force::<Rope>([1.5, 0.0, 0.0], [1.5, 0.0, 0.0], [0.0; 3], [0.0; 3], &p)
        );
    }
}
