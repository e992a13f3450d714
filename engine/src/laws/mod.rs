//! The scalar force laws of the interactions (spec §2.3–§2.6).
//!
//! Every law takes the elongation Δx = x₁ − x₂ and the relative velocity
//! Δv = (x₁ − x̃₁) − (x₂ − x̃₂) (units per step, spec §1.3) and the per-step parameters, and
//! returns the scalar force f. The caller applies F₁ −= f, F₂ += f. The kernels of
//! [`crate::engine`] call these functions, so the code here is the one place the equations live.
//!
//! [`LawKind`] lists the laws, with each one's row of the table ([`table`]) and its slope for
//! the analyses ([`linear`]).

pub(crate) mod linear;
mod table;

pub use table::{Column, LawKind, LawRow};

/// `spring`, `damper`, `springDamper` (spec §2.3): f = K·Δx + Z·Δv.
#[inline(always)]
pub fn spring_damper(dx: f64, dv: f64, k: f64, z: f64) -> f64 {
    k * dx + z * dv
}

/// `contact` (spec §2.4.1): a conditional spring-damper, engaged iff Δx > −θ.
///
/// f = K(Δx + θ) + Z·Δv when engaged, 0 otherwise. The damping part is not clamped, so a
/// separating contact can briefly pull (compat, §3.13 #15).
#[inline(always)]
pub fn contact(dx: f64, dv: f64, k: f64, z: f64, thresh: f64) -> f64 {
    if dx > -thresh {
        k * (dx + thresh) + z * dv
    } else {
        0.0
    }
}

/// The bounded cubic elastic law shared by `nlContact` and `nlSpringDamper`, without the
/// `k < s` correction: returns (force, true when in the bounded region).
///
/// * c = 0: f = s·d;
/// * s ≥ k, or c < 0: f = k·d (the bounded branch);
/// * otherwise, with the tipping distance b = √((k − s)/c): f = d(s + c·d²) for |d| ≤ b and
///   f = k·d beyond. The law is continuous at |d| = b because s·b + c·b³ = k·b.
#[inline(always)]
fn bounded_cubic(d: f64, s: f64, c: f64, k: f64) -> (f64, bool) {
    if c == 0.0 {
        (s * d, false)
    } else if s >= k || c < 0.0 {
        (k * d, true)
    } else {
        // |d| ≤ b  ⇔  c·d² ≤ k − s (c > 0), which avoids the square root.
        if c * d * d <= k - s {
            (d * (s + c * d * d), false)
        } else {
            (k * d, true)
        }
    }
}

/// `nlContact` (spec §2.4.2): (s, c, k, Z, θ). If k < s then k ← s and c ← 0. Engaged iff
/// d = Δx + θ > 0; then f = f_e(d) + Z·Δv with the bounded cubic f_e and no extra damping.
#[inline(always)]
pub fn nl_contact(dx: f64, dv: f64, s: f64, c: f64, k: f64, z: f64, thresh: f64) -> f64 {
    let d = dx + thresh;
    if d > 0.0 {
        let (k, c) = if k < s { (s, 0.0) } else { (k, c) };
        bounded_cubic(d, s, c, k).0 + z * dv
    } else {
        0.0
    }
}

/// `nlSpring2` (spec §2.5.1): f = K·Δx + Q·sgn(Δx)·Δx² + Z·Δv, with sgn(0) = 0.
#[inline(always)]
pub fn nl_spring2(dx: f64, dv: f64, k: f64, q: f64, z: f64) -> f64 {
    k * dx + q * dx * dx.abs() + z * dv
}

/// `nlSpring3` (spec §2.5.2): f = K·Δx + Q·Δx³ + Z·Δv.
#[inline(always)]
pub fn nl_spring3(dx: f64, dv: f64, k: f64, q: f64, z: f64) -> f64 {
    k * dx + q * dx * dx * dx + z * dv
}

/// `nlSpringDamper` (spec §2.5.3): (s, c, k, Z), always active, **without** the k < s
/// correction. In the bounded region the damping is Z + 0.3·k (normative).
#[inline(always)]
pub fn nl_spring_damper(dx: f64, dv: f64, s: f64, c: f64, k: f64, z: f64) -> f64 {
    let (fe, bounded) = bounded_cubic(dx, s, c, k);
    if bounded {
        fe + (z + 0.3 * k) * dv
    } else {
        fe + z * dv
    }
}

/// The pluck's sharpness σ (spec §2.6.1).
pub const PLUCK_SHARPNESS: f64 = 10.0;

/// `nlPluck` (spec §2.6.1): a repulsive piecewise-linear tent with d_t = scale/σ, K_e = K/σ:
///
/// * |Δx| < d_t: f = −(K − K_e)·Δx;
/// * d_t ≤ |Δx| < scale: f = −sgn(Δx)·d_t·K + K_e·Δx + Z·Δv;
/// * otherwise 0.
///
/// NORMATIVE: the damping Z acts only in the outer band.
#[inline(always)]
pub fn nl_pluck(dx: f64, dv: f64, k: f64, scale: f64, z: f64) -> f64 {
    let d_t = scale / PLUCK_SHARPNESS;
    let k_e = k / PLUCK_SHARPNESS;
    let adx = dx.abs();
    if adx < d_t {
        -(k - k_e) * dx
    } else if adx < scale {
        -dx.signum() * d_t * k + k_e * dx + z * dv
    } else {
        0.0
    }
}

/// The piecewise bow's sharpness σ (spec §2.6.2).
pub const BOW_SHARPNESS: f64 = 3.0;

/// `nlBow` (spec §2.6.2), a friction force of the relative velocity.
///
/// * smooth ≥ 1: f = 0.63·Z·Δv·exp(−4(Δv/scale)² + ½);
/// * otherwise (piecewise), with v_t = scale/3 and Z_e = Z/3: (Z − Z_e)·Δv for |Δv| < v_t
///   (stick), sgn(Δv)·v_t·Z − Z_e·Δv for v_t ≤ |Δv| < scale (slip), 0 beyond.
///
/// A non-positive scale gives no force (the smooth law would divide by zero).
#[inline(always)]
pub fn nl_bow(dv: f64, z: f64, scale: f64, smooth: f64) -> f64 {
    if !(scale > 0.0) {
        return 0.0;
    }
    if smooth >= 1.0 {
        let r = dv / scale;
        0.63 * z * dv * (-4.0 * r * r + 0.5).exp()
    } else {
        let v_t = scale / BOW_SHARPNESS;
        let z_e = z / BOW_SHARPNESS;
        let adv = dv.abs();
        if adv < v_t {
            (z - z_e) * dv
        } else if adv < scale {
            dv.signum() * v_t * z - z_e * dv
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-15 * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn contact_engages_above_threshold_only() {
        // Δx = -0.3, θ = 0.5: engaged, f = K(0.2) + Z·Δv.
        assert!(close(
            contact(-0.3, 0.01, 2.0, 0.5, 0.5),
            2.0 * 0.2 + 0.5 * 0.01
        ));
        // Δx = -0.6 < -θ: free.
        assert_eq!(contact(-0.6, 0.01, 2.0, 0.5, 0.5), 0.0);
        // Exactly at the switching point the elastic part is zero and the contact is off.
        assert_eq!(contact(-0.5, 0.01, 2.0, 0.5, 0.5), 0.0);
    }

    #[test]
    fn nl_contact_cubic_then_bounded_and_continuous() {
        let (s, c, k): (f64, f64, f64) = (0.01, 0.1, 0.4);
        let b = ((k - s) / c).sqrt();
        // Cubic region.
        let d = 0.5 * b;
        assert!(close(
            nl_contact(d, 0.0, s, c, k, 0.0, 0.0),
            d * (s + c * d * d)
        ));
        // Bounded region.
        let d = 2.0 * b;
        assert!(close(nl_contact(d, 0.0, s, c, k, 0.0, 0.0), k * d));
        // Continuity at the tipping point.
        let below = nl_contact(b * (1.0 - 1e-12), 0.0, s, c, k, 0.0, 0.0);
        let above = nl_contact(b * (1.0 + 1e-12), 0.0, s, c, k, 0.0, 0.0);
        assert!((below - above).abs() < 1e-10);
        // k < s: k ← s, c ← 0, so linear with s.
        assert!(close(
            nl_contact(0.3, 0.0, 0.5, 3.0, 0.1, 0.0, 0.0),
            0.5 * 0.3
        ));
        // Not engaged below the threshold.
        assert_eq!(nl_contact(-0.1, 1.0, s, c, k, 0.3, 0.05), 0.0);
        // No extra damping in the bounded region.
        assert!(close(
            nl_contact(d, 0.2, s, c, k, 0.01, 0.0),
            k * d + 0.01 * 0.2
        ));
    }

    #[test]
    fn nl_spring_damper_extra_damping_only_when_bounded() {
        let (s, c, k, z): (f64, f64, f64, f64) = (0.03, 0.005, 0.8, 0.0002);
        let b = ((k - s) / c).sqrt();
        let dv = 0.001;
        let d = 0.5 * b;
        assert!(close(
            nl_spring_damper(d, dv, s, c, k, z),
            d * (s + c * d * d) + z * dv
        ));
        let d = -1.5 * b;
        assert!(close(
            nl_spring_damper(d, dv, s, c, k, z),
            k * d + (z + 0.3 * k) * dv
        ));
        // No k < s correction: k < s with c ≠ 0 is bounded by the weaker k.
        assert!(close(
            nl_spring_damper(0.1, 0.0, 0.5, 1.0, 0.2, 0.0),
            0.2 * 0.1
        ));
        // c = 0 is linear with s.
        assert!(close(nl_spring_damper(0.1, 0.0, 0.5, 0.0, 0.2, 0.0), 0.05));
    }

    #[test]
    fn nl_springs() {
        assert!(close(
            nl_spring2(-0.2, 0.1, 1.0, 2.0, 0.5),
            -0.2 - 2.0 * 0.04 + 0.05
        ));
        assert_eq!(nl_spring2(0.0, 0.0, 1.0, 2.0, 0.5), 0.0);
        assert!(close(
            nl_spring3(-0.2, 0.1, 1.0, 2.0, 0.5),
            -0.2 - 2.0 * 0.008 + 0.05
        ));
    }

    #[test]
    fn pluck_tent_and_outer_band_damping() {
        let (k, scale, z) = (0.5, 0.1, 0.001);
        let (d_t, k_e) = (0.01, 0.05);
        // Inner band: no damping whatever Δv.
        assert!(close(nl_pluck(0.005, 3.0, k, scale, z), -(k - k_e) * 0.005));
        // Outer band: damping applies.
        assert!(close(
            nl_pluck(-0.05, 3.0, k, scale, z),
            d_t * k + k_e * -0.05 + z * 3.0
        ));
        // Beyond the scale: nothing.
        assert_eq!(nl_pluck(0.1, 3.0, k, scale, z), 0.0);
        // Peak 0.9·K·d_t at |Δx| = d_t, continuous from both sides.
        let inner = nl_pluck(d_t * (1.0 - 1e-12), 0.0, k, scale, 0.0);
        let outer = nl_pluck(d_t, 0.0, k, scale, 0.0);
        assert!((inner - outer).abs() < 1e-12);
        assert!((outer + 0.9 * k * d_t).abs() < 1e-15);
    }

    #[test]
    fn bow_profiles() {
        let (z, scale) = (1.2, 0.001);
        // Piecewise stick, slip, free.
        assert!(close(nl_bow(0.0002, z, scale, 0.0), (z - z / 3.0) * 0.0002));
        assert!(close(
            nl_bow(-0.0005, z, scale, 0.0),
            -(scale / 3.0) * z - (z / 3.0) * -0.0005
        ));
        assert_eq!(nl_bow(0.002, z, scale, 0.0), 0.0);
        // Peak 2/9·Z·scale at v_t.
        assert!(close(
            nl_bow(scale / 3.0, z, scale, 0.0),
            2.0 / 9.0 * z * scale
        ));
        // Smooth: peak ≈ 0.223·Z·scale at scale/√8.
        let v = scale / 8f64.sqrt();
        let f = nl_bow(v, z, scale, 1.0);
        assert!(close(f, 0.63 * z * v * (-0.5f64 + 0.5).exp()));
        assert!((f / (z * scale) - 0.2227).abs() < 1e-3);
        // A zero scale is inert rather than NaN.
        assert_eq!(nl_bow(0.0, z, 0.0, 1.0), 0.0);
    }
}
