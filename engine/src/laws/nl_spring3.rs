//! `nlSpring3` (spec §2.5.2): f = K·Δx + Q·Δx³ + Z·Δv.
//!
//! Analyses: the linear K for the bound (the cubic term has none: noted); at rest the
//! tangent K + 3Q·Δx².

use super::linear::{BoundNote, Linear};
use super::table::{col, LawRow, K, Z};
use super::{Arith, Law};

/// The cubic spring.
pub(crate) struct NlSpring3;

impl Law for NlSpring3 {
    const ROW: LawRow = LawRow {
        keyword: "nlSpring3",
        columns: &[col("K", K), col("KnlQ", K), col("Z", Z)],
        required: 3,
        signature: "m1 m2 K KnlQ Z",
        odd: true,
        bounded: false,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, dx: A::F, dv: A::F, p: impl Fn(usize) -> A::F) -> A::F {
        let (k, q, z) = (p(0), p(1), p(2));
        let cubic = a.mul(a.mul(a.mul(q, dx), dx), dx);
        a.add(a.add(a.mul(k, dx), cubic), a.mul(z, dv))
    }

    fn linearise(p: &[f64], rest_dx: Option<f64>) -> Linear {
        let (k, q, z) = (p[0], p[1], p[2]);
        match rest_dx {
            None => Linear::Link { k, z },
            Some(dx) => Linear::Link {
                k: k + 3.0 * q * dx * dx,
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
    fn cubic() {
        let f = scalar::<NlSpring3>;
        assert!(close(
            f(-0.2, 0.1, &[1.0, 2.0, 0.5]),
            -0.2 - 2.0 * 0.008 + 0.05
        ));
    }
}
