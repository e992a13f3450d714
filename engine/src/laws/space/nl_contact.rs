//! `nlContact m1 m2 s c k Z D` (3-D spec §2.3.2): the bounded cubic sphere contact. Engaged as
//! `contact` (D > 0, q < D·D); then f = f_e(e) + (Z·ė) with e = ℓ − D, where f_e is the 1-D
//! `nlContact`'s elastic law (spec §2.4.2, with its k < s fix; [`crate::laws::nl_contact`]),
//! odd, so repulsive for e < 0. On the z axis it is the 1-D `nlContact` with θ = D.
//!
//! Analyses: at rest, the cubic's slope at e and the force f_e(e); bound k (3k − 2s below the
//! tipping point), as 1-D.

use super::table::{col, len, SpaceRow, K, Z};
use super::vector::{central_block, central_if, norm, sub};
use super::{Arith, Ends, Linear3, SpaceLaw, V3};
use crate::laws::linear::Linear;
use crate::laws::Law;

/// The bounded cubic sphere contact.
pub(crate) struct NlContact;

impl SpaceLaw for NlContact {
    const ROW: SpaceRow = SpaceRow {
        keyword: "nlContact",
        columns: &[col("s", K), col("c", K), col("k", K), col("Z", Z), len("D")],
        required: 5,
        signature: "m1 m2 s c k Z D",
        endpoints: 2,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F> {
        let (s, c, k, z, reach) = (p(0), p(1), p(2), p(3), p(4));
        central_if::<A, true>(
            a,
            e,
            |a, q| a.and(a.gt(reach, a.num(0.0)), a.lt(q, a.mul(reach, reach))),
            |a, _, l, edot| {
                let fe = crate::laws::nl_contact::elastic(a, a.sub(l, reach), s, c, k);
                a.add(fe, a.mul(z, edot))
            },
        )
    }

    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3 {
        let (s, c, k, z, reach) = (p[0], p[1], p[2], p[3], p[4]);
        let d = sub(x1, x2);
        let l = norm(d);
        if !(reach > 0.0 && l * l < reach * reach) {
            return Linear3::Open;
        }
        // The 1-D law at penetration −e (θ = 0), odd: the same slope, the force negated.
        let pen = reach - l;
        let one = [s, c, k, z, 0.0];
        let slope = match crate::laws::nl_contact::NlContact::linearise(&one, Some(pen)) {
            Linear::Link { k, .. } => k,
            Linear::Open | Linear::Free => 0.0,
        };
        let t =
            -crate::laws::nl_contact::NlContact::force(&crate::laws::Scalar, pen, 0.0, |i| one[i]);
        Linear3::Link(central_block(d, slope, t, z))
    }

    fn bound(p: &[f64]) -> (f64, f64, bool) {
        match crate::laws::nl_contact::NlContact::linearise(&[p[0], p[1], p[2], p[3], 0.0], None) {
            Linear::Link { k, z } => (k.abs(), z.abs(), true),
            Linear::Open | Linear::Free => (0.0, p[3].abs(), true),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::force;
    use super::*;

    /// On the z axis with m2 above, it is the 1-D `nlContact` with θ = D.
    #[test]
    fn on_the_axis_it_is_the_1d_law() {
        let (s, c, k, z, theta) = (0.01, 0.1, 0.4, 0.002, 0.3);
        for (x2, xp2) in [(0.1, 0.11), (0.2, 0.19), (0.29, 0.3)] {
            let (x1, xp1): (f64, f64) = (0.0, 0.0);
            let g = force::<NlContact>(
                [0.0, 0.0, x1],
                [0.0, 0.0, xp1],
                [0.0, 0.0, x2],
                [0.0, 0.0, xp2],
                &[s, c, k, z, theta],
            );
            let one = crate::laws::nl_contact::NlContact::force(
                &crate::laws::Scalar,
                x1 - x2,
                (x1 - xp1) - (x2 - xp2),
                |i| [s, c, k, z, theta][i],
            );
            assert!((g[2] - one).abs() < 1e-14, "{} vs {one}", g[2]);
        }
    }
}
