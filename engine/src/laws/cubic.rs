//! The bounded cubic elastic law shared by `nlContact` (spec §2.4.2) and `nlSpringDamper`
//! (spec §2.5.3), with its slopes for the analyses.
//!
//! * c = 0: f = s·d;
//! * s ≥ k, or c < 0: f = k·d (the bounded branch);
//! * otherwise, with the tipping distance b = √((k − s)/c): f = d(s + c·d²) for |d| ≤ b and
//!   f = k·d beyond. The law is continuous at |d| = b because s·b + c·b³ = k·b.

use super::Arith;

/// The force of the bounded cubic at `d`, and whether `d` is on the bounded branch.
///
/// |d| ≤ b ⇔ c·d² ≤ k − s (c > 0), which avoids the square root.
#[inline(always)]
pub(super) fn force<A: Arith>(a: &A, d: A::F, s: A::F, c: A::F, k: A::F) -> (A::F, A::M) {
    let zero = a.num(0.0);
    let cdd = a.mul(a.mul(c, d), d);
    let cubic = a.mul(d, a.add(s, cdd));
    let (linear_s, linear_k) = (a.mul(s, d), a.mul(k, d));
    let c_zero = a.eq(c, zero);
    // s ≥ k (written k ≤ s, false for a NaN) or c < 0: bounded whatever d; else bounded
    // beyond the tipping point.
    let flat = a.or(a.le(k, s), a.lt(c, zero));
    let within = a.le(cdd, a.sub(k, s));
    let bounded = a.and(a.not(c_zero), a.or(flat, a.not(within)));
    let force = a.select(c_zero, linear_s, a.select(bounded, linear_k, cubic));
    (force, bounded)
}

/// The tangent at d: s for c = 0, k on the bounded branch, s + 3c·d² in the cubic region;
/// and whether d is on the bounded branch.
pub(super) fn slope(d: f64, s: f64, c: f64, k: f64) -> (f64, bool) {
    if c == 0.0 {
        (s, false)
    } else if s >= k || c < 0.0 {
        (k, true)
    } else if c * d * d <= k - s {
        (s + 3.0 * c * d * d, false)
    } else {
        (k, true)
    }
}

/// The bounded tangent: s for c = 0, k when the bound is all there is, else 3k − 2s (the
/// slope at the tipping point, the steepest the cubic gets).
pub(super) fn bound(s: f64, c: f64, k: f64) -> f64 {
    if c == 0.0 {
        s
    } else if s >= k || c < 0.0 {
        k
    } else {
        3.0 * k - 2.0 * s
    }
}
