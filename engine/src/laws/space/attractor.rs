//! `attractor m1 m2 A Dmin` (3-D spec §2.2.7): f = A/q beyond Dmin (engaged iff
//! q > Dmin·Dmin), an inverse-square attraction for A > 0; nothing inside Dmin. No damping.
//! A is K-class (force × length², §1.6).
//!
//! Analyses: k_t = −2A/ℓ³, T = A/ℓ² at rest (§5.1) when engaged; its stiffness has no bound
//! as ℓ → Dmin: the rule uses 2|A|/Dmin³ and says so.

use super::table::{col, SpaceRow, K, N};
use super::vector::{central_block, central_if, norm, sub};
use super::{Arith, Ends, Linear3, SpaceLaw, V3};

/// The inverse-square attractor.
pub(crate) struct Attractor;

impl SpaceLaw for Attractor {
    const ROW: SpaceRow = SpaceRow {
        keyword: "attractor",
        columns: &[col("A", K), col("Dmin", N)],
        required: 2,
        signature: "m1 m2 A Dmin",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        let (strength, dmin) = (p(0), p(1));
        central_if::<A, false>(
            a,
            e,
            |a, q| a.gt(q, a.mul(dmin, dmin)),
            |a, q, _, _| a.div(strength, q),
        )
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        let (strength, dmin) = (p[0], p[1]);
        let d = sub(x1, x2);
        let l = norm(d);
        if l * l > dmin * dmin && l > 0.0 {
            Linear3::Link(central_block(
                d,
                -2.0 * strength / (l * l * l),
                strength / (l * l),
                0.0,
            ))
        } else {
            Linear3::Open
        }
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        let dmin = p[1].abs();
        (2.0 * p[0].abs() / (dmin * dmin * dmin), 0.0, false)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::force;
    use super::*;

    #[test]
    fn inverse_square_beyond_dmin() {
        let g = force::<Attractor>(
            [2.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0; 3],
            [0.0; 3],
            &[0.8, 0.5],
        );
        // f = A/q = 0.2, g = (f/ℓ)·d = 0.2 along x (attractive: F₁ −= g pulls m1 back).
        assert!((g[0] - 0.2).abs() < 1e-15);
        assert_eq!(
            force::<Attractor>(
                [0.4, 0.0, 0.0],
                [0.4, 0.0, 0.0],
                [0.0; 3],
                [0.0; 3],
                &[0.8, 0.5]
            ),
            [0.0; 3]
        );
    }
}
