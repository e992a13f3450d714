//! The 3-D script (3-D spec §1.1): a script with `~dim 3` is read with the 3-D keywords and
//! argument shapes into a [`SpaceSpec`]. The lines, labels, expressions, vectors, endpoints,
//! parameters, scopes and host directives are read as in 1-D; what differs is here:
//!
//! * `mod.rs`: the dimension of a script, the 3-D keywords and the shape and argument count
//!   each selects;
//! * `labels`: pass 1 for the structures and adders, whose generated labels (`s_m12`, `s_r3`,
//!   `h_7`) are resolved from their counts (3-D spec §4.0, §4.7), an OBJ file read once;
//! * `command`: pass 2, each 3-D element's arguments;
//! * `structure`: a structure statement (§4): sizes, arguments and the options group;
//! * `checks`: what is checked once the script is read (channels taken by the XYZ forms, the
//!   lints of §5.6).

use super::lines::Item;
use crate::lang::lexer::{TokKind, Token};
use crate::lang::symbols::SymKind;
use crate::laws::space::SpaceLawKind;
use crate::spec::space::{Body, Probe, SpaceSpec, StructureKind};

mod checks;
mod command;
pub(super) mod labels;
mod structure;

/// Whether the script is three-dimensional: some `~dim` line says `3` (3-D spec §1.1: it may
/// stand anywhere and applies to the whole script). Conflicts and bad values are reported
/// when the directive is read in pass 2.
pub(super) fn is_3d(items: &[Item], all: &[Token]) -> bool {
    items.iter().filter(|i| i.directive && !i.broken).any(|i| {
        let t = i.tokens(all);
        t.first().is_some_and(|t| t.text == "~dim")
            && t.get(1)
                .is_some_and(|a| a.kind == TokKind::Bare && a.text == "3")
    })
}

/// The argument shape a 3-D type keyword selects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Shape3 {
    Mass(Body),
    Osc,
    Ground,
    /// A law of the 3-D table; its directional form, if any, is chosen by the count.
    Law(SpaceLawKind),
    Structure(StructureKind),
    ContactSet,
    Vdampers,
    PosInput,
    PosInputXyz,
    FrcInput,
    FrcInputXyz,
    Output(Probe),
    DistOutput,
    Mic,
    Param,
    AudioParam,
}

/// The 3-D keywords besides the laws' own and the structures'.
const OTHER_KEYWORDS: [(&str, Shape3); 16] = [
    ("mass", Shape3::Mass(Body::Free)),
    ("massZ", Shape3::Mass(Body::Z)),
    ("massXY", Shape3::Mass(Body::Xy)),
    ("osc", Shape3::Osc),
    ("ground", Shape3::Ground),
    ("contactSet", Shape3::ContactSet),
    ("vdampers", Shape3::Vdampers),
    ("posInput", Shape3::PosInput),
    ("posInputXYZ", Shape3::PosInputXyz),
    ("frcInput", Shape3::FrcInput),
    ("frcInputXYZ", Shape3::FrcInputXyz),
    ("posOutput", Shape3::Output(Probe::Position)),
    ("frcOutput", Shape3::Output(Probe::Force)),
    ("velOutput", Shape3::Output(Probe::Velocity)),
    ("distOutput", Shape3::DistOutput),
    ("mic", Shape3::Mic),
];

/// Every 3-D keyword: each law's (its plain form; `nlSpring` is `nlSpring2`), each
/// structure's, then the others, `param` and `audioParam`.
pub(super) fn keywords() -> impl Iterator<Item = (&'static str, Shape3)> {
    SpaceLawKind::ALL
        .into_iter()
        .filter(|k| SpaceLawKind::with_keyword(k.row().keyword).next() == Some(*k))
        .map(|k| (k.row().keyword, Shape3::Law(k)))
        .chain([("nlSpring", Shape3::Law(SpaceLawKind::NlSpring2))])
        .chain(StructureKind::ALL.map(|k| (k.keyword(), Shape3::Structure(k))))
        .chain(OTHER_KEYWORDS)
        .chain([("param", Shape3::Param), ("audioParam", Shape3::AudioParam)])
}

pub(super) fn shape_of(keyword: &str) -> Option<Shape3> {
    keywords().find(|(k, _)| *k == keyword).map(|(_, s)| s)
}

/// The 1-D keywords that have no 3-D form, with what to write instead (3-D spec §1.8).
pub(super) fn one_d_only(keyword: &str) -> Option<&'static str> {
    Some(match keyword {
        "massG" => "use `mass` with gravity, or `~gravity` for a uniform acceleration",
        "string" | "chain" => "use `string3` (`fix=none` for a chain)",
        "mesh" | "cornerMesh" | "closedMesh" => {
            "use `mesh3` (with `fix=none`, `corners` or `borders`)"
        }
        "stiffString" => {
            "a straight string has no central-force bending: use a `lattice3` beam (2×2×N with \
             `diag`) or `hinge` links on a curved shell"
        }
        "feltContact" => "the felt is a 1-D law only; use `nlContact`",
        _ => return None,
    })
}

/// The accepted argument counts (after the keyword) and the signature for messages.
pub(super) fn arity(shape: Shape3) -> (usize, usize, &'static str) {
    match shape {
        Shape3::Mass(_) => (3, 4, "M {gravity} pos vel"),
        Shape3::Osc => (5, 6, "M K Z {gravity} pos vel"),
        Shape3::Ground => (1, 1, "pos"),
        Shape3::Law(kind) => {
            let rows: Vec<_> = SpaceLawKind::with_keyword(kind.row().keyword).collect();
            let ends = kind.row().endpoints;
            let least = rows.iter().map(|r| r.row().required).min().unwrap_or(0);
            let most = rows
                .iter()
                .map(|r| r.row().columns.len())
                .max()
                .unwrap_or(0);
            (ends + least, ends + most, kind.row().signature)
        }
        Shape3::Structure(kind) => {
            let n = kind.num_sizes().max(1) + 6;
            (n, n + 1, kind.signature())
        }
        Shape3::ContactSet => (5, 7, "m1 @struct K Z D {Zt} {mu}"),
        Shape3::Vdampers => (2, 2, "@struct Zv"),
        Shape3::PosInput => (1, 2, "pos {dir}"),
        Shape3::PosInputXyz => (1, 1, "pos"),
        Shape3::FrcInput | Shape3::Output(_) => (1, 2, "target {dir}"),
        Shape3::FrcInputXyz => (1, 1, "target"),
        Shape3::DistOutput => (2, 2, "m1 m2"),
        Shape3::Mic => (5, 5, "SET P DIR q r0"),
        Shape3::Param => (1, 1, "value"),
        Shape3::AudioParam => (1, 2, "@inN {default}"),
    }
}

/// What a label of this shape names, for name resolution (pass 1).
pub(super) fn sym_kind(shape: Shape3) -> SymKind {
    match shape {
        Shape3::Mass(_) | Shape3::Osc | Shape3::Ground | Shape3::PosInput | Shape3::PosInputXyz => {
            SymKind::Point
        }
        Shape3::Law(_) | Shape3::ContactSet | Shape3::Vdampers => SymKind::Interaction,
        Shape3::Structure(k) => SymKind::Macro {
            dims: k.coordinates(),
        },
        Shape3::FrcInput | Shape3::FrcInputXyz => SymKind::FrcInput,
        Shape3::Output(_) | Shape3::DistOutput | Shape3::Mic => SymKind::Output,
        Shape3::Param | Shape3::AudioParam => SymKind::Param,
    }
}

/// The 3-D model being read, beside the 1-D builder's state.
#[derive(Debug, Default)]
pub(super) struct SpaceState {
    pub spec: SpaceSpec,
    /// The line of the `~dim 3`, `~gravity` and `~friction` read so far.
    pub dim_line: Option<u32>,
    pub gravity_line: Option<u32>,
    pub friction_line: Option<u32>,
    /// Input channels an `XYZ` element takes beyond its own label: (channel, line, label).
    pub taken_inputs: Vec<(u32, u32, String)>,
}
