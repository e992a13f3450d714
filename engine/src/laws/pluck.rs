//! `nlPluck` (spec §2.6.1): a repulsive piecewise-linear tent with d_t = scale/σ, K_e = K/σ:
//!
//! * |Δx| < d_t: f = −(K − K_e)·Δx;
//! * d_t ≤ |Δx| < scale: f = −sgn(Δx)·d_t·K + K_e·Δx + Z·Δv;
//! * otherwise 0.
//!
//! NORMATIVE: the damping Z acts only in the outer band.
//!
//! Analyses: 0.9·|K| with Z for the bound (the tent's steepest slope); at rest −(K − K/σ)
//! without damping inside d_t, K/σ with Z in the outer band, nothing beyond the scale.

use super::linear::Linear;
use super::table::{col, LawRow, K, N, Z};
use super::{Arith, Law};

/// The pluck's sharpness σ.
pub const PLUCK_SHARPNESS: f64 = 10.0;

/// The plectrum.
pub(crate) struct Pluck;

impl Law for Pluck {
    const ROW: LawRow = LawRow {
        keyword: "nlPluck",
        columns: &[col("Knl", K), col("Pscale", N), col("Z", Z)],
        required: 2,
        signature: "m1 m2 Knl Pscale {Z}",
        odd: false,
        bounded: false,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, dx: A::F, dv: A::F, p: impl Fn(usize) -> A::F) -> A::F {
        let (k, scale, z) = (p(0), p(1), p(2));
        let sharpness = a.num(PLUCK_SHARPNESS);
        let d_t = a.div(scale, sharpness);
        let k_e = a.div(k, sharpness);
        let adx = a.abs(dx);
        let inner = a.mul(a.neg(a.sub(k, k_e)), dx);
        // sgn(Δx) is ±1 in every band a value reaches (a NaN Δx reaches none).
        let band = a.mul(a.mul(a.neg(a.sign(dx)), d_t), k);
        let outer = a.add(a.add(band, a.mul(k_e, dx)), a.mul(z, dv));
        let beyond = a.select(a.lt(adx, scale), outer, a.num(0.0));
        a.select(a.lt(adx, d_t), inner, beyond)
    }

    fn linearise(p: &[f64], rest_dx: Option<f64>) -> Linear {
        let (k, scale, z) = (p[0], p[1], p[2]);
        match rest_dx {
            None => Linear::Link {
                k: 0.9 * k.abs(),
                z,
            },
            Some(dx) if dx.abs() < scale / PLUCK_SHARPNESS => Linear::Link {
                k: -(k - k / PLUCK_SHARPNESS),
                z: 0.0,
            },
            Some(dx) if dx.abs() < scale => Linear::Link {
                k: k / PLUCK_SHARPNESS,
                z,
            },
            Some(_) => Linear::Free,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::tests::{close, scalar};

    #[test]
    fn tent_and_outer_band_damping() {
        let f = |dx, dv, k, scale, z| scalar::<Pluck>(dx, dv, &[k, scale, z]);
        let (k, scale, z) = (0.5, 0.1, 0.001);
        let (d_t, k_e) = (0.01, 0.05);
        // Inner band: no damping whatever Δv.
        assert!(close(f(0.005, 3.0, k, scale, z), -(k - k_e) * 0.005));
        // Outer band: damping applies.
        assert!(close(
            f(-0.05, 3.0, k, scale, z),
            d_t * k + k_e * -0.05 + z * 3.0
        ));
        // Beyond the scale: nothing.
        assert_eq!(f(0.1, 3.0, k, scale, z), 0.0);
        // Peak 0.9·K·d_t at |Δx| = d_t, continuous from both sides.
        let inner = f(d_t * (1.0 - 1e-12), 0.0, k, scale, 0.0);
        let outer = f(d_t, 0.0, k, scale, 0.0);
        assert!((inner - outer).abs() < 1e-12);
        assert!((outer + 0.9 * k * d_t).abs() < 1e-15);
    }
}
