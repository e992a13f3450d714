//! `springDamper m1 m2 K Z L` (3-D spec §2.2.3): f = (K·e) + (Z·ė), the 1-D spring-damper's
//! law (spec §2.3) of the elongation e = ℓ − L and the distance rate ė, along the link.
//!
//! Analyses: k_t = K, T = K·e, C = Z·uuᵀ (§5.1); bounds K and Z.

use super::table::{col, len, SpaceRow, K, Z};
use super::vector::{central, central_block, norm, sub};
use super::{Arith, Ends, Linear3, SpaceLaw, V3};
use crate::laws::Law;

/// The central spring-damper.
pub(crate) struct SpringDamper;

impl SpaceLaw for SpringDamper {
    const ROW: SpaceRow = SpaceRow {
        keyword: "springDamper",
        columns: &[col("K", K), col("Z", Z), len("L")],
        required: 3,
        signature: "m1 m2 K Z L",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        let rest = p(2);
        central::<A, true>(a, e, |a, _, l, edot| {
            crate::laws::spring_damper::SpringDamper::force(a, a.sub(l, rest), edot, &p)
        })
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        let (k, z, rest) = (p[0], p[1], p[2]);
        let d = sub(x1, x2);
        Linear3::Link(central_block(d, k, k * (norm(d) - rest), z))
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        (p[0].abs(), p[1].abs(), true)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::force;
    use super::*;

    /// On the z axis with L = 0 it is the 1-D spring-damper exactly (3-D spec §1.8).
    #[test]
    fn on_the_axis_with_zero_length_it_is_the_1d_law() {
        let (k, z) = (0.2, 0.01);
        let (x1, xp1, x2, xp2) = (0.7, 0.65, 0.1, 0.12);
        let g = force::<SpringDamper>(
            [0.0, 0.0, x1],
            [0.0, 0.0, xp1],
            [0.0, 0.0, x2],
            [0.0, 0.0, xp2],
            &[k, z, 0.0],
        );
        let dx: f64 = x1 - x2;
        let dv = (x1 - xp1) - (x2 - xp2);
        let want = k * dx + z * dv;
        assert!((g[2] - want).abs() < 1e-15, "{} vs {want}", g[2]);
        assert_eq!((g[0], g[1]), (0.0, 0.0));
    }
}
