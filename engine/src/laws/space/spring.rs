//! `spring m1 m2 K L` (3-D spec §2.2.1): a central spring, f = K·e with e = ℓ − L. No
//! damping term, so no distance rate.
//!
//! With L = 0, f·u = K·d: a linear isotropic spring (§1.8); with L = `auto` it is stress-free
//! at stage 0; with L < ℓ₀ it is pre-tensioned, T = K(ℓ₀ − L), transverse stiffness T/ℓ₀.
//!
//! Analyses: k_t = K, T = K·e at rest (§5.1); bound K (a tensioned linear spring's largest
//! eigenvalue at every stretch, §5.1, §5.5).

use super::table::{col, len, SpaceRow, K};
use super::vector::{central, central_block, norm, sub};
use super::{Arith, Ends, Linear3, SpaceLaw, V3};

/// The central linear spring.
pub(crate) struct Spring;

impl SpaceLaw for Spring {
    const ROW: SpaceRow = SpaceRow {
        keyword: "spring",
        columns: &[col("K", K), len("L")],
        required: 2,
        signature: "m1 m2 K L",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        let (k, rest) = (p(0), p(1));
        central::<A, false>(a, e, |a, _, l, _| a.mul(k, a.sub(l, rest)))
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        let (k, rest) = (p[0], p[1]);
        let d = sub(x1, x2);
        Linear3::Link(central_block(d, k, k * (norm(d) - rest), 0.0))
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        (p[0].abs(), 0.0, true)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::force;
    use super::*;

    #[test]
    fn pulls_along_the_link_by_the_elongation() {
        // ℓ = 5 along (3, 4, 0), L = 2: f = 0.5·3, g = (f/ℓ)·d.
        let g = force::<Spring>(
            [3.0, 4.0, 0.0],
            [3.0, 4.0, 0.0],
            [0.0; 3],
            [0.0; 3],
            &[0.5, 2.0],
        );
        let f = 0.5 * 3.0;
        assert_eq!(g, [f / 5.0 * 3.0, f / 5.0 * 4.0, 0.0]);
        // Zero length with L = 0: g = K·d exactly in the limit, 0 at coincidence (§1.4).
        let g = force::<Spring>([1.0; 3], [1.0; 3], [1.0; 3], [1.0; 3], &[0.5, 0.0]);
        assert_eq!(g, [0.0; 3]);
    }
}
