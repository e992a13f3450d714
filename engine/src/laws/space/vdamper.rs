//! `vdamper m1 m2 Z` (3-D spec §2.2.4): a vector damper, g = Z·Δv componentwise: the 1-D
//! damper applied per axis. It damps all relative motion, transverse included, needs no
//! square root and has no degenerate case; it is not rotation-objective.
//!
//! Analyses: C = Z·I; bound Z.

use super::table::{col, SpaceRow, Z};
use super::vector::scale;
use super::{Arith, Block, Ends, Linear3, SpaceLaw, V3};

/// The vector damper.
pub(crate) struct Vdamper;

impl SpaceLaw for Vdamper {
    const ROW: SpaceRow = SpaceRow {
        keyword: "vdamper",
        columns: &[col("Z", Z)],
        required: 1,
        signature: "m1 m2 Z",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        scale(a, p(0), e.dv(a))
    }

    fn linearise(p: &[f64], _x1: [f64; 3], _x2: [f64; 3]) -> Linear3 {
        let mut b = Block::ZERO;
        for i in 0..3 {
            b.z[i][i] = p[0];
        }
        Linear3::Link(b)
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
    fn damps_every_axis_of_the_relative_velocity() {
        let g = force::<Vdamper>(
            [1.0, 2.0, 3.0],
            [0.9, 2.2, 3.0],
            [0.0; 3],
            [0.1, 0.0, 0.0],
            &[0.5],
        );
        let want = [0.5 * ((1.0 - 0.9) - (0.0 - 0.1)), 0.5 * (2.0f64 - 2.2), 0.0];
        assert_eq!(g, want);
    }
}
