//! The table of 3-D interaction laws: one row per law of 3-D spec §2.2–§2.5.
//!
//! [`SpaceLawKind`] is the one list, declared by `space_laws!` from one line per law in
//! `laws/space/mod.rs`, as `laws!` declares the 1-D [`crate::LawKind`]: `ALL` and `COUNT`,
//! each law's [`SpaceRow`], its force on any [`crate::laws::Arith`], its blocks for the
//! analyses, its bounds for the stability rule, and the visit of every law in order that the
//! 3-D kernels are written with.

use crate::laws::ArgClass;

/// Declares [`SpaceLawKind`] and its dispatch from one list of `Variant => LawType` lines.
macro_rules! space_laws {
    ($($(#[$doc:meta])* $name:ident => $law:ty,)*) => {
        /// A 3-D interaction law, in the order of its group in a compiled 3-D model, which is
        /// also the order the kernels apply the groups in within a sample.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum SpaceLawKind {
            $($(#[$doc])* $name,)*
        }

        impl SpaceLawKind {
            /// Every law, in group order (`ALL[k as usize] == k`).
            pub const ALL: [SpaceLawKind; [$(SpaceLawKind::$name,)*].len()] =
                [$(SpaceLawKind::$name,)*];
            /// The number of laws.
            pub const COUNT: usize = Self::ALL.len();

            /// The law's row of the table.
            pub const fn row(self) -> SpaceRow {
                match self {
                    $(SpaceLawKind::$name => <$law as $crate::laws::space::SpaceLaw>::ROW,)*
                }
            }

            /// The law's g (F₁ −= g, F₂ += g) for the endpoints `e` and its slots `p`.
            #[inline(always)]
            pub(crate) fn force<A: $crate::laws::Arith>(
                self,
                a: &A,
                e: &$crate::laws::space::Ends<A::F>,
                p: &[A::F],
            ) -> $crate::laws::space::V3<A::F> {
                match self {
                    $(SpaceLawKind::$name =>
                        <$law as $crate::laws::space::SpaceLaw>::force(a, e, |c| p[c]),)*
                }
            }

            /// The law's blocks at rest with its endpoints at `x1` and `x2`.
            pub fn linearise(self, p: &[f64], x1: [f64; 3], x2: [f64; 3]) -> $crate::laws::space::Linear3 {
                match self {
                    $(SpaceLawKind::$name =>
                        <$law as $crate::laws::space::SpaceLaw>::linearise(p, x1, x2),)*
                }
            }

            /// The law's bounds for the stability rule: (k̂, ẑ, whether k̂ bounds the law at
            /// every amplitude).
            pub fn bound(self, p: &[f64]) -> (f64, f64, bool) {
                match self {
                    $(SpaceLawKind::$name => <$law as $crate::laws::space::SpaceLaw>::bound(p),)*
                }
            }

            /// Calls `v.visit::<L>(kind)` for every law in group order: the 3-D kernels'
            /// stage 4, each law's loop with its force inlined.
            #[inline(always)]
            pub(crate) fn visit_all(v: &mut impl $crate::laws::space::SpaceLawVisitor) {
                $(v.visit::<$law>(SpaceLawKind::$name);)*
            }
        }
    };
}

pub(super) use space_laws;

/// Code run once per 3-D law, with the law's type ([`SpaceLawKind::visit_all`]).
pub(crate) trait SpaceLawVisitor {
    /// Runs for law `kind`, whose force is `L`'s.
    fn visit<L: super::SpaceLaw>(&mut self, kind: SpaceLawKind);
}

/// What an argument column holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColShape {
    /// A number (an expression).
    Scalar,
    /// A length that may use `auto`, the endpoints' distance at stage 0 (3-D spec §1.7): the
    /// rest length L, the contact distance D, the bubble's radius R.
    Length,
    /// A direction (3-D spec §1.7): a vector `[x y z]`, three slots, normalised where it is
    /// used.
    Direction,
}

/// One argument column of a 3-D law: its name in the signature, its class (spec §1.7, 3-D
/// spec §1.6) and its shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SpaceColumn {
    pub name: &'static str,
    pub(crate) class: ArgClass,
    pub shape: ColShape,
}

impl SpaceColumn {
    /// How many argument slots the column takes.
    pub const fn slots(&self) -> usize {
        match self.shape {
            ColShape::Direction => 3,
            ColShape::Scalar | ColShape::Length => 1,
        }
    }
}

/// A scalar column.
pub(super) const fn col(name: &'static str, class: ArgClass) -> SpaceColumn {
    SpaceColumn {
        name,
        class,
        shape: ColShape::Scalar,
    }
}

/// A length column (`auto` allowed).
pub(super) const fn len(name: &'static str) -> SpaceColumn {
    SpaceColumn {
        name,
        class: ArgClass::None,
        shape: ColShape::Length,
    }
}

/// A direction column.
pub(super) const fn dir(name: &'static str) -> SpaceColumn {
    SpaceColumn {
        name,
        class: ArgClass::None,
        shape: ColShape::Direction,
    }
}

pub(super) const K: ArgClass = ArgClass::Stiffness;
pub(super) const Z: ArgClass = ArgClass::Damping;
pub(super) const N: ArgClass = ArgClass::None;
pub(super) const V: ArgClass = ArgClass::VelocityScale;

/// A 3-D law's row of the table.
#[derive(Clone, Copy, Debug)]
pub struct SpaceRow {
    /// The script keyword (3-D spec §2.7). Two rows share one when the second is the law's
    /// directional form, chosen when its direction is written (`nlPluck`, `nlBow`).
    pub keyword: &'static str,
    /// The argument columns, in order, after the endpoints.
    pub columns: &'static [SpaceColumn],
    /// How many columns a script must write; the ones after default to 0.
    pub required: usize,
    /// The keyword's signature, for messages.
    pub signature: &'static str,
    /// 2 for interactions between two points, 1 for `planeContact`.
    pub endpoints: usize,
}

impl SpaceRow {
    /// The argument slots the columns take (a direction three).
    pub const fn slots(&self) -> usize {
        let mut n = 0;
        let mut i = 0;
        while i < self.columns.len() {
            n += self.columns[i].slots();
            i += 1;
        }
        n
    }

    /// Each slot's column name (a direction's three slots repeat it).
    pub fn slot_names(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.columns
            .iter()
            .flat_map(|c| std::iter::repeat_n(c.name, c.slots()))
    }

    /// Each slot's class.
    pub(crate) fn slot_classes(&self) -> impl Iterator<Item = ArgClass> + '_ {
        self.columns
            .iter()
            .flat_map(|c| std::iter::repeat_n(c.class, c.slots()))
    }

    /// The first slot of the column named `name`.
    pub fn slot_of(&self, name: &str) -> Option<usize> {
        let mut slot = 0;
        for c in self.columns {
            if c.name == name {
                return Some(slot);
            }
            slot += c.slots();
        }
        None
    }
}

impl SpaceLawKind {
    /// The most argument slots any law has.
    pub const MAX_SLOTS: usize = {
        let mut most = 0;
        let mut i = 0;
        while i < Self::COUNT {
            let n = Self::ALL[i].row().slots();
            if n > most {
                most = n;
            }
            i += 1;
        }
        most
    };

    /// The law's position in [`SpaceLawKind::ALL`] and its group's index.
    pub const fn index(self) -> usize {
        self as usize
    }

    /// The rows written with `keyword`, the plain form first.
    pub fn with_keyword(keyword: &str) -> impl Iterator<Item = SpaceLawKind> + '_ {
        Self::ALL
            .into_iter()
            .filter(move |k| k.row().keyword == keyword)
    }
}

use super::SpaceLawKind;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_lists_every_law_once_in_order() {
        for (i, k) in SpaceLawKind::ALL.iter().enumerate() {
            assert_eq!(k.index(), i);
        }
    }

    /// The signature names the endpoints and the columns in order, the optional ones in
    /// braces; a directional form shares its plain form's signature.
    #[test]
    fn signatures_follow_the_columns() {
        for k in SpaceLawKind::ALL {
            let r = k.row();
            let plain = SpaceLawKind::with_keyword(r.keyword).next().unwrap();
            if plain != k {
                assert_eq!(plain.row().signature, r.signature, "{k:?}");
                assert_eq!(
                    r.required,
                    r.columns.len(),
                    "{k:?}: a directional form writes all"
                );
                continue;
            }
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
            let ends = if r.endpoints == 1 { "m" } else { "m1 m2" };
            let mut want = format!("{ends} {}", names.join(" "));
            // The directional form adds its trailing direction.
            if let Some(d) = SpaceLawKind::with_keyword(r.keyword).nth(1) {
                want.push_str(&format!(" {{{}}}", d.row().columns.last().unwrap().name));
            }
            assert_eq!(r.signature, want, "{k:?}");
        }
    }

    /// At most two rows share a keyword, and then the second extends the first by one
    /// direction column.
    #[test]
    fn shared_keywords_are_directional_forms() {
        for k in SpaceLawKind::ALL {
            let rows: Vec<_> = SpaceLawKind::with_keyword(k.row().keyword).collect();
            assert!(rows.len() <= 2, "{k:?}");
            if let [plain, directional] = rows[..] {
                let (p, d) = (plain.row(), directional.row());
                assert_eq!(d.columns.len(), p.columns.len() + 1);
                assert_eq!(&d.columns[..p.columns.len()], p.columns);
                assert_eq!(d.columns.last().unwrap().shape, ColShape::Direction);
            }
        }
    }
}
