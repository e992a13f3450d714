//! The table of interaction laws: one row per kernel family of spec §2.3–§2.6.
//!
//! [`LawKind`] is the one list of laws. Every pass that walks them (the compiler's groups and
//! bands, the kernels, the voice lanes, the native code, the linearisation of the analyses,
//! the structure display) loops over [`LawKind::ALL`] or matches a kind exhaustively, so a
//! law added here and forgotten in one of them is a compile error, not a silent omission. The
//! law's own data (its keyword, its argument columns and their classes, its symmetry) is a
//! row of [`LawKind::row`]; its force is a function of [`crate::laws`], and its slope for the
//! analyses is [`LawKind::linearise`].

use crate::engine::ArgClass;

/// Declares [`LawKind`] with its `ALL` list and `COUNT` from one list of variants, so the
/// three cannot disagree.
macro_rules! law_kinds {
    ($($(#[$doc:meta])* $name:ident,)*) => {
        /// An interaction law, in the order of its group in the compiled model
        /// ([`crate::engine::Interactions`]), which is also the order the kernels apply the
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

        }
    };
}

law_kinds! {
    /// `spring`, `damper`, `springDamper` (spec §2.3): f = K·Δx + Z·Δv.
    SpringDamper,
    /// `contact` (spec §2.4.1).
    Contact,
    /// `nlContact` (spec §2.4.2).
    NlContact,
    /// `nlSpring2` (spec §2.5.1).
    NlSpring2,
    /// `nlSpring3` (spec §2.5.2).
    NlSpring3,
    /// `nlSpringDamper` (spec §2.5.3).
    NlSpringDamper,
    /// `nlPluck` (spec §2.6.1).
    Pluck,
    /// `nlBow` (spec §2.6.2).
    Bow,
}

/// One argument column of a law: its name in the spec's signature and the class its value is
/// scaled by (spec §1.7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Column {
    pub name: &'static str,
    pub(crate) class: ArgClass,
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

const K: ArgClass = ArgClass::Stiffness;
const Z: ArgClass = ArgClass::Damping;
const N: ArgClass = ArgClass::None;
const V: ArgClass = ArgClass::VelocityScale;

impl LawKind {
    /// The law's row of the table.
    pub const fn row(self) -> LawRow {
        match self {
            LawKind::SpringDamper => LawRow {
                keyword: "springDamper",
                columns: &[
                    Column {
                        name: "K",
                        class: K,
                    },
                    Column {
                        name: "Z",
                        class: Z,
                    },
                ],
                required: 2,
                signature: "m1 m2 K Z",
                odd: true,
                bounded: false,
            },
            LawKind::Contact => LawRow {
                keyword: "contact",
                columns: &[
                    Column {
                        name: "K",
                        class: K,
                    },
                    Column {
                        name: "Z",
                        class: Z,
                    },
                    Column {
                        name: "thresh",
                        class: N,
                    },
                ],
                required: 2,
                signature: "m1 m2 K Z {thresh}",
                odd: false,
                bounded: false,
            },
            LawKind::NlContact => LawRow {
                keyword: "nlContact",
                columns: &[
                    Column {
                        name: "K",
                        class: K,
                    },
                    Column {
                        name: "KnlQ",
                        class: K,
                    },
                    Column {
                        name: "Klim",
                        class: K,
                    },
                    Column {
                        name: "Z",
                        class: Z,
                    },
                    Column {
                        name: "thresh",
                        class: N,
                    },
                ],
                required: 4,
                signature: "m1 m2 K KnlQ Klim Z {thresh}",
                odd: false,
                bounded: true,
            },
            LawKind::NlSpring2 => LawRow {
                keyword: "nlSpring2",
                columns: &[
                    Column {
                        name: "K",
                        class: K,
                    },
                    Column {
                        name: "KnlP",
                        class: K,
                    },
                    Column {
                        name: "Z",
                        class: Z,
                    },
                ],
                required: 3,
                signature: "m1 m2 K KnlP Z",
                odd: true,
                bounded: false,
            },
            LawKind::NlSpring3 => LawRow {
                keyword: "nlSpring3",
                columns: &[
                    Column {
                        name: "K",
                        class: K,
                    },
                    Column {
                        name: "KnlQ",
                        class: K,
                    },
                    Column {
                        name: "Z",
                        class: Z,
                    },
                ],
                required: 3,
                signature: "m1 m2 K KnlQ Z",
                odd: true,
                bounded: false,
            },
            LawKind::NlSpringDamper => LawRow {
                keyword: "nlSpringDamper",
                columns: &[
                    Column {
                        name: "K",
                        class: K,
                    },
                    Column {
                        name: "KnlQ",
                        class: K,
                    },
                    Column {
                        name: "Klim",
                        class: K,
                    },
                    Column {
                        name: "Z",
                        class: Z,
                    },
                ],
                required: 4,
                signature: "m1 m2 K KnlQ Klim Z",
                odd: false,
                bounded: true,
            },
            LawKind::Pluck => LawRow {
                keyword: "nlPluck",
                columns: &[
                    Column {
                        name: "Knl",
                        class: K,
                    },
                    Column {
                        name: "Pscale",
                        class: N,
                    },
                    Column {
                        name: "Z",
                        class: Z,
                    },
                ],
                required: 2,
                signature: "m1 m2 Knl Pscale {Z}",
                odd: false,
                bounded: false,
            },
            LawKind::Bow => LawRow {
                keyword: "nlBow",
                columns: &[
                    Column {
                        name: "Znl",
                        class: Z,
                    },
                    Column {
                        name: "Vscale",
                        class: V,
                    },
                    Column {
                        name: "smooth",
                        class: N,
                    },
                ],
                required: 2,
                signature: "m1 m2 Znl Vscale {smooth}",
                odd: false,
                bounded: false,
            },
        }
    }

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
