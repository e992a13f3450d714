//! `feltContact`: a power-law (Hertzian) contact, the felt of a piano hammer (Chaigne and
//! Askenfelt 1994, after Hunt and Crossley's nonlinear contact). With the penetration
//! d = Δx + θ:
//!
//! * d > 0 (in contact): f = K·dᵖ + Z·Δv;
//! * otherwise 0.
//!
//! p = 1 is `contact` exactly (powf(d, 1) = d); felt hammers measure p ≈ 2 … 3.5, hardening
//! as they are pressed, so a harder blow is a shorter and brighter one: against a rigid stop a
//! mass m meeting the felt at speed v stays in contact for a time proportional to
//! (m/K)^(1/(p+1))·v^(−(p−1)/(p+1)). As in `contact`, the damping is not clamped, so a
//! separating hammer can briefly pull.
//!
//! Analyses: for the stability bound, its linear part as for `nlSpring2`/`nlSpring3` (K when
//! p = 1, nothing otherwise: the tangent p·K·d^(p−1) has no bound, which the rule notes) with
//! Z; at rest, p·K·d^(p−1) with Z when the felt is pressed (d > 0), else open. A felt has no
//! length of its own to bound it by: its tangent passes 4M, the limit of a mass alone, only
//! beyond the penetration (4M/pK)^(1/(p−1)), far deeper than a hammer presses a string.

use super::linear::{BoundNote, Linear};
use super::table::{col, LawRow, K, N, Z};
use super::{Arith, Law};

/// The felt-hammer contact.
pub(crate) struct Felt;

impl Law for Felt {
    const ROW: LawRow = LawRow {
        keyword: "feltContact",
        columns: &[col("K", K), col("p", N), col("Z", Z), col("thresh", N)],
        required: 3,
        signature: "m1 m2 K p Z {thresh}",
        odd: false,
        bounded: false,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, dx: A::F, dv: A::F, p: impl Fn(usize) -> A::F) -> A::F {
        let (k, exponent, z, t) = (p(0), p(1), p(2), p(3));
        let d = a.add(dx, t);
        // The power only while in contact: it is the costly part, and the felt is away from
        // the string for most of a note.
        a.branch(
            a.gt(d, a.num(0.0)),
            |a| a.add(a.mul(k, a.pow(d, exponent)), a.mul(z, dv)),
            |a| a.num(0.0),
        )
    }

    fn linearise(p: &[f64], rest_dx: Option<f64>) -> Linear {
        let (k, exponent, z, t) = (p[0], p[1], p[2], p[3]);
        match rest_dx {
            None if exponent == 1.0 => Linear::Link { k, z },
            None => Linear::Link { k: 0.0, z },
            Some(dx) if dx + t > 0.0 => Linear::Link {
                k: exponent * k * (dx + t).powf(exponent - 1.0),
                z,
            },
            Some(_) => Linear::Open,
        }
    }

    fn bound_note(p: &[f64]) -> Option<BoundNote> {
        (p[1] != 1.0).then_some(BoundNote::Unbounded)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::picks::{draws, same};
    use crate::laws::tests::{close, scalar};
    use crate::laws::LawKind;

    #[test]
    fn power_of_the_penetration_in_contact_only() {
        let f = |dx, dv, k, exponent, z, t| scalar::<Felt>(dx, dv, &[k, exponent, z, t]);
        // d = 0.02 − 0.01 + 0.03 = 0.04: f = K·d^2.5 + Z·Δv.
        let want = 3e4 * 0.04f64.powf(2.5) + 0.01 * 0.2;
        assert!(close(f(0.02 - 0.01, 0.2, 3e4, 2.5, 0.01, 0.03), want));
        // Apart, or just touching: nothing, whatever Δv.
        assert_eq!(f(-0.05, 0.2, 3e4, 2.5, 0.01, 0.03), 0.0);
        assert_eq!(f(-0.03, 0.2, 3e4, 2.5, 0.01, 0.03), 0.0);
        // Twice as deep, 2^p times the elastic force.
        let (one, two) = (
            f(0.01, 0.0, 5.0, 3.0, 0.0, 0.0),
            f(0.02, 0.0, 5.0, 3.0, 0.0, 0.0),
        );
        assert!(close(two / one, 8.0));
    }

    /// With p = 1 the felt is the linear `contact`, bit for bit.
    #[test]
    fn exponent_one_is_the_linear_contact() {
        for d in draws(20_000) {
            let (dx, dv, k, z, t) = (d[0], d[1], d[2], d[3], d[4]);
            let felt = scalar::<Felt>(dx, dv, &[k, 1.0, z, t]);
            let contact = LawKind::Contact.force(&crate::laws::Scalar, dx, dv, &[k, z, t]);
            assert!(same(felt, contact), "{d:?}: {felt:e} against {contact:e}");
        }
    }

    /// The slope the analyses use is the force's derivative in the penetration.
    #[test]
    fn slope_at_rest_is_the_tangent() {
        let (k, exponent, z, t) = (2e3, 2.5, 0.001, 0.0);
        let p = [k, exponent, z, t];
        let d = 0.01;
        let h = 1e-7;
        let numeric = (scalar::<Felt>(d + h, 0.0, &p) - scalar::<Felt>(d - h, 0.0, &p)) / (2.0 * h);
        assert_eq!(Felt::linearise(&p, None), Linear::Link { k: 0.0, z });
        let Linear::Link {
            k: slope,
            z: damping,
        } = Felt::linearise(&p, Some(d))
        else {
            panic!("pressed felt is a link");
        };
        assert!((numeric - slope).abs() < 1e-6 * slope, "{numeric} {slope}");
        assert_eq!(damping, z);
        assert_eq!(Felt::linearise(&p, Some(-0.01)), Linear::Open);
        assert_eq!(Felt::bound_note(&p), Some(BoundNote::Unbounded));
        assert_eq!(Felt::bound_note(&[k, 1.0, z, t]), None);
    }
}
