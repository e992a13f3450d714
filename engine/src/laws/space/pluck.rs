//! `nlPluck m1 m2 Knl Pscale {Z=0} {dir}` (3-D spec §2.5.1), the 1-D pluck of spec §2.6.1
//! ([`crate::laws::pluck`]) in two forms:
//!
//! * **radial** (no `dir`): the 1-D law of the distance, f = pluck(ℓ, ė), along the link: a
//!   round plectrum of reach Pscale that pushes the string away, peaks at 0.9·Knl·d_t and lets
//!   it slip past below d_t; it can push sideways too (both polarisations);
//! * **directional** (`dir` given, â its unit vector): the 1-D law of p = â·d and
//!   p_v = â·Δv, applied along â (g = f·â): an infinite plectrum edge across â.
//!
//! Both are the 1-D law on the z axis. Analyses: at rest, the 1-D law's slope (radial: along
//! the link, with T = f; directional: k·ââᵀ); bound 0.9·|Knl|, as 1-D.

use super::table::{col, dir, SpaceRow, K, N, Z};
use super::vector::{central, central_block, dot, norm, scale, sub};
use super::{unit, Arith, Block, Ends, Linear3, SpaceLaw, V3};
use crate::laws::linear::Linear;
use crate::laws::pluck::Pluck as Pluck1;
use crate::laws::{Law, Scalar};

/// The radial pluck.
pub(crate) struct Pluck;
/// The directional pluck.
pub(crate) struct PluckDir;

const SIGNATURE: &str = "m1 m2 Knl Pscale {Z} {dir}";

/// The 1-D law's bound.
fn pluck_bound(p: &[f64]) -> (f64, f64, bool) {
    match Pluck1::linearise(&p[..3], None) {
        Linear::Link { k, z } => (k.abs(), z.abs(), true),
        Linear::Open | Linear::Free => (0.0, 0.0, true),
    }
}

/// The 1-D law's slope and force at `dx` (at rest).
fn pluck_slope(p: &[f64], dx: f64) -> (f64, f64, f64) {
    let (k, z) = match Pluck1::linearise(&p[..3], Some(dx)) {
        Linear::Link { k, z } => (k, z),
        Linear::Open | Linear::Free => (0.0, 0.0),
    };
    (k, z, Pluck1::force(&Scalar, dx, 0.0, |i| p[i]))
}

impl SpaceLaw for Pluck {
    const ROW: SpaceRow = SpaceRow {
        keyword: "nlPluck",
        columns: &[col("Knl", K), col("Pscale", N), col("Z", Z)],
        required: 2,
        signature: SIGNATURE,
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        central::<A, true>(a, e, |a, _, l, edot| Pluck1::force(a, l, edot, &p))
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        let d = sub(x1, x2);
        let (k, z, t) = pluck_slope(p, norm(d));
        Linear3::Link(central_block(d, k, t, z))
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        pluck_bound(p)
    }
}

impl SpaceLaw for PluckDir {
    const ROW: SpaceRow = SpaceRow {
        keyword: "nlPluck",
        columns: &[col("Knl", K), col("Pscale", N), col("Z", Z), dir("dir")],
        required: 4,
        signature: SIGNATURE,
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        let axis = unit(a, [p(3), p(4), p(5)]);
        let along = dot(a, axis, e.d(a));
        let rate = dot(a, axis, e.dv(a));
        let f = Pluck1::force(a, along, rate, &p);
        scale(a, f, axis)
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        let raw = [p[3], p[4], p[5]];
        let n = norm(raw);
        if !(n > 0.0) {
            return Linear3::Link(Block::ZERO);
        }
        let axis = raw.map(|c| c / n);
        let d = sub(x1, x2);
        let (k, z, _) = pluck_slope(p, axis[0] * d[0] + axis[1] * d[1] + axis[2] * d[2]);
        let mut b = Block::ZERO;
        for i in 0..3 {
            for j in 0..3 {
                b.k[i][j] = k * axis[i] * axis[j];
                b.z[i][j] = z * axis[i] * axis[j];
            }
        }
        Linear3::Link(b)
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        pluck_bound(p)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::force;
    use super::*;

    /// Both forms are the 1-D pluck on the z axis.
    #[test]
    fn both_forms_are_the_1d_law_on_the_axis() {
        let one = [0.5, 0.1, 0.001];
        for (x1, xp1) in [(0.005f64, 0.004f64), (0.05, 0.06), (0.2, 0.2)] {
            let want = Pluck1::force(&Scalar, x1, x1 - xp1, |i| one[i]);
            let g = force::<PluckDir>(
                [0.0, 0.0, x1],
                [0.0, 0.0, xp1],
                [0.0; 3],
                [0.0; 3],
                &[0.5, 0.1, 0.001, 0.0, 0.0, 2.0],
            );
            assert!((g[2] - want).abs() < 1e-15, "{} vs {want}", g[2]);
            let g = force::<Pluck>([0.0, 0.0, x1], [0.0, 0.0, xp1], [0.0; 3], [0.0; 3], &one);
            assert!((g[2] - want).abs() < 1e-15, "{} vs {want}", g[2]);
        }
    }
}
