//! `spring`, `damper`, `springDamper` (spec §2.3): f = K·Δx + Z·Δv.
//!
//! Linear, so the analyses read (K, Z) as they are, bounded or at rest.

use super::linear::Linear;
use super::table::{col, LawRow, K, Z};
use super::{Arith, Law, Scalar};

/// The linear spring-damper.
pub(crate) struct SpringDamper;

impl Law for SpringDamper {
    const ROW: LawRow = LawRow {
        keyword: "springDamper",
        columns: &[col("K", K), col("Z", Z)],
        required: 2,
        signature: "m1 m2 K Z",
        odd: true,
        bounded: false,
    };

    #[inline(always)]
    fn force<A: Arith>(a: &A, dx: A::F, dv: A::F, p: impl Fn(usize) -> A::F) -> A::F {
        let (k, z) = (p(0), p(1));
        a.add(a.mul(k, dx), a.mul(z, dv))
    }

    fn linearise(p: &[f64], _rest_dx: Option<f64>) -> Linear {
        Linear::Link { k: p[0], z: p[1] }
    }
}

/// The spring-damper on plain numbers, for the string and mesh kernels (`kernels/`).
#[inline(always)]
pub fn spring_damper(dx: f64, dv: f64, k: f64, z: f64) -> f64 {
    SpringDamper::force(&Scalar, dx, dv, |c| if c == 0 { k } else { z })
}
