//! `nlContact` (spec §2.4.2): (s, c, k, Z, θ). If k < s then k ← s and c ← 0. Engaged iff
//! d = Δx + θ > 0; then f = f_e(d) + Z·Δv with the bounded cubic f_e ([`super::cubic`]) and
//! no extra damping.
//!
//! Analyses: the bounded tangent (k, or 3k − 2s below the tipping point); at rest, the
//! slope of the bounded cubic at d if d > 0, else open.

use super::linear::{BoundNote, Linear};
use super::table::{col, LawRow, K, N, Z};
use super::{cubic, Arith, Law};

/// The nonlinear unilateral contact.
pub(crate) struct NlContact;

impl Law for NlContact {
    const ROW: LawRow = LawRow {
        keyword: "nlContact",
        columns: &[
            col("K", K),
            col("KnlQ", K),
            col("Klim", K),
            col("Z", Z),
            col("thresh", N),
        ],
        required: 4,
        signature: "m1 m2 K KnlQ Klim Z {thresh}",
        odd: false,
        bounded: true,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, dx: A::F, dv: A::F, p: impl Fn(usize) -> A::F) -> A::F {
        let (s, c, k, z, t) = (p(0), p(1), p(2), p(3), p(4));
        let zero = a.num(0.0);
        let d = a.add(dx, t);
        let f = a.add(elastic(a, d, s, c, k), a.mul(z, dv));
        a.select(a.gt(d, zero), f, zero)
    }

    fn linearise(p: &[f64], rest_dx: Option<f64>) -> Linear {
        let (s, c, k, z, t) = (p[0], p[1], p[2], p[3], p[4]);
        let (k, c) = if k < s { (s, 0.0) } else { (k, c) };
        match rest_dx {
            None => Linear::Link {
                k: cubic::bound(s, c, k),
                z,
            },
            Some(dx) if dx + t > 0.0 => Linear::Link {
                k: cubic::slope(dx + t, s, c, k).0,
                z,
            },
            Some(_) => Linear::Open,
        }
    }

    fn bound_note(p: &[f64]) -> Option<BoundNote> {
        // `k < s` turns the cubic off.
        (p[1] < 0.0 && !(p[2] < p[0])).then_some(BoundNote::NegativeCubic)
    }
}

/// The contact's elastic force f_e(d) for the penetration `d`: the bounded cubic with the
/// k < s fix (k ← s, c ← 0). The 3-D sphere contact applies it to the elongation ℓ − D
/// (3-D spec §2.3.2).
#[inline(always)]
pub(crate) fn elastic<A: Arith>(a: &A, d: A::F, s: A::F, c: A::F, k: A::F) -> A::F {
    let swap = a.lt(k, s);
    let (k, c) = (a.select(swap, s, k), a.select(swap, a.num(0.0), c));
    cubic::force(a, d, s, c, k).0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::tests::{close, scalar};

    #[test]
    fn cubic_then_bounded_and_continuous() {
        let f = |dx, dv, s, c, k, z, t| scalar::<NlContact>(dx, dv, &[s, c, k, z, t]);
        let (s, c, k): (f64, f64, f64) = (0.01, 0.1, 0.4);
        let b = ((k - s) / c).sqrt();
        // Cubic region.
        let d = 0.5 * b;
        assert!(close(f(d, 0.0, s, c, k, 0.0, 0.0), d * (s + c * d * d)));
        // Bounded region.
        let d = 2.0 * b;
        assert!(close(f(d, 0.0, s, c, k, 0.0, 0.0), k * d));
        // Continuity at the tipping point.
        let below = f(b * (1.0 - 1e-12), 0.0, s, c, k, 0.0, 0.0);
        let above = f(b * (1.0 + 1e-12), 0.0, s, c, k, 0.0, 0.0);
        assert!((below - above).abs() < 1e-10);
        // k < s: k ← s, c ← 0, so linear with s.
        assert!(close(f(0.3, 0.0, 0.5, 3.0, 0.1, 0.0, 0.0), 0.5 * 0.3));
        // Not engaged below the threshold.
        assert_eq!(f(-0.1, 1.0, s, c, k, 0.3, 0.05), 0.0);
        // No extra damping in the bounded region.
        assert!(close(f(d, 0.2, s, c, k, 0.01, 0.0), k * d + 0.01 * 0.2));
    }
}
