//! The type keywords of spec §2.9 (with the legacy aliases of §3.12 a), the argument shape
//! each selects, and the accepted argument counts.

use crate::lang::symbols::SymKind;
use crate::laws::LawKind;
use crate::spec::{LawForm, MacroKind};

/// The argument shape a type keyword selects (spec §3.4, §2.9).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Shape {
    Mass,
    Osc,
    Ground,
    MassG,
    Law(LawForm),
    Macro(MacroKind),
    PosInput,
    FrcInput,
    PosOutput,
    FrcOutput,
    Param,
    AudioParam,
}

/// The type keywords of spec §2.9 besides the laws' own ([`keywords`] adds those), with the
/// legacy aliases of §3.12 a.
const OTHER_KEYWORDS: [(&str, Shape); 19] = [
    ("mass", Shape::Mass),
    ("osc", Shape::Osc),
    ("ground", Shape::Ground),
    ("massG", Shape::MassG),
    ("spring", Shape::Law(LawForm::Spring)),
    ("damper", Shape::Law(LawForm::Damper)),
    ("nlSpring", Shape::Law(LawForm::Full(LawKind::NlSpring2))),
    ("string", Shape::Macro(MacroKind::String)),
    ("chain", Shape::Macro(MacroKind::Chain)),
    ("stiffString", Shape::Macro(MacroKind::StiffString)),
    ("mesh", Shape::Macro(MacroKind::Mesh)),
    ("cornerMesh", Shape::Macro(MacroKind::CornerMesh)),
    ("closedMesh", Shape::Macro(MacroKind::ClosedMesh)),
    ("posInput", Shape::PosInput),
    ("frcInput", Shape::FrcInput),
    ("posOutput", Shape::PosOutput),
    ("frcOutput", Shape::FrcOutput),
    ("param", Shape::Param),
    ("audioParam", Shape::AudioParam),
];

/// Every type keyword: each law's own, from the table of laws, then the others.
pub(super) fn keywords() -> impl Iterator<Item = (&'static str, Shape)> {
    LawKind::ALL
        .into_iter()
        .map(|k| (k.row().keyword, Shape::Law(LawForm::Full(k))))
        .chain(OTHER_KEYWORDS)
}

pub(super) fn shape_of(keyword: &str) -> Option<Shape> {
    keywords().find(|(k, _)| *k == keyword).map(|(_, s)| s)
}

/// The accepted argument counts (after the keyword) and the signature for messages (§2.9).
pub(super) fn arity(shape: Shape) -> (usize, usize, &'static str) {
    match shape {
        Shape::Mass => (3, 4, "M {gravity} pos vel"),
        Shape::Osc => (5, 6, "M K Z {gravity} pos vel"),
        Shape::Ground => (1, 1, "pos"),
        Shape::MassG => (4, 4, "M G X0 XR0"),
        Shape::Law(LawForm::Spring) => (3, 4, "m1 m2 K {Z}"),
        Shape::Law(LawForm::Damper) => (3, 3, "m1 m2 Z"),
        Shape::Law(LawForm::Full(kind)) => {
            let row = kind.row();
            (2 + row.required, 2 + row.columns.len(), row.signature)
        }
        Shape::Macro(MacroKind::String | MacroKind::Chain) => (6, 7, "nbMass M K Z {Zo} pos vel"),
        Shape::Macro(MacroKind::StiffString) => (7, 8, "nbMass M K K2 Z {Zo} pos vel"),
        Shape::Macro(_) => (7, 8, "nbX nbY M K Z {Zo} pos vel"),
        Shape::PosInput => (1, 1, "pos"),
        Shape::FrcInput | Shape::PosOutput | Shape::FrcOutput => (1, 1, "target"),
        Shape::Param => (1, 1, "value"),
        Shape::AudioParam => (1, 2, "@inN {default}"),
    }
}

pub(super) fn sym_kind(shape: Shape) -> SymKind {
    match shape {
        Shape::Mass | Shape::Osc | Shape::Ground | Shape::MassG | Shape::PosInput => SymKind::Point,
        Shape::Law(_) => SymKind::Interaction,
        Shape::Macro(k) => SymKind::Macro {
            dims: if k.is_2d() { 2 } else { 1 },
        },
        Shape::FrcInput => SymKind::FrcInput,
        Shape::PosOutput | Shape::FrcOutput => SymKind::Output,
        Shape::Param | Shape::AudioParam => SymKind::Param,
    }
}
