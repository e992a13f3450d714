//! `planeContact m K Z n c {r=0} {Zt=0} {mu=0}` (3-D spec §2.3.3, §2.3.4): a fixed half-space
//! {y : n̂·y < c} and a sphere of radius r at the point m. With s = (n̂·x) − c − r, while
//! s < 0: f_n = (−K·s) − (Z·(n̂·(x − x̃))) and F += f_n·n̂. The plane is infinitely massive:
//! the reaction is lost. The damping is not clamped (sticky near exit, as `contact`). With
//! Zt > 0, the tangential friction of §2.3.4 on the point's own velocity (F −= h).
//!
//! n̂ is the normal argument normalised ([`super::unit`]); a zero normal applies no force.
//!
//! Analyses: one endpoint; at rest, engaged: K·n̂n̂ᵀ and Z·n̂n̂ᵀ (plus Zt across), else open.

use super::table::{col, dir, SpaceRow, K, N, Z};
use super::vector::{dot, friction, map3, norm, scale};
use super::{unit, Arith, Block, Ends, Linear3, SpaceLaw, V3};

/// The plane contact.
pub(crate) struct PlaneContact;

impl SpaceLaw for PlaneContact {
    const ROW: SpaceRow = SpaceRow {
        keyword: "planeContact",
        columns: &[
            col("K", K),
            col("Z", Z),
            dir("n"),
            col("c", N),
            col("r", N),
            col("Zt", Z),
            col("mu", N),
        ],
        required: 4,
        signature: "m K Z n c {r} {Zt} {mu}",
        endpoints: 1,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        let (k, z, offset, radius, zt, mu) = (p(0), p(1), p(5), p(6), p(7), p(8));
        let zero = a.num(0.0);
        let n = unit(a, [p(2), p(3), p(4)]);
        let s = a.sub(a.sub(dot(a, n, e.x1), offset), radius);
        a.branch_v(
            a.lt(s, zero),
            |a| {
                let w = e.v1(a);
                let f_n = a.sub(a.mul(a.neg(k), s), a.mul(z, dot(a, n, w)));
                // F += f_n·n̂, so g = −f_n·n̂.
                let g = scale(a, a.neg(f_n), n);
                a.branch_v(
                    a.gt(zt, zero),
                    |a| {
                        let h = friction(a, w, n, f_n, zt, mu);
                        map3(|c| a.add(g[c], h[c]))
                    },
                    |_| g,
                )
            },
            |a| [a.num(0.0); 3],
        )
    }

    fn linearise(p: &[f64], x1: [f64; 3], _x2: [f64; 3]) -> Linear3 {
        let (k, z, offset, radius, zt) = (p[0], p[1], p[5], p[6], p[7]);
        let raw = [p[2], p[3], p[4]];
        let len = norm(raw);
        if !(len > 0.0) {
            return Linear3::Open;
        }
        let n = raw.map(|c| c / len);
        let s = n[0] * x1[0] + n[1] * x1[1] + n[2] * x1[2] - offset - radius;
        if !(s < 0.0) {
            return Linear3::Open;
        }
        let mut b = Block::ZERO;
        for i in 0..3 {
            for j in 0..3 {
                let nn = n[i] * n[j];
                let eye = if i == j { 1.0 } else { 0.0 };
                b.k[i][j] = k * nn;
                b.z[i][j] = z * nn + zt.max(0.0) * (eye - nn);
            }
        }
        Linear3::Link(b)
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        (p[0].abs(), p[1].abs() + p[7].max(0.0), true)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::force;
    use super::*;

    #[test]
    fn a_floor_pushes_up_below_its_surface() {
        // Floor z = 0, sphere radius 0.1, point at z = 0.05: s = −0.05, F += 0.05·K·ẑ.
        let p = [0.2, 0.0, 0.0, 0.0, 1.0, 0.0, 0.1, 0.0, 0.0];
        let g = force::<PlaneContact>([0.3, 0.2, 0.05], [0.3, 0.2, 0.05], [0.0; 3], [0.0; 3], &p);
        assert!(
            (-g[2] - 0.2 * 0.05).abs() < 1e-15 && g[0] == 0.0 && g[1] == 0.0,
            "{g:?}"
        );
        assert_eq!(
            force::<PlaneContact>([0.0, 0.0, 0.2], [0.0, 0.0, 0.2], [0.0; 3], [0.0; 3], &p),
            [0.0; 3]
        );
        // A wall facing +x at x = −2, written with an unnormalised normal.
        let p = [0.2, 0.0, 3.0, 0.0, 0.0, -2.0, 0.0, 0.0, 0.0];
        let g = force::<PlaneContact>([-2.1, 0.0, 0.0], [-2.1, 0.0, 0.0], [0.0; 3], [0.0; 3], &p);
        assert!((-g[0] - 0.2 * 0.1).abs() < 1e-14, "{g:?}");
        // A zero normal: no force.
        let p = [0.2, 0.0, 0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0];
        assert_eq!(
            force::<PlaneContact>([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3], &p),
            [0.0; 3]
        );
    }
}
