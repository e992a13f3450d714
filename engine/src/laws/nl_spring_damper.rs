//! `nlSpringDamper` (spec §2.5.3): (s, c, k, Z), always active, **without** the k < s
//! correction: the bounded cubic of Δx ([`super::cubic`]) plus Z·Δv, and in the bounded
//! region the damping is Z + 0.3·k (normative).
//!
//! Analyses: the bounded tangent with damping Z + 0.3k (Z alone for c = 0); at rest, the
//! slope at Δx with the damping of its region.

use super::linear::{BoundNote, Linear};
use super::table::{col, LawRow, K, Z};
use super::{cubic, Arith, Law};

/// The bounded nonlinear spring-damper.
pub(crate) struct NlSpringDamper;

impl Law for NlSpringDamper {
    const ROW: LawRow = LawRow {
        keyword: "nlSpringDamper",
        columns: &[col("K", K), col("KnlQ", K), col("Klim", K), col("Z", Z)],
        required: 4,
        signature: "m1 m2 K KnlQ Klim Z",
        odd: false,
        bounded: true,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, dx: A::F, dv: A::F, p: impl Fn(usize) -> A::F) -> A::F {
        let (s, c, k, z) = (p(0), p(1), p(2), p(3));
        let (fe, bounded) = cubic::force(a, dx, s, c, k);
        let damping = a.add(z, a.mul(a.num(0.3), k));
        a.add(fe, a.mul(a.select(bounded, damping, z), dv))
    }

    fn linearise(p: &[f64], rest_dx: Option<f64>) -> Linear {
        let (s, c, k, z) = (p[0], p[1], p[2], p[3]);
        let link = |k: f64, z: f64| Linear::Link { k, z };
        match rest_dx {
            None if c == 0.0 => link(s, z),
            None => link(cubic::bound(s, c, k), z + 0.3 * k),
            Some(dx) => match cubic::slope(dx, s, c, k) {
                (slope, true) => link(slope, z + 0.3 * k),
                (slope, false) => link(slope, z),
            },
        }
    }

    fn bound_note(p: &[f64]) -> Option<BoundNote> {
        if p[1] < 0.0 {
            Some(BoundNote::NegativeCubic)
        } else if p[1] != 0.0 && p[2] < p[0] {
            Some(BoundNote::WeakBound)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::tests::{close, scalar};

    #[test]
    fn extra_damping_only_when_bounded() {
        let f = |dx, dv, s, c, k, z| scalar::<NlSpringDamper>(dx, dv, &[s, c, k, z]);
        let (s, c, k, z): (f64, f64, f64, f64) = (0.03, 0.005, 0.8, 0.0002);
        let b = ((k - s) / c).sqrt();
        let dv = 0.001;
        let d = 0.5 * b;
        assert!(close(f(d, dv, s, c, k, z), d * (s + c * d * d) + z * dv));
        let d = -1.5 * b;
        assert!(close(f(d, dv, s, c, k, z), k * d + (z + 0.3 * k) * dv));
        // No k < s correction: k < s with c ≠ 0 is bounded by the weaker k.
        assert!(close(f(0.1, 0.0, 0.5, 1.0, 0.2, 0.0), 0.2 * 0.1));
        // c = 0 is linear with s.
        assert!(close(f(0.1, 0.0, 0.5, 0.0, 0.2, 0.0), 0.05));
    }
}
