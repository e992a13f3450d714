//! The `~generate` directive: the topology generators of spec §4 in a script.
//!
//! ```text
//! ~generate KIND NAME key=value …
//! ~generate triangle tri size=10 M=1 K=0.3 Z=1e-4 fixed=corners from=0,0,0 to=1,1,0
//! ```
//!
//! The directive expands inline, at its line, into the explicit elements of
//! [`crate::spec::generators`]: the parameters `NAME_M`, `NAME_K`, `NAME_Z`, `NAME_Zo` (and
//! `NAME_Ks` for the stiff string), then the nodes (`NAME_m<k>`, `NAME_m<a>_<b>`,
//! `NAME_m<a>_<b>_<c>`, end grounds `NAME_g0`/`NAME_g1`), then the links (`NAME_r<k>`). Later
//! (and earlier) lines address the nodes by label. Generated points join every buffer scope open
//! at the directive's line and carry the generator's x/y for motion buffers (§6.3).
//!
//! The directive is read in the parser's first pass, which must know every label before any
//! line is resolved (§3.4): kind, name, sizes and geometry are literals, so the labels are
//! known without evaluating anything. The physical values (`M`, `K`, `Z`, `Zo`, `Ks`) may be
//! expressions of parameters declared on earlier lines; they are evaluated in the second pass,
//! once, when the script is read, and become the initial values of the generated parameters.

use super::diagnostics::{Diagnostic, DiagnosticCode, Diags};
use super::expr_parser::{is_identifier, parse_expression, ExprContext};
use super::lexer::{col_plus, is_blank, split_items, width, TokKind, Token};
use super::numbers::{parse_number_literal, NumberError};
use super::symbols::Symbols;
use crate::spec::generators::{
    generate, Fixed, Generator, GeneratorError, LatticeFixed, Topology, MAX_GENERATED_LINKS,
    MAX_GENERATED_NODES,
};
use crate::spec::{Element, ModelBuilder, ParamDecl, ParamKind, Span};

mod first_pass;
pub(crate) use first_pass::{broken_name, read};

/// The most elements (nodes plus links) all the `~generate` directives of one script may
/// create together: 262 144, e.g. a 290 × 290 mesh (84 100 nodes, 167 620 links). Every
/// generated element is a full element of the model, about a kilobyte once parsed, compiled
/// and analysed, so this keeps what a script can ask for to a few hundred megabytes. The macros
/// (§2.7) remain the way to very large structures: they are one element whatever their size.
pub const MAX_GENERATED_ELEMENTS: usize = 1 << 18;

/// The generators of spec §4.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum GenKind {
    String,
    StiffString,
    Chain,
    Mesh,
    Triangle,
    Hexagon,
    Ring,
    Lattice,
    Polyline,
}

/// Generator kinds as written in a script; `cube` is the spec's other name for the lattice.
const KINDS: [(&str, GenKind); 10] = [
    ("string", GenKind::String),
    ("stiffString", GenKind::StiffString),
    ("chain", GenKind::Chain),
    ("mesh", GenKind::Mesh),
    ("triangle", GenKind::Triangle),
    ("hexagon", GenKind::Hexagon),
    ("ring", GenKind::Ring),
    ("lattice", GenKind::Lattice),
    ("cube", GenKind::Lattice),
    ("polyline", GenKind::Polyline),
];

/// The generator kinds for messages.
const KIND_LIST: &str =
    "string, stiffString, chain, mesh, triangle, hexagon, ring, lattice (or cube), polyline";

/// The keys of the directive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Key {
    M,
    K,
    Z,
    Zo,
    Ks,
    Nodes,
    Size,
    Fixed,
    From,
    To,
    Centre,
    Radius,
    Span,
    Diagonals,
    Points,
    Closed,
}

const ALL_KEYS: [Key; 16] = [
    Key::M,
    Key::K,
    Key::Z,
    Key::Zo,
    Key::Ks,
    Key::Nodes,
    Key::Size,
    Key::Fixed,
    Key::From,
    Key::To,
    Key::Centre,
    Key::Radius,
    Key::Span,
    Key::Diagonals,
    Key::Points,
    Key::Closed,
];

impl Key {
    fn name(self) -> &'static str {
        match self {
            Key::M => "M",
            Key::K => "K",
            Key::Z => "Z",
            Key::Zo => "Zo",
            Key::Ks => "Ks",
            Key::Nodes => "nodes",
            Key::Size => "size",
            Key::Fixed => "fixed",
            Key::From => "from",
            Key::To => "to",
            Key::Centre => "centre",
            Key::Radius => "radius",
            Key::Span => "span",
            Key::Diagonals => "diagonals",
            Key::Points => "points",
            Key::Closed => "closed",
        }
    }

    fn from_name(name: &str) -> Option<Key> {
        ALL_KEYS.into_iter().find(|k| k.name() == name)
    }

    /// The value's form, for messages.
    fn form(self, kind: GenKind) -> &'static str {
        match self {
            Key::M | Key::K | Key::Z | Key::Zo | Key::Ks => {
                "a number, or an expression of parameters declared above"
            }
            Key::Nodes => "an integer",
            Key::Size => match kind {
                GenKind::Mesh => "L,W (two integers)",
                GenKind::Lattice => "NX,NY,NZ (three integers)",
                _ => "an integer",
            },
            Key::Fixed => match kind {
                GenKind::Lattice => {
                    "none, corners, borders, centre, xmin, xmax, ymin, ymax, zmin or zmax"
                }
                _ => "none, corners or borders",
            },
            Key::From | Key::To | Key::Centre => "x,y,z (three numbers) or [x y z]",
            Key::Radius => "a number",
            Key::Span => "an integer",
            Key::Diagonals | Key::Closed => "on or off",
            Key::Points => "x,y;x,y;… (at least two points)",
        }
    }
}

/// (required keys, optional keys) of each generator.
fn keys_of(kind: GenKind) -> (&'static [Key], &'static [Key]) {
    use Key::*;
    match kind {
        GenKind::String | GenKind::Chain => (&[Nodes, M, K, Z], &[Zo, From, To]),
        GenKind::StiffString => (&[Nodes, M, K, Ks, Z], &[Zo, From, To]),
        GenKind::Mesh | GenKind::Triangle | GenKind::Hexagon => {
            (&[Size, M, K, Z], &[Zo, Fixed, From, To])
        }
        GenKind::Ring => (&[Nodes, M, K, Z], &[Zo, Radius, Centre]),
        GenKind::Lattice => (&[Size, M, K, Z], &[Zo, Span, Diagonals, Fixed, From, To]),
        GenKind::Polyline => (&[Points, M, K, Z], &[Zo, Closed, From, To]),
    }
}

/// The directive's full form for one kind, for messages: `~generate mesh NAME size=L,W …`.
fn usage(kind: GenKind, keyword: &str) -> String {
    let (required, optional) = keys_of(kind);
    let mut s = format!("~generate {keyword} NAME");
    for k in required {
        s.push_str(&format!(" {}={}", k.name(), placeholder(*k, kind)));
    }
    for k in optional {
        s.push_str(&format!(" {{{}={}}}", k.name(), default_text(*k)));
    }
    s
}

fn placeholder(key: Key, kind: GenKind) -> &'static str {
    match key {
        Key::Nodes => "N",
        Key::Size => match kind {
            GenKind::Mesh => "L,W",
            GenKind::Lattice => "NX,NY,NZ",
            _ => "S",
        },
        Key::Points => "x,y;x,y;…",
        _ => "…",
    }
}

fn default_text(key: Key) -> &'static str {
    match key {
        Key::Zo => "0",
        Key::Fixed => "none",
        Key::From | Key::Centre => "0,0,0",
        Key::To => "1,1,0",
        Key::Radius => "1",
        Key::Span => "1",
        Key::Diagonals => "off",
        Key::Closed => "on",
        _ => "",
    }
}

/// The smallest accepted value of each integer of a generator (spec §4): moving nodes of a
/// string, chain nodes, mesh sides, triangle rows, hexagon rings, ring nodes, lattice sides and
/// span.
fn minimum(kind: GenKind) -> usize {
    match kind {
        GenKind::String | GenKind::StiffString | GenKind::Hexagon | GenKind::Lattice => 1,
        GenKind::Chain | GenKind::Mesh | GenKind::Triangle | GenKind::Polyline => 2,
        GenKind::Ring => 3,
    }
}

/// A value as written: its characters and the column of the first one.
#[derive(Clone, Debug)]
pub(crate) struct Val {
    value: String,
    col: u32,
    /// Written as `key=[ … ]`.
    bracket: bool,
}

impl Val {
    fn text(&self) -> String {
        self.value.clone()
    }
}

/// A `~generate` directive read in the first pass: everything but the physical values, which
/// are evaluated in the second.
#[derive(Clone, Debug)]
pub(crate) struct GenRequest {
    pub line: u32,
    pub keyword: String,
    pub kind_col: u32,
    pub name: String,
    pub name_col: u32,
    pub topology: Topology,
    first: [f64; 3],
    last: [f64; 3],
    m: Val,
    k: Val,
    z: Val,
    zo: Option<Val>,
    ks: Option<Val>,
}

/// The outcome of the first pass over a `~generate` line.
#[derive(Debug)]
pub(crate) enum Read {
    /// Valid: the labels can be planned.
    Ready(Box<GenRequest>),
    /// An error was reported; `name` is the generator's name when it could be read, so that
    /// references to its labels are not reported again.
    Broken { name: Option<String> },
}

fn diag(code: DiagnosticCode, line: u32, col: u32, message: impl Into<String>) -> Diagnostic {
    Diagnostic::new(code, line, col, message)
}

fn kind_name(kind: GenKind) -> &'static str {
    KINDS
        .iter()
        .find(|(_, k)| *k == kind)
        .map_or("", |(n, _)| *n)
}

/// The second pass: evaluates the physical values and expands the generator. `params` are the
/// parameters declared so far (the values may use those, and only those); `buffers` the scopes
/// open at the directive's line. Returns the generated parameters and elements.
pub(crate) fn expand(
    req: &GenRequest,
    symbols: &Symbols,
    params: &[ParamDecl],
    buffers: &[u32],
    diags: &mut Diags,
) -> Option<(Vec<ParamDecl>, Vec<Element>)> {
    let label = Some(req.name.as_str());
    let cx = ExprContext {
        symbols,
        line: req.line,
        label,
        auto: None,
    };
    let eval = |key: &str, v: &Val, diags: &mut Diags| -> Option<f64> {
        let e = parse_expression(&v.value, v.col, &cx, diags)?;
        let mut problem: Option<String> = None;
        e.for_each_name(&mut |n| {
            if problem.is_some() {
                return;
            }
            problem = match params.iter().find(|p| p.name == n).map(|p| &p.kind) {
                Some(ParamKind::Control { .. }) => None,
                Some(ParamKind::Audio { .. }) => Some(format!(
                    "`{key}` uses the audio-rate parameter `{n}`, which has no value when the \
                     script is read"
                )),
                None => Some(format!(
                    "`{key}` uses the parameter `{n}`, which is declared after this line; a \
                     `~generate` value may only use parameters declared above it"
                )),
            };
        });
        if let Some(message) = problem {
            diags.push(
                diag(
                    DiagnosticCode::InvalidGeneratorValue,
                    req.line,
                    v.col,
                    message,
                )
                .with_label(label)
                .with_expected("a number, or an expression of control parameters declared above")
                .with_found(v.text()),
            );
            return None;
        }
        let value = e.eval(&|n: &str| {
            params
                .iter()
                .find(|p| p.name == n)
                .and_then(|p| match p.kind {
                    ParamKind::Control { value } => Some(value),
                    ParamKind::Audio { .. } => None,
                })
        });
        let bad = if !value.is_finite() {
            Some(format!("`{key}` evaluates to {value}"))
        } else if key == "M" && !(value > 0.0) {
            Some(format!("`M` must be greater than 0, found {value}"))
        } else {
            None
        };
        if let Some(message) = bad {
            diags.push(
                diag(
                    DiagnosticCode::InvalidGeneratorValue,
                    req.line,
                    v.col,
                    message,
                )
                .with_label(label)
                .with_expected(if key == "M" {
                    "a finite number > 0"
                } else {
                    "a finite number"
                })
                .with_found(v.text()),
            );
            return None;
        }
        Some(value)
    };
    let m = eval("M", &req.m, diags);
    let k = eval("K", &req.k, diags);
    let z = eval("Z", &req.z, diags);
    let zo = match &req.zo {
        Some(v) => eval("Zo", v, diags),
        None => Some(0.0),
    };
    let ks = match &req.ks {
        Some(v) => eval("Ks", v, diags),
        None => Some(0.0),
    };
    let generator = Generator {
        name: req.name.clone(),
        m: m?,
        k: k?,
        z: z?,
        zo: zo?,
        ks: ks?,
        first: req.first,
        last: req.last,
    };
    let mut builder = ModelBuilder::new();
    if let Err(e) = generate(&mut builder, &generator, &req.topology) {
        diags.push(
            diag(
                DiagnosticCode::InvalidGeneratorValue,
                req.line,
                req.kind_col,
                format!("the `{}` generator `{}`: {e}", req.keyword, req.name),
            )
            .with_label(label),
        );
        return None;
    }
    let spec = builder.finish();
    let span = Span::new(req.line, req.name_col);
    let params = spec
        .params
        .into_iter()
        .map(|p| ParamDecl { span, ..p })
        .collect();
    let elements = spec
        .elements
        .into_iter()
        .map(|e| Element {
            buffers: buffers.to_vec(),
            span,
            ..e
        })
        .collect();
    Some((params, elements))
}
