//! The table of interaction laws: one row per kernel family of spec §2.3–§2.6.
//!
//! [`LawKind`] is the one list of laws, declared by `laws!` from one line per law in
//! `laws/mod.rs`: its variant and the type that implements [`super::Law`] in the law's own
//! file. Everything else is derived from that list: `ALL` and `COUNT`, each law's [`LawRow`]
//! (keyword, argument columns and classes, symmetry), its force on any [`super::Arith`], its
//! slope for the analyses, and the visit of every law in order that the kernels are written
//! with ([`LawKind::visit_all`]). Every pass that walks the laws (the compiler's groups and
//! bands, the kernels, the voice lanes, the native code, the linearisation of the analyses,
//! the structure display) goes through these, so a law added here runs everywhere, and one
//! that a pass forgot would be a compile error, not a silent omission.

use super::LawKind;
use crate::laws::ArgClass;

/// Declares [`LawKind`] and its dispatch from one list of `Variant => LawType` lines (the
/// table, in `laws/mod.rs`).
macro_rules! laws {
    ($($(#[$doc:meta])* $name:ident => $law:ty,)*) => {
        /// An interaction law, in the order of its group in the compiled model
        /// ([`crate::sim::engine::Interactions`]), which is also the order the kernels apply the
        /// groups in within a sample.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum LawKind {
            $($(#[$doc])* $name,)*
        }

        impl LawKind {
            /// Every law, in group order (`ALL[k as usize] == k`).
            pub const ALL: [LawKind; [$(LawKind::$name,)*].len()] = [$(LawKind::$name,)*];
            /// The number of laws.
            pub const COUNT: usize = Self::ALL.len();

            /// The law's row of the table.
            pub const fn row(self) -> LawRow {
                match self {
                    $(LawKind::$name => <$law as $crate::laws::Law>::ROW,)*
                }
            }

            /// The law's force for the elongation `dx`, the relative velocity `dv` and its
            /// columns `p` (the caller applies F₁ −= f, F₂ += f).
            #[inline(always)]
            pub(crate) fn force<A: $crate::laws::Arith>(self, a: &A, dx: A::F, dv: A::F, p: &[A::F]) -> A::F {
                match self {
                    $(LawKind::$name => <$law as $crate::laws::Law>::force(a, dx, dv, |c| p[c]),)*
                }
            }

            /// The law's linear stand-in for the arguments `p` (its columns, per-step values):
            /// at its bounded tangent when `rest_dx` is `None` (the stability rule, spec
            /// §5.2), else at rest with elongation `rest_dx` and Δv = 0 (the modes, §5.5).
            pub(crate) fn linearise(self, p: &[f64], rest_dx: Option<f64>) -> $crate::laws::linear::Linear {
                match self {
                    $(LawKind::$name => <$law as $crate::laws::Law>::linearise(p, rest_dx),)*
                }
            }

            /// What the stability rule notes of the arguments `p`, if anything.
            pub(crate) fn bound_note(self, p: &[f64]) -> Option<$crate::laws::linear::BoundNote> {
                match self {
                    $(LawKind::$name => <$law as $crate::laws::Law>::bound_note(p),)*
                }
            }

            /// Calls `v.visit::<L>(kind)` for every law in group order: the kernels' stage 4,
            /// straight-line code with each law's force inlined (a loop over [`LawKind::ALL`]
            /// with a `match` inside measured 30 % slower on a 100-mass string).
            #[inline(always)]
            pub(crate) fn visit_all(v: &mut impl $crate::laws::LawVisitor) {
                $(v.visit::<$law>(LawKind::$name);)*
            }
        }
    };
}

pub(super) use laws;

/// Code run once per law, with the law's type ([`LawKind::visit_all`]).
pub(crate) trait LawVisitor {
    /// Runs for law `kind`, whose force is `L`'s.
    fn visit<L: super::Law>(&mut self, kind: LawKind);
}

/// One argument column of a law: its name in the spec's signature and the class its value is
/// scaled by (spec §1.7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Column {
    pub name: &'static str,
    pub(crate) class: ArgClass,
}

/// A column named `name` of class `class`.
pub(super) const fn col(name: &'static str, class: ArgClass) -> Column {
    Column { name, class }
}

/// A law's row of the table.
#[derive(Clone, Copy, Debug)]
pub struct LawRow {
    /// The script keyword that writes the law with every column (spec §2.9).
    pub keyword: &'static str,
    /// The argument columns the kernels read, in order (after the two endpoints).
    pub columns: &'static [Column],
    /// How many of the columns a script must write; the ones after default to 0 (spec §2.9).
    pub required: usize,
    /// The keyword's signature, for messages: endpoints, then the columns, optional ones in
    /// braces.
    pub signature: &'static str,
    /// The law is odd, f(−Δx, −Δv) = −f(Δx, Δv), exactly in floating point (negation is
    /// exact and round-to-nearest is symmetric), so a link written (b, a) applies exactly the
    /// forces of (a, b) and the compiler may turn links round to form bands.
    pub odd: bool,
    /// The law bounds its own stiffness (a `Klim` column): the stability rule reads its
    /// bounded tangent rather than a linear K (spec §5.2).
    pub bounded: bool,
}

/// The scaling classes of the columns (spec §1.7): stiffness, damping, none, velocity scale.
pub(super) const K: ArgClass = ArgClass::Stiffness;
pub(super) const Z: ArgClass = ArgClass::Damping;
pub(super) const N: ArgClass = ArgClass::None;
pub(super) const V: ArgClass = ArgClass::VelocityScale;

impl LawKind {
    /// How many argument columns the law's kernels read.
    pub const fn arity(self) -> usize {
        self.row().columns.len()
    }

    /// The most columns any law has.
    pub const MAX_ARITY: usize = {
        let mut most = 0;
        let mut i = 0;
        while i < Self::COUNT {
            let n = Self::ALL[i].arity();
            if n > most {
                most = n;
            }
            i += 1;
        }
        most
    };

    /// The law's position in [`LawKind::ALL`] and its group's index.
    pub const fn index(self) -> usize {
        self as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_lists_every_law_once_in_order() {
        for (i, k) in LawKind::ALL.iter().enumerate() {
            assert_eq!(k.index(), i);
        }
        assert_eq!(LawKind::MAX_ARITY, 5);
    }

    /// The signature names the columns in order, the optional ones in braces.
    #[test]
    fn signatures_follow_the_columns() {
        for k in LawKind::ALL {
            let r = k.row();
            let names: Vec<String> = r
                .columns
                .iter()
                .enumerate()
                .map(|(i, c)| {
                    if i < r.required {
                        c.name.to_string()
                    } else {
                        format!("{{{}}}", c.name)
                    }
                })
                .collect();
            assert_eq!(r.signature, format!("m1 m2 {}", names.join(" ")), "{k:?}");
        }
    }

    #[test]
    fn keywords_are_distinct() {
        for a in LawKind::ALL {
            for b in LawKind::ALL {
                assert!(a == b || a.row().keyword != b.row().keyword);
            }
        }
    }
}
