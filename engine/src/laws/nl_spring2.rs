//! `nlSpring2` (spec §2.5.1, alias `nlSpring`): f = K·Δx + Q·sgn(Δx)·Δx² + Z·Δv, written
//! K·Δx + Q·Δx·|Δx| + Z·Δv (sgn(0) = 0 follows).
//!
//! Analyses: the linear K for the bound (the quadratic term has none: noted); at rest the
//! tangent K + 2Q·|Δx|.

use super::linear::{BoundNote, Linear};
use super::table::{col, LawRow, K, Z};
use super::{Arith, Law};

/// The quadratic spring.
pub(crate) struct NlSpring2;

impl Law for NlSpring2 {
    const ROW: LawRow = LawRow {
        keyword: "nlSpring2",
        columns: &[col("K", K), col("KnlP", K), col("Z", Z)],
        required: 3,
        signature: "m1 m2 K KnlP Z",
        odd: true,
        bounded: false,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, dx: A::F, dv: A::F, p: impl Fn(usize) -> A::F) -> A::F {
        let (k, q, z) = (p(0), p(1), p(2));
        let quadratic = a.mul(a.mul(q, dx), a.abs(dx));
        a.add(a.add(a.mul(k, dx), quadratic), a.mul(z, dv))
    }

    fn linearise(p: &[f64], rest_dx: Option<f64>) -> Linear {
        let (k, q, z) = (p[0], p[1], p[2]);
        match rest_dx {
            None => Linear::Link { k, z },
            Some(dx) => Linear::Link {
                k: k + 2.0 * q * dx.abs(),
                z,
            },
        }
    }

    fn bound_note(p: &[f64]) -> Option<BoundNote> {
        (p[1] != 0.0).then_some(BoundNote::Unbounded)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::tests::{close, scalar};

    #[test]
    fn quadratic_with_the_sign_of_the_elongation() {
        let f = scalar::<NlSpring2>;
        assert!(close(
            f(-0.2, 0.1, &[1.0, 2.0, 0.5]),
            -0.2 - 2.0 * 0.04 + 0.05
        ));
        assert_eq!(f(0.0, 0.0, &[1.0, 2.0, 0.5]), 0.0);
    }
}
