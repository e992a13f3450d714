//! `nlBow` (spec §2.6.2), a friction force of the relative velocity Δv:
//!
//! * smooth ≥ 1: f = 0.63·Z·Δv·exp(−4(Δv/scale)² + ½);
//! * otherwise (piecewise), with v_t = scale/σ and Z_e = Z/σ: (Z − Z_e)·Δv for |Δv| < v_t
//!   (stick), sgn(Δv)·v_t·Z − Z_e·Δv for v_t ≤ |Δv| < scale (slip), 0 beyond.
//!
//! A non-positive scale gives no force (the smooth law would divide by zero).
//!
//! Analyses: the slope at Δv = 0 (the bow rests on the string), as a damping: ⅔·Z
//! (piecewise) or 0.63·e^½·Z (smooth), for the bound and at rest alike.

use super::linear::Linear;
use super::table::{col, LawRow, N, V, Z};
use super::{Arith, Law};

/// The piecewise bow's sharpness σ.
pub const BOW_SHARPNESS: f64 = 3.0;

/// The bow.
pub(crate) struct Bow;

impl Law for Bow {
    const ROW: LawRow = LawRow {
        keyword: "nlBow",
        columns: &[col("Znl", Z), col("Vscale", V), col("smooth", N)],
        required: 2,
        signature: "m1 m2 Znl Vscale {smooth}",
        odd: false,
        bounded: false,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, _dx: A::F, dv: A::F, p: impl Fn(usize) -> A::F) -> A::F {
        let (z, scale, smooth) = (p(0), p(1), p(2));
        // The smooth profile's `exp` only where it is chosen.
        let force = a.branch(
            a.ge(smooth, a.num(1.0)),
            |a| {
                let r = a.div(dv, scale);
                let e = a.exp(a.add(a.mul(a.mul(a.num(-4.0), r), r), a.num(0.5)));
                a.mul(a.mul(a.mul(a.num(0.63), z), dv), e)
            },
            |a| {
                let sharpness = a.num(BOW_SHARPNESS);
                let v_t = a.div(scale, sharpness);
                let z_e = a.div(z, sharpness);
                let adv = a.abs(dv);
                let stick = a.mul(a.sub(z, z_e), dv);
                let slip = a.sub(a.mul(a.mul(a.sign(dv), v_t), z), a.mul(z_e, dv));
                let beyond = a.select(a.lt(adv, scale), slip, a.num(0.0));
                a.select(a.lt(adv, v_t), stick, beyond)
            },
        );
        a.select(a.gt(scale, a.num(0.0)), force, a.num(0.0))
    }

    fn linearise(p: &[f64], _rest_dx: Option<f64>) -> Linear {
        let (z, scale, smooth) = (p[0], p[1], p[2]);
        let stick = if !(scale > 0.0) {
            0.0
        } else if smooth >= 1.0 {
            0.63 * 0.5f64.exp() * z
        } else {
            2.0 / 3.0 * z
        };
        Linear::Link { k: 0.0, z: stick }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::tests::{close, scalar};

    #[test]
    fn profiles() {
        let f = |dv, z, scale, smooth| scalar::<Bow>(0.0, dv, &[z, scale, smooth]);
        let (z, scale) = (1.2, 0.001);
        // Piecewise stick, slip, free.
        assert!(close(f(0.0002, z, scale, 0.0), (z - z / 3.0) * 0.0002));
        assert!(close(
            f(-0.0005, z, scale, 0.0),
            -(scale / 3.0) * z - (z / 3.0) * -0.0005
        ));
        assert_eq!(f(0.002, z, scale, 0.0), 0.0);
        // Peak 2/9·Z·scale at v_t.
        assert!(close(f(scale / 3.0, z, scale, 0.0), 2.0 / 9.0 * z * scale));
        // Smooth: peak ≈ 0.223·Z·scale at scale/√8.
        let v = scale / 8f64.sqrt();
        let force = f(v, z, scale, 1.0);
        assert!(close(force, 0.63 * z * v * (-0.5f64 + 0.5).exp()));
        assert!((force / (z * scale) - 0.2227).abs() < 1e-3);
        // A zero scale is inert rather than NaN.
        assert_eq!(f(0.0, z, 0.0, 1.0), 0.0);
    }
}
