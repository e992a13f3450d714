//! `contact m1 m2 K Z D {Zt=0} {mu=0}` (3-D spec §2.3.1, §2.3.4): two spheres whose radii sum
//! to D. Engaged iff D > 0 and q < D·D (strict); then f = (K·e) + (Z·ė) with e = ℓ − D < 0
//! (the 1-D spring-damper's law, repulsive, zero at the switching distance), along the link.
//! The damping is not clamped (compat: briefly sticky while the spheres separate).
//!
//! With Zt > 0, a regularised Coulomb friction acts on the tangential relative velocity while
//! engaged ([`super::vector::friction`]), capped at μ·|f| when μ > 0.
//!
//! On the z axis with endpoint 2 above endpoint 1 this is the 1-D `contact` with θ = D (§1.8).
//!
//! Analyses: at rest, k_t = K, T = K·e (negative: a compressed contact's transverse term is
//! negative), C = Z·uuᵀ when engaged, else open; the friction counts in the damping bound.

use super::table::{col, len, SpaceRow, K, N, Z};
use super::vector::{central_block, dot, friction, map3, norm, scale, sub};
use super::{Arith, Ends, Linear3, SpaceLaw, V3};
use crate::laws::Law;

/// The sphere–sphere contact.
pub(crate) struct Contact;

impl SpaceLaw for Contact {
    const ROW: SpaceRow = SpaceRow {
        keyword: "contact",
        columns: &[
            col("K", K),
            col("Z", Z),
            len("D"),
            col("Zt", Z),
            col("mu", N),
        ],
        required: 3,
        signature: "m1 m2 K Z D {Zt} {mu}",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        let (reach, zt, mu) = (p(2), p(3), p(4));
        let zero = a.num(0.0);
        let d = e.d(a);
        let q = dot(a, d, d);
        let on = a.and(a.gt(reach, zero), a.lt(q, a.mul(reach, reach)));
        a.branch_v(
            on,
            |a| {
                let l = a.sqrt(q);
                let dp = e.dp(a);
                let edot = a.sub(l, a.sqrt(dot(a, dp, dp)));
                let f =
                    crate::laws::spring_damper::SpringDamper::force(a, a.sub(l, reach), edot, &p);
                let s = a.select(a.gt(q, zero), a.div(f, l), zero);
                let g = scale(a, s, d);
                a.branch_v(
                    a.gt(zt, zero),
                    |a| {
                        let u = scale(a, a.select(a.gt(q, zero), a.div(a.num(1.0), l), zero), d);
                        let h = friction(a, e.dv(a), u, f, zt, mu);
                        map3(|c| a.add(g[c], h[c]))
                    },
                    |_| g,
                )
            },
            |a| [a.num(0.0); 3],
        )
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        let (k, z, reach, zt) = (p[0], p[1], p[2], p[3]);
        let d = sub(x1, x2);
        let l = norm(d);
        if reach > 0.0 && l * l < reach * reach {
            let mut b = central_block(d, k, k * (l - reach), z);
            // The friction's viscous part on the tangential velocity (μ caps it, and at rest
            // the normal force is the static one).
            if zt > 0.0 && l > 0.0 {
                let u = d.map(|c| c / l);
                for i in 0..3 {
                    for j in 0..3 {
                        let eye = if i == j { 1.0 } else { 0.0 };
                        b.z[i][j] += zt * (eye - u[i] * u[j]);
                    }
                }
            }
            Linear3::Link(b)
        } else {
            Linear3::Open
        }
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        (p[0].abs(), p[1].abs() + p[3].max(0.0), true)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::force;
    use super::*;

    #[test]
    fn pushes_apart_inside_its_distance_only() {
        let p = [0.1, 0.0, 0.5, 0.0, 0.0];
        // ℓ = 0.3 < D = 0.5: f = K(ℓ − D) = −0.02, repulsive (g against d).
        let g = force::<Contact>([0.3, 0.0, 0.0], [0.3, 0.0, 0.0], [0.0; 3], [0.0; 3], &p);
        assert!((g[0] - 0.1 * (0.3f64 - 0.5)).abs() < 1e-15);
        assert_eq!(
            force::<Contact>([0.5, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0; 3], [0.0; 3], &p),
            [0.0; 3]
        );
        // D ≤ 0 never engages.
        let p = [0.1, 0.0, -0.5, 0.0, 0.0];
        assert_eq!(
            force::<Contact>([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3], &p),
            [0.0; 3]
        );
    }

    /// On the z axis with m2 above, it is the 1-D contact with θ = D (3-D spec §1.8).
    #[test]
    fn on_the_axis_it_is_the_1d_contact() {
        let (k, z, theta) = (0.2, 0.003, 0.05);
        let (x1, xp1, x2, xp2): (f64, f64, f64, f64) = (0.0, -0.001, 0.03, 0.031);
        let g = force::<Contact>(
            [0.0, 0.0, x1],
            [0.0, 0.0, xp1],
            [0.0, 0.0, x2],
            [0.0, 0.0, xp2],
            &[k, z, theta, 0.0, 0.0],
        );
        let one = crate::laws::contact::Contact::force(
            &crate::laws::Scalar,
            x1 - x2,
            (x1 - xp1) - (x2 - xp2),
            |c| [k, z, theta][c],
        );
        // F₁,z −= g_z in 3-D; F₁ −= f in 1-D.
        assert!((g[2] - one).abs() < 1e-15, "{} vs {one}", g[2]);
    }

    #[test]
    fn friction_opposes_sliding_and_is_capped() {
        // Pressed along x, sliding along y.
        let p = [0.1, 0.0, 0.5, 10.0, 0.0];
        let g = force::<Contact>([0.3, 0.01, 0.0], [0.3, 0.0, 0.0], [0.0; 3], [0.0; 3], &p);
        assert!(
            g[1] > 0.0,
            "F₁ −= g: friction pulls m1 back along −y: {g:?}"
        );
        let p = [0.1, 0.0, 0.5, 10.0, 0.5];
        let capped = force::<Contact>([0.3, 0.01, 0.0], [0.3, 0.0, 0.0], [0.0; 3], [0.0; 3], &p);
        assert!(
            capped[1] > 0.0 && capped[1] <= 0.5 * 0.1 * 0.2 + 1e-12,
            "{capped:?}"
        );
    }
}
