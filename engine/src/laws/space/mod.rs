//! The interaction laws of 3-D models (3-D spec §2.2–§2.5): each law in its own file, written
//! once against [`Arith`], and listed once in the table ([`SpaceLawKind`]).
//!
//! A 3-D law reads the positions and delayed positions of its endpoints ([`Ends`]) and its
//! per-step arguments, and returns the vector g that the kernel applies as F₁ −= g, F₂ += g
//! (one-endpoint laws, `planeContact`, apply F₁ −= g only). Two shapes:
//!
//! * **central laws** (3-D spec §1.3, §2.2) compute a scalar f of the elongation e = ℓ − L
//!   and the distance rate ė = ℓ − ℓ̃, and apply it along u = d/ℓ: g = (f/ℓ)·d. The common
//!   evaluation, with its engagement test on q = d·d before any square root and the rule that
//!   q = 0 applies no force (§1.4), is [`central`]. The radial laws whose scalar law is a 1-D
//!   law of the 1-D table (`springDamper`, `nlSpring2/3`, `nlSpringDamper`, `nlPluck`,
//!   `nlContact`'s elastic part) call that law: one source for both dimensions;
//! * **vector laws** (`vdamper`, the isotropic and directional bow, the directional pluck,
//!   `planeContact`, the tangential friction of contacts) compute g directly.
//!
//! Adding a law: a file here with a type that implements [`SpaceLaw`] (its [`SpaceRow`], its
//! force, its linear blocks for the analyses, its unit tests), its `mod` line and its row in
//! the table below. The 3-D parser, printer, compiler, kernels and analyses read the table.

mod table;
mod vector;

// The laws, one file each (a law with a directional form keeps both in its file).
mod attractor;
mod bow;
mod contact;
mod damper;
mod nl_contact;
mod nl_springs;
mod plane;
mod pluck;
mod rope;
mod spring;
mod spring_damper;
mod vdamper;

pub(crate) use table::SpaceLawVisitor;
pub use table::{ColShape, SpaceColumn, SpaceRow};
pub(crate) use vector::{map3, unit, Ends, V3};

use super::Arith;

// The table: one row per law, in group order (the order the 3-D kernels apply them in).
table::space_laws! {
    /// `spring m1 m2 K L` (3-D spec §2.2.1): f = K·e.
    Spring => spring::Spring,
    /// `damper m1 m2 Z` (§2.2.2): f = Z·ė, radial.
    Damper => damper::Damper,
    /// `springDamper m1 m2 K Z L` (§2.2.3): f = K·e + Z·ė.
    SpringDamper => spring_damper::SpringDamper,
    /// `vdamper m1 m2 Z` (§2.2.4): g = Z·Δv.
    Vdamper => vdamper::Vdamper,
    /// `rope m1 m2 K Z L` (§2.2.5): a spring-damper engaged beyond its length.
    Rope => rope::Rope,
    /// `bubble m1 m2 K Z R` (§2.2.6): the rope's law with L = R.
    Bubble => rope::Bubble,
    /// `attractor m1 m2 A Dmin` (§2.2.7): f = A/q beyond Dmin.
    Attractor => attractor::Attractor,
    /// `contact m1 m2 K Z D {Zt} {mu}` (§2.3.1, §2.3.4): sphere–sphere.
    Contact => contact::Contact,
    /// `nlContact m1 m2 s c k Z D` (§2.3.2): the bounded cubic sphere contact.
    NlContact => nl_contact::NlContact,
    /// `planeContact m K Z n c {r} {Zt} {mu}` (§2.3.3, §2.3.4): a half-space.
    PlaneContact => plane::PlaneContact,
    /// `nlSpring2 m1 m2 K Q Z L` (§2.4).
    NlSpring2 => nl_springs::NlSpring2,
    /// `nlSpring3 m1 m2 K Q Z L` (§2.4).
    NlSpring3 => nl_springs::NlSpring3,
    /// `nlSpringDamper m1 m2 s c k Z L` (§2.4).
    NlSpringDamper => nl_springs::NlSpringDamper,
    /// `nlPluck m1 m2 Knl Pscale {Z}` (§2.5.1), radial.
    Pluck => pluck::Pluck,
    /// `nlPluck m1 m2 Knl Pscale Z dir` (§2.5.1), along a direction.
    PluckDir => pluck::PluckDir,
    /// `nlBow m1 m2 Znl Vscale {smooth}` (§2.5.2), isotropic.
    Bow => bow::Bow,
    /// `nlBow m1 m2 Znl Vscale smooth dir` (§2.5.2), along a direction.
    BowDir => bow::BowDir,
}

/// A law's 3 × 3 blocks for the analyses (3-D spec §5.1): the force on endpoint 1 about a
/// rest configuration is F₁ ≈ −k·δd − z·δv with δd, δv the relative displacement and
/// velocity of endpoint 1 to endpoint 2 (of endpoint 1 alone for a one-endpoint law).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Block {
    pub k: [[f64; 3]; 3],
    pub z: [[f64; 3]; 3],
}

impl Block {
    /// No stiffness, no damping.
    pub const ZERO: Block = Block {
        k: [[0.0; 3]; 3],
        z: [[0.0; 3]; 3],
    };
}

/// A 3-D law as the linear analyses see it at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Linear3 {
    /// Engaged: its blocks.
    Link(Block),
    /// A conditional law open at rest: no force, but a path a strike takes.
    Open,
}

/// One 3-D interaction law: its row of the table and its equations.
pub(crate) trait SpaceLaw {
    /// Its keyword, columns and endpoint count.
    const ROW: SpaceRow;

    /// The vector g (F₁ −= g, F₂ += g) for the endpoints `e`, with argument slot `c` (in
    /// [`SpaceRow::slots`] order: a vector column takes three) read as `p(c)`.
    fn force<A: Arith>(a: &A, e: &Ends<A::F>, p: impl Fn(usize) -> A::F) -> V3<A::F>;

    /// Its blocks at rest (zero velocity) with the endpoints at `x1` and `x2` (`x2` unused by
    /// a one-endpoint law), `p` its argument slots (per-step values).
    fn linearise(p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> Linear3;

    /// Its bounds for the per-point stability rule (3-D spec §5.4): the largest eigenvalue of
    /// its stiffness block over every configuration it can be in while engaged, and of its
    /// damping block. `None` when the law's stiffness has no bound (the rule then uses its
    /// small-signal slope and says so).
    fn bound(p: &[f64]) -> (f64, f64, bool);
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::laws::Scalar;

    /// `L`'s force on plain numbers for endpoints at `x1`, `x2` with delayed positions `xp1`,
    /// `xp2`.
    pub(crate) fn force<L: SpaceLaw>(
        x1: V3<f64>,
        xp1: V3<f64>,
        x2: V3<f64>,
        xp2: V3<f64>,
        p: &[f64],
    ) -> V3<f64> {
        L::force(&Scalar, &Ends { x1, xp1, x2, xp2 }, |c| p[c])
    }

    /// Every law of the table is finite and, but for the one-endpoint plane, applies equal and
    /// opposite forces; nothing panics, at coincident points either (3-D spec §1.4).
    #[test]
    fn every_law_is_finite_at_coincident_points() {
        for kind in SpaceLawKind::ALL {
            let slots = kind.row().slots();
            let p: Vec<f64> = (0..slots).map(|i| 0.1 + 0.05 * i as f64).collect();
            let x = [0.3, -0.2, 0.5];
            let g = kind.force(
                &Scalar,
                &Ends {
                    x1: x,
                    xp1: x,
                    x2: x,
                    xp2: x,
                },
                &p,
            );
            assert!(g.iter().all(|v| v.is_finite()), "{kind:?}: {g:?}");
            let g = kind.force(
                &Scalar,
                &Ends {
                    x1: x,
                    xp1: [0.29, -0.2, 0.5],
                    x2: x,
                    xp2: [0.3, -0.21, 0.5],
                },
                &p,
            );
            assert!(g.iter().all(|v| v.is_finite()), "{kind:?}: {g:?}");
        }
    }

    /// The analyses' blocks agree with the forces: a finite difference of g in each
    /// coordinate of endpoint 1 (and of its velocity) matches the blocks wherever the law is
    /// smooth and engaged.
    #[test]
    fn blocks_match_finite_differences_of_the_forces() {
        let mut checked = 0;
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for kind in SpaceLawKind::ALL {
            let row = kind.row();
            for _ in 0..400 {
                let mut p: Vec<f64> = (0..row.slots()).map(|_| 0.05 + next()).collect();
                // Flags and exponents in their useful ranges.
                for (i, s) in row.slot_names().enumerate() {
                    if s == "smooth" {
                        p[i] = if next() < 0.5 { 0.0 } else { 1.0 };
                    }
                    if s == "mu" {
                        p[i] = 0.0;
                    }
                    if s == "Zt" {
                        p[i] = 0.0;
                    }
                }
                let x1 = [next() - 0.5, next() - 0.5, next() - 0.5];
                let x2 = [next() - 0.5, next() - 0.5, next() - 0.5];
                let Linear3::Link(block) = kind.linearise(&p, x1, x2) else {
                    continue;
                };
                let h = 1e-7;
                let g = |x1: V3<f64>, xp1: V3<f64>| {
                    kind.force(
                        &Scalar,
                        &Ends {
                            x1,
                            xp1,
                            x2,
                            xp2: x2,
                        },
                        &p,
                    )
                };
                let mut smooth = true;
                let mut k = [[0.0; 3]; 3];
                let mut z = [[0.0; 3]; 3];
                for j in 0..3 {
                    let mut up = x1;
                    up[j] += h;
                    let mut dn = x1;
                    dn[j] -= h;
                    // Displacement at rest: x and x̃ move together (no velocity).
                    let (gu, gd, g0) = (g(up, up), g(dn, dn), g(x1, x1));
                    // Velocity: x moves, x̃ stays.
                    let (vu, vd) = (g(up, x1), g(dn, x1));
                    for i in 0..3 {
                        let right = (gu[i] - g0[i]) / h;
                        let left = (g0[i] - gd[i]) / h;
                        if (right - left).abs() > 1e-4 * (1.0 + right.abs().max(left.abs())) {
                            smooth = false;
                        }
                        k[i][j] = (gu[i] - gd[i]) / (2.0 * h);
                        // F₁ = −g: the velocity block is ∂g/∂v minus the stiffness already
                        // counted in moving x alone.
                        z[i][j] = (vu[i] - vd[i]) / (2.0 * h) - k[i][j];
                    }
                }
                if !smooth {
                    continue;
                }
                for i in 0..3 {
                    for j in 0..3 {
                        let tol = 1e-4 * (1.0 + block.k[i][j].abs());
                        assert!(
                            (k[i][j] - block.k[i][j]).abs() <= tol,
                            "{kind:?} k[{i}][{j}]: {} vs {} (p {p:?}, x1 {x1:?}, x2 {x2:?})",
                            k[i][j],
                            block.k[i][j]
                        );
                        let tol = 1e-4 * (1.0 + block.z[i][j].abs());
                        assert!(
                            (z[i][j] - block.z[i][j]).abs() <= tol,
                            "{kind:?} z[{i}][{j}]: {} vs {} (p {p:?})",
                            z[i][j],
                            block.z[i][j]
                        );
                    }
                }
                checked += 1;
            }
        }
        assert!(
            checked > 1000,
            "only {checked} smooth configurations checked"
        );
    }
}
