//! `damper m1 m2 Z` (3-D spec §2.2.2): radial damping of the distance rate, f = Z·ė with
//! ė = ℓ − ℓ̃ (the backward difference of the distance, as miPhysics damps it). It damps
//! only changes of distance: transverse motion and rigid rotation are undamped to first
//! order; `vdamper` damps all relative motion.
//!
//! Analyses: C = Z·uuᵀ at rest (§5.1); bound Z.

use super::table::{col, SpaceRow, Z};
use super::vector::{central, central_block, sub};
use super::{Arith, Ends, Linear3, SpaceLaw, V3};

/// The radial damper.
pub(crate) struct Damper;

impl SpaceLaw for Damper {
    const ROW: SpaceRow = SpaceRow {
        keyword: "damper",
        columns: &[col("Z", Z)],
        required: 1,
        signature: "m1 m2 Z",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        let z = p(0);
        central::<A, true>(a, e, |a, _, _, edot| a.mul(z, edot))
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        Linear3::Link(central_block(sub(x1, x2), 0.0, 0.0, p[0]))
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        (0.0, p[0].abs(), true)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::force;
    use super::*;

    #[test]
    fn damps_the_distance_rate_not_sliding() {
        // Separating along x by 0.1: ė = 0.1.
        let g = force::<Damper>([2.0, 0.0, 0.0], [1.9, 0.0, 0.0], [0.0; 3], [0.0; 3], &[0.3]);
        assert!((g[0] - 0.3 * (2.0 - 1.9)).abs() < 1e-15 && g[1] == 0.0 && g[2] == 0.0);
        // Sliding across at constant distance (x₂ moves on a circle): ė = 0.
        let g = force::<Damper>([1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0; 3], [0.0; 3], &[0.3]);
        assert_eq!(g, [0.0; 3]);
    }
}
