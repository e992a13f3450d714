//! `contact` (spec §2.4.1): a conditional spring-damper, engaged iff Δx > −θ.
//!
//! f = K(Δx + θ) + Z·Δv when engaged, 0 otherwise. The damping part is not clamped, so a
//! separating contact can briefly pull (compat, §3.13 #15).
//!
//! Analyses: (K, Z), counted engaged by the stability bound; at rest (K, Z) if Δx > −θ, else
//! open.

use super::linear::Linear;
use super::table::{col, LawRow, K, N, Z};
use super::{Arith, Law};

/// The unilateral spring-damper.
pub(crate) struct Contact;

impl Law for Contact {
    const ROW: LawRow = LawRow {
        keyword: "contact",
        columns: &[col("K", K), col("Z", Z), col("thresh", N)],
        required: 2,
        signature: "m1 m2 K Z {thresh}",
        odd: false,
        bounded: false,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, dx: A::F, dv: A::F, p: impl Fn(usize) -> A::F) -> A::F {
        let (k, z, t) = (p(0), p(1), p(2));
        let f = a.add(a.mul(k, a.add(dx, t)), a.mul(z, dv));
        a.select(a.gt(dx, a.neg(t)), f, a.num(0.0))
    }

    fn linearise(p: &[f64], rest_dx: Option<f64>) -> Linear {
        let (k, z, t) = (p[0], p[1], p[2]);
        if rest_dx.is_none_or(|dx| dx > -t) {
            Linear::Link { k, z }
        } else {
            Linear::Open
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::tests::{close, scalar};

    #[test]
    fn engages_above_threshold_only() {
        let f = scalar::<Contact>;
        // Δx = −0.3, θ = 0.5: engaged, f = K(0.2) + Z·Δv.
        assert!(close(
            f(-0.3, 0.01, &[2.0, 0.5, 0.5]),
            2.0 * 0.2 + 0.5 * 0.01
        ));
        // Δx = −0.6 < −θ: free.
        assert_eq!(f(-0.6, 0.01, &[2.0, 0.5, 0.5]), 0.0);
        // Exactly at the switching point the elastic part is zero and the contact is off.
        assert_eq!(f(-0.5, 0.01, &[2.0, 0.5, 0.5]), 0.0);
    }
}
