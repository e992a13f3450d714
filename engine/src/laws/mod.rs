//! The interaction laws (spec §2.3–§2.6): each law in its own file, written once against
//! [`Arith`], and listed once in the table ([`LawKind`]).
//!
//! Every law takes the elongation Δx = x₁ − x₂ and the relative velocity
//! Δv = (x₁ − x̃₁) − (x₂ − x̃₂) (units per step, spec §1.3) and its per-step arguments, and
//! returns the scalar force f; the caller applies F₁ −= f, F₂ += f. The same function is the
//! reference kernels' law (on `f64`), the voice lanes' (on native vectors) and the native
//! code's (on Cranelift values), so the three paths compute the same bits by construction;
//! the differential tests check it over every branch.
//!
//! Adding a law: a file here with a type that implements [`Law`] (its [`LawRow`], its force,
//! its slope for the analyses, its unit tests), its `mod` line and its row in the table
//! below. Nothing else: the parser, the printer, the compiler, the three kernels and the
//! analyses all read the table ([`table`]).

mod arith;
mod classes;
mod cubic;
pub(crate) mod linear;
pub(crate) mod nodes;
pub(crate) use classes::{ArgClass, NUM_ARG_CLASSES};
/// The 3-D laws (3-D spec §2), their own table.
pub mod space;
mod table;

// The laws, one file each.
mod bow;
mod contact;
mod felt;
mod nl_contact;
mod nl_spring2;
mod nl_spring3;
mod nl_spring_damper;
mod pluck;
mod spring_damper;

// The table: one row per law, in group order (the order the kernels apply them in).
table::laws! {
    /// `spring`, `damper`, `springDamper` (spec §2.3): f = K·Δx + Z·Δv.
    SpringDamper => spring_damper::SpringDamper,
    /// `contact` (spec §2.4.1).
    Contact => contact::Contact,
    /// `nlContact` (spec §2.4.2).
    NlContact => nl_contact::NlContact,
    /// `nlSpring2` (spec §2.5.1).
    NlSpring2 => nl_spring2::NlSpring2,
    /// `nlSpring3` (spec §2.5.2).
    NlSpring3 => nl_spring3::NlSpring3,
    /// `nlSpringDamper` (spec §2.5.3).
    NlSpringDamper => nl_spring_damper::NlSpringDamper,
    /// `nlPluck` (spec §2.6.1).
    Pluck => pluck::Pluck,
    /// `nlBow` (spec §2.6.2).
    Bow => bow::Bow,
    /// `feltContact`, a power-law (Hertzian) contact: a piano hammer's felt.
    Felt => felt::Felt,
}

#[cfg(test)]
pub(crate) use arith::picks;
pub use arith::{Arith, Scalar};
pub use bow::BOW_SHARPNESS;
pub use pluck::PLUCK_SHARPNESS;
pub use spring_damper::spring_damper;
pub(crate) use table::LawVisitor;
pub use table::{Column, LawRow};

use linear::{BoundNote, Linear};

/// One interaction law: its row of the table and its equations.
pub(crate) trait Law {
    /// Its keyword, columns and flags.
    const ROW: LawRow;

    /// The force f for the elongation `dx`, the relative velocity `dv` and the columns, column
    /// `c` (in [`Law::ROW`]'s order) read as `p(c)`: an accessor rather than a slice, so that
    /// a kernel reads only the columns the law uses, straight from its argument arrays.
    fn force<A: Arith>(a: &A, dx: A::F, dv: A::F, p: impl Fn(usize) -> A::F) -> A::F;

    /// Its linear stand-in: at its bounded tangent when `rest_dx` is `None`, else at rest
    /// with elongation `rest_dx` and Δv = 0 ([`LawKind::linearise`]).
    fn linearise(p: &[f64], rest_dx: Option<f64>) -> Linear;

    /// What the stability rule notes of the arguments, if anything.
    fn bound_note(_p: &[f64]) -> Option<BoundNote> {
        None
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Equal to a relative 1e-15.
    pub(crate) fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-15 * (1.0 + a.abs().max(b.abs()))
    }

    /// `L`'s force on plain numbers.
    pub(crate) fn scalar<L: Law>(dx: f64, dv: f64, p: &[f64]) -> f64 {
        L::force(&Scalar, dx, dv, |c| p[c])
    }

    /// The analyses' slopes agree with the forces: at rest, a finite difference of the force
    /// in Δx (and in Δv) matches the linear stand-in wherever the law is smooth there.
    #[test]
    fn slopes_at_rest_match_the_forces() {
        let mut picks = picks::Picks(11);
        let mut checked = 0;
        for kind in LawKind::ALL {
            for _ in 0..2000 {
                let p: [f64; LawKind::MAX_ARITY] =
                    std::array::from_fn(|_| picks.next().abs().min(5.0));
                let dx = picks.next().clamp(-3.0, 3.0);
                if !p.iter().all(|v| v.is_finite() && *v > 1e-6) || !dx.is_finite() {
                    continue;
                }
                let h = 1e-7;
                let f = |dx: f64, dv: f64| kind.force(&Scalar, dx, dv, &p);
                let (k, z) = match kind.linearise(&p, Some(dx)) {
                    Linear::Link { k, z } => (k, z),
                    Linear::Open | Linear::Free => (0.0, 0.0),
                };
                let dk = (f(dx + h, 0.0) - f(dx - h, 0.0)) / (2.0 * h);
                let dz = (f(dx, h) - f(dx, -h)) / (2.0 * h);
                // Skip kinks: where the one-sided slopes differ, the law is not smooth.
                let right = (f(dx + h, 0.0) - f(dx, 0.0)) / h;
                let left = (f(dx, 0.0) - f(dx - h, 0.0)) / h;
                let zr = (f(dx, h) - f(dx, 0.0)) / h;
                let zl = (f(dx, 0.0) - f(dx, -h)) / h;
                let tol = |a: f64, b: f64| (a - b).abs() <= 1e-4 * (1.0 + a.abs().max(b.abs()));
                if !tol(right, left) || !tol(zr, zl) {
                    continue;
                }
                assert!(
                    tol(dk, k),
                    "{kind:?} {p:?} at {dx}: slope {dk}, stand-in {k}"
                );
                assert!(
                    tol(dz, z),
                    "{kind:?} {p:?} at {dx}: damping {dz}, stand-in {z}"
                );
                checked += 1;
            }
        }
        assert!(checked > 1000, "only {checked} smooth points checked");
    }
}
