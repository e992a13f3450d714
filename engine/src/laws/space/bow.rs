//! `nlBow m1 m2 Znl Vscale {smooth=0} {dir}` (3-D spec §2.5.2): a friction of the relative
//! velocity, in two forms:
//!
//! * **isotropic** (no `dir`), with w = Δv and ν = |w|: smooth (smooth ≥ 1)
//!   g = 0.63·Znl·exp(−4(ν/Vscale)² + ½)·w; piecewise, with v_t = Vscale/3 and Z_e = Znl/3,
//!   g = (Znl − Z_e)·w for ν < v_t (stick), (v_t·Znl/ν − Z_e)·w for v_t ≤ ν < Vscale (slip),
//!   0 beyond. It opposes sliding in every direction and is rotation-invariant; the slip
//!   branch never divides by zero (ν ≥ v_t > 0);
//! * **directional** (`dir` given, â): the 1-D bow of spec §2.6.2 ([`crate::laws::bow`]) of
//!   p_v = â·Δv, along â: it grips along the bowing direction only.
//!
//! A non-positive Vscale gives no force, as 1-D. Both are the 1-D bow on the z axis.
//! Analyses: in stick the bow is a damper of ⅔·Znl (0.63·e^½·Znl smooth), isotropic or
//! along â; no stiffness.

use super::table::{col, dir, SpaceRow, N, V, Z};
use super::vector::{dot, norm, scale};
use super::{unit, Arith, Block, Ends, Linear3, SpaceLaw, V3};
use crate::laws::bow::{Bow as Bow1, BOW_SHARPNESS};
use crate::laws::linear::Linear;
use crate::laws::Law;

/// The isotropic bow.
pub(crate) struct Bow;
/// The directional bow.
pub(crate) struct BowDir;

const SIGNATURE: &str = "m1 m2 Znl Vscale {smooth} {dir}";

/// The stick damping, the 1-D law's.
fn stick(p: &[f64]) -> f64 {
    match Bow1::linearise(&p[..3], None) {
        Linear::Link { z, .. } => z,
        Linear::Open | Linear::Free => 0.0,
    }
}

impl SpaceLaw for Bow {
    const ROW: SpaceRow = SpaceRow {
        keyword: "nlBow",
        columns: &[col("Znl", Z), col("Vscale", V), col("smooth", N)],
        required: 2,
        signature: SIGNATURE,
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        let (z, vscale, smooth) = (p(0), p(1), p(2));
        let zero = a.num(0.0);
        let w = e.dv(a);
        let nu = a.sqrt(dot(a, w, w));
        let c = a.branch(
            a.ge(smooth, a.num(1.0)),
            |a| {
                let r = a.div(nu, vscale);
                let ex = a.exp(a.add(a.mul(a.mul(a.num(-4.0), r), r), a.num(0.5)));
                a.mul(a.mul(a.num(0.63), z), ex)
            },
            |a| {
                let sharpness = a.num(BOW_SHARPNESS);
                let v_t = a.div(vscale, sharpness);
                let z_e = a.div(z, sharpness);
                let stick = a.sub(z, z_e);
                let slip = a.sub(a.div(a.mul(v_t, z), nu), z_e);
                let beyond = a.select(a.lt(nu, vscale), slip, zero);
                a.select(a.lt(nu, v_t), stick, beyond)
            },
        );
        let c = a.select(a.gt(vscale, zero), c, zero);
        scale(a, c, w)
    }

    fn linearise(p: &[f64], _x1: [f64; 3], _x2: [f64; 3]) -> Linear3 {
        let z = stick(p);
        let mut b = Block::ZERO;
        for i in 0..3 {
            b.z[i][i] = z;
        }
        Linear3::Link(b)
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        (0.0, stick(p).abs(), true)
    }
}

impl SpaceLaw for BowDir {
    const ROW: SpaceRow = SpaceRow {
        keyword: "nlBow",
        columns: &[
            col("Znl", Z),
            col("Vscale", V),
            col("smooth", N),
            dir("dir"),
        ],
        required: 4,
        signature: SIGNATURE,
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        let axis = unit(a, [p(3), p(4), p(5)]);
        let rate = dot(a, axis, e.dv(a));
        let f = Bow1::force(a, a.num(0.0), rate, &p);
        scale(a, f, axis)
    }

    fn linearise(p: &[f64], _x1: [f64; 3], _x2: [f64; 3]) -> Linear3 {
        let raw = [p[3], p[4], p[5]];
        let n = norm(raw);
        let mut b = Block::ZERO;
        if n > 0.0 {
            let axis = raw.map(|c| c / n);
            let z = stick(p);
            for i in 0..3 {
                for j in 0..3 {
                    b.z[i][j] = z * axis[i] * axis[j];
                }
            }
        }
        Linear3::Link(b)
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        (0.0, stick(p).abs(), true)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::force;
    use super::*;
    use crate::laws::Scalar;

    /// Both forms are the 1-D bow on the z axis, moving up or down, in stick and in slip.
    #[test]
    fn both_forms_are_the_1d_law_on_the_axis() {
        for smooth in [0.0, 1.0] {
            let one = [0.08, 0.01, smooth];
            for v in [0.001f64, -0.002, 0.006, -0.009, 0.02] {
                let want = Bow1::force(&Scalar, 0.0, v, |i| one[i]);
                let g = force::<BowDir>(
                    [0.0, 0.0, v],
                    [0.0; 3],
                    [0.0; 3],
                    [0.0; 3],
                    &[0.08, 0.01, smooth, 0.0, 0.0, 1.0],
                );
                assert!((g[2] - want).abs() < 1e-15, "dir {v}: {} vs {want}", g[2]);
                let g = force::<Bow>([0.0, 0.0, v], [0.0; 3], [0.0; 3], [0.0; 3], &one);
                assert!(
                    (g[2] - want).abs() <= 1e-15 * (1.0 + want.abs()),
                    "iso {v}: {} vs {want}",
                    g[2]
                );
            }
        }
    }
}
