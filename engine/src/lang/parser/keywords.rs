//! The type keywords of spec §2.9 (with the legacy aliases of §3.12 a), the argument shape
//! each selects, and the accepted argument counts.

use crate::lang::symbols::SymKind;
use crate::spec::MacroKind;

/// The interaction laws, before their arguments are known.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum LawKind {
    Spring,
    Damper,
    SpringDamper,
    Contact,
    NlContact,
    NlSpring2,
    NlSpring3,
    NlSpringDamper,
    NlPluck,
    NlBow,
}

/// The argument shape a type keyword selects (spec §3.4, §2.9).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Shape {
    Mass,
    Osc,
    Ground,
    MassG,
    Law(LawKind),
    Macro(MacroKind),
    PosInput,
    FrcInput,
    PosOutput,
    FrcOutput,
    Param,
    AudioParam,
}

/// Every type keyword of spec §2.9, with the legacy aliases of §3.12 a.
pub(super) const KEYWORDS: [(&str, Shape); 27] = [
    ("mass", Shape::Mass),
    ("osc", Shape::Osc),
    ("ground", Shape::Ground),
    ("massG", Shape::MassG),
    ("spring", Shape::Law(LawKind::Spring)),
    ("damper", Shape::Law(LawKind::Damper)),
    ("springDamper", Shape::Law(LawKind::SpringDamper)),
    ("contact", Shape::Law(LawKind::Contact)),
    ("nlContact", Shape::Law(LawKind::NlContact)),
    ("nlSpring2", Shape::Law(LawKind::NlSpring2)),
    ("nlSpring", Shape::Law(LawKind::NlSpring2)),
    ("nlSpring3", Shape::Law(LawKind::NlSpring3)),
    ("nlSpringDamper", Shape::Law(LawKind::NlSpringDamper)),
    ("nlPluck", Shape::Law(LawKind::NlPluck)),
    ("nlBow", Shape::Law(LawKind::NlBow)),
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

pub(super) fn shape_of(keyword: &str) -> Option<Shape> {
    KEYWORDS
        .iter()
        .find(|(k, _)| *k == keyword)
        .map(|(_, s)| *s)
}

/// The accepted argument counts (after the keyword) and the signature for messages (§2.9).
pub(super) fn arity(shape: Shape) -> (usize, usize, &'static str) {
    use LawKind as L;
    match shape {
        Shape::Mass => (3, 4, "M {gravity} pos vel"),
        Shape::Osc => (5, 6, "M K Z {gravity} pos vel"),
        Shape::Ground => (1, 1, "pos"),
        Shape::MassG => (4, 4, "M G X0 XR0"),
        Shape::Law(L::Spring) => (3, 4, "m1 m2 K {Z}"),
        Shape::Law(L::Damper) => (3, 3, "m1 m2 Z"),
        Shape::Law(L::SpringDamper) => (4, 4, "m1 m2 K Z"),
        Shape::Law(L::Contact) => (4, 5, "m1 m2 K Z {thresh}"),
        Shape::Law(L::NlContact) => (6, 7, "m1 m2 K KnlQ Klim Z {thresh}"),
        Shape::Law(L::NlSpring2) => (5, 5, "m1 m2 K KnlP Z"),
        Shape::Law(L::NlSpring3) => (5, 5, "m1 m2 K KnlQ Z"),
        Shape::Law(L::NlSpringDamper) => (6, 6, "m1 m2 K KnlQ Klim Z"),
        Shape::Law(L::NlPluck) => (4, 5, "m1 m2 Knl Pscale {Z}"),
        Shape::Law(L::NlBow) => (4, 5, "m1 m2 Znl Vscale {smooth}"),
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
