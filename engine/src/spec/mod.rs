//! The model spec: what a model *is*, in user terms (labels, script values, expressions), before
//! it is compiled for a sample rate. Second step of the pipeline: [`crate::lang`] reads text
//! into it, [`crate::compile`] turns it into a running model.
//!
//! This folder owns the spec's types and the builder API, the expression trees (`expr`), the
//! topology generators of spec §4 (`generators`), the label tables both the parser and the
//! compiler use (`label_map`) and the reference models of spec §7 (`reference`).
//!
//! Both the script parser and the Rust [`ModelBuilder`] produce a [`ModelSpec`]. It keeps the
//! script order of elements, because the stage order of spec §1.5 and the motion-buffer order of
//! §6.2 are defined by it. Nothing here touches the audio thread: [`crate::compile`] turns a spec
//! into flat arrays.

use crate::laws::LawKind;
use crate::spec::expr::Expr;

mod builder;
pub mod expr;
pub mod generators;
mod host;
pub(crate) mod label_map;
pub mod reference;
pub mod space;
pub use builder::ModelBuilder;
pub use host::{ExciterDecl, ExciterKind, HostSpec, MacroRange, Route, RouteSource};

/// An element's label or the label an endpoint names, without `@`. Labels up to 23 bytes (nearly
/// all) are stored inline, so a spec of thousands of elements holds no string per label, and a
/// clone copies. Compares with, hashes as and dereferences to its `str`.
pub type Label = smol_str::SmolStr;

/// `text` as a [`Label`]: the same value as `Label::new`, built without its general path
/// (a copy call and a check for whitespace-only strings) when it fits inline.
#[inline]
pub(crate) fn label(text: &str) -> Label {
    if text.len() <= 23 {
        Label::new_inline(text)
    } else {
        Label::new(text)
    }
}

/// Where a construct stood in its script: 1-based line and column (Unicode scalar values, a
/// tab counting as one). `0:0` means "not from a script" (built in Rust).
///
/// Spans are metadata: two specs that differ only in their spans compare equal, so
/// `parse(print(parse(x))) == parse(x)` holds although printing moves text around.
#[derive(Clone, Copy, Debug, Default, Eq)]
pub struct Span {
    pub line: u32,
    pub col: u32,
}

impl Span {
    pub fn new(line: u32, col: u32) -> Span {
        Span { line, col }
    }

    /// True for constructs that came from script text.
    pub fn is_known(self) -> bool {
        self.line > 0
    }
}

impl PartialEq for Span {
    fn eq(&self, _other: &Span) -> bool {
        true
    }
}

/// How script values relate to the running sample rate (spec §1.7, §3.12 b).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SampleRateMode {
    /// Values are "as tuned at 44.1 kHz" and are rescaled by their class. The default.
    #[default]
    Scaled,
    /// Values are per-step; velocities are in units per step; gravity is a per-step force.
    Raw,
}

/// A parameter declaration (spec §3.8).
#[derive(Clone, Debug, PartialEq)]
pub struct ParamDecl {
    /// The name, without `@`; an identifier that is not a function name.
    pub name: String,
    pub kind: ParamKind,
    pub span: Span,
}

/// Control-rate or audio-rate parameter.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamKind {
    /// `@name param value`: changed by the host between blocks.
    Control { value: f64 },
    /// `@name audioParam @inN [default]`: at every sample (spec §1.5 stage 1 b, §3.8) its
    /// value is `default` + input channel `input` (1-based). An unfed or silent input gives
    /// the default; a connected one modulates around it. The default is a project extension
    /// (0 when omitted, so a MIMS4Max script keeps its meaning: the value is the input).
    Audio { input: u32, default: f64 },
}

/// A position or velocity argument (spec §3.7): a scalar z, or an `[x y z]` vector whose x and
/// y only place the point for rendering.
#[derive(Clone, Debug, PartialEq)]
pub enum Vector {
    Scalar(Expr),
    /// Boxed: most positions are scalars; inline, three expressions would set the size of
    /// every mass in a spec.
    Xyz(Box<[Expr; 3]>),
}

impl Vector {
    /// The physics coordinate.
    pub fn z(&self) -> &Expr {
        match self {
            Vector::Scalar(z) => z,
            Vector::Xyz(v) => &v[2],
        }
    }

    /// The rendering coordinates, when given.
    pub fn xy(&self) -> Option<(&Expr, &Expr)> {
        match self {
            Vector::Scalar(_) => None,
            Vector::Xyz(v) => Some((&v[0], &v[1])),
        }
    }
}

impl From<f64> for Vector {
    fn from(z: f64) -> Self {
        Vector::Scalar(Expr::Num(z))
    }
}

impl From<Expr> for Vector {
    fn from(z: Expr) -> Self {
        Vector::Scalar(z)
    }
}

impl From<[f64; 3]> for Vector {
    fn from(v: [f64; 3]) -> Self {
        Vector::Xyz(Box::new(v.map(Expr::Num)))
    }
}

/// One endpoint of an interaction, or the target of an input or output (spec §1.4, §2.8).
///
/// The coordinates of the connection-point forms are boxed: nearly every endpoint is a plain
/// label, and every interaction in a spec holds two endpoints.
#[derive(Clone, Debug, PartialEq)]
pub enum Endpoint {
    /// `@label`: a mass-type element or an avatar (and, for outputs, a ground).
    Label(Label),
    /// `[@macro α]` on a string, chain or stiff string: α ∈ [0, 1] along the nodes.
    Line { target: Label, alpha: Box<Expr> },
    /// `[@mesh u w]` on a mesh: u along the length, w along the width.
    Surface {
        target: Label,
        u: Box<Expr>,
        w: Box<Expr>,
    },
    /// `[@c u v w]` on a 3-D lattice (3-D spec §2.6): trilinear.
    Volume {
        target: Label,
        coords: Box<[Expr; 3]>,
    },
}

impl Endpoint {
    /// `@label`.
    pub fn label(label: &str) -> Endpoint {
        Endpoint::Label(label.into())
    }

    /// `[@target alpha]`.
    pub fn at(target: &str, alpha: impl Into<Expr>) -> Endpoint {
        Endpoint::Line {
            target: target.into(),
            alpha: Box::new(alpha.into()),
        }
    }

    /// `[@target u w]`.
    pub fn at2(target: &str, u: impl Into<Expr>, w: impl Into<Expr>) -> Endpoint {
        Endpoint::Surface {
            target: target.into(),
            u: Box::new(u.into()),
            w: Box::new(w.into()),
        }
    }

    /// The label the endpoint names (the macro's for connection points).
    pub fn target(&self) -> &str {
        match self {
            Endpoint::Label(l) => l,
            Endpoint::Line { target, .. }
            | Endpoint::Surface { target, .. }
            | Endpoint::Volume { target, .. } => target,
        }
    }
}

/// How a script writes an interaction (spec §2.9): a law under its own keyword, every column
/// in order ([`LawKind::row`]), or one of the short forms of the spring-damper.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LawForm {
    /// The law's own keyword (or an alias of it).
    Full(LawKind),
    /// `spring m1 m2 K`: f = K·Δx (and the legacy `spring m1 m2 K Z`, spec §3.12 a, which is
    /// read as `springDamper`).
    Spring,
    /// `damper m1 m2 Z`: f = Z·Δv.
    Damper,
}

impl LawForm {
    /// The law the form writes.
    pub fn kind(self) -> LawKind {
        match self {
            LawForm::Full(kind) => kind,
            LawForm::Spring | LawForm::Damper => LawKind::SpringDamper,
        }
    }

    /// The kind's columns the form writes, in order: all of them for a law's own keyword,
    /// K for `spring`, Z for `damper`.
    pub fn columns(self) -> std::ops::Range<usize> {
        match self {
            LawForm::Full(kind) => 0..kind.arity(),
            LawForm::Spring => 0..1,
            LawForm::Damper => 1..2,
        }
    }

    /// The keyword that writes the form.
    pub fn keyword(self) -> &'static str {
        match self {
            LawForm::Full(kind) => kind.row().keyword,
            LawForm::Spring => "spring",
            LawForm::Damper => "damper",
        }
    }
}

/// The law of an interaction (spec §2.3–§2.6): how it is written and its arguments, the
/// columns of its kind's row ([`crate::laws::LawRow::columns`]) that the form writes, in
/// order. Every law has this one shape, so a law added to the table needs nothing here.
#[derive(Clone, Debug, PartialEq)]
pub struct Law {
    form: LawForm,
    args: Vec<Expr>,
}

impl Law {
    /// The law `kind` under its own keyword with `args` as its columns in order; columns not
    /// given are 0 (the default of an optional column, spec §2.9), extra ones are dropped.
    pub fn new(kind: LawKind, args: impl IntoIterator<Item = Expr>) -> Law {
        Law::of_form(LawForm::Full(kind), args)
    }

    /// The law written in `form`, with `args` as the columns it writes.
    pub fn of_form(form: LawForm, args: impl IntoIterator<Item = Expr>) -> Law {
        let n = form.columns().len();
        let mut args: Vec<Expr> = args.into_iter().take(n).collect();
        args.resize(n, Expr::Num(0.0));
        Law { form, args }
    }

    /// `spring m1 m2 K`.
    pub fn spring(k: Expr) -> Law {
        Law::of_form(LawForm::Spring, [k])
    }

    /// `damper m1 m2 Z`.
    pub fn damper(z: Expr) -> Law {
        Law::of_form(LawForm::Damper, [z])
    }

    /// How the law is written.
    pub fn form(&self) -> LawForm {
        self.form
    }

    /// The law's kind: its row of the table of laws ([`LawKind::row`]). `spring` and
    /// `damper` are spring-dampers with one column written.
    pub fn kind(&self) -> LawKind {
        self.form.kind()
    }

    /// The arguments as written (the form's columns, in order).
    pub fn args(&self) -> &[Expr] {
        &self.args
    }

    /// The arguments as written, to change.
    pub fn args_mut(&mut self) -> &mut [Expr] {
        &mut self.args
    }

    /// The argument of the column named `name` in the kind's row (`"K"`, `"Vscale"`…), if
    /// the law has that column and its form writes it.
    pub fn arg(&self, name: &str) -> Option<&Expr> {
        let c = self
            .kind()
            .row()
            .columns
            .iter()
            .position(|c| c.name == name)?;
        let written = self.form.columns();
        written.contains(&c).then(|| &self.args[c - written.start])
    }

    /// The law's arguments in its kind's column order ([`crate::laws::LawRow::columns`]),
    /// with `zero` for a column the form leaves out (the Z of `spring`, the K of `damper`)
    /// and past the kind's own columns.
    pub fn columns<'a>(&'a self, zero: &'a Expr) -> [&'a Expr; LawKind::MAX_ARITY] {
        let written = self.form.columns();
        std::array::from_fn(|c| {
            if written.contains(&c) {
                &self.args[c - written.start]
            } else {
                zero
            }
        })
    }

    /// The canonical keyword of the law.
    pub fn keyword(&self) -> &'static str {
        self.form.keyword()
    }
}

/// The parameter scaling classes of spec §1.7.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ScaleClass {
    /// M, thresh, Pscale, smooth, positions, coordinates: ×1.
    None,
    /// K, K2, Knl, KnlP, KnlQ, Klim: ×(44100/SR)² when scaled.
    Stiffness,
    /// Z, Znl, Vscale, Zo: ×44100/SR when scaled.
    Damping,
    /// gravity: ×(44100/SR)²/44100 when scaled.
    Gravity,
}

/// The reference rate that script values are tuned at (spec §1.7).
pub const REFERENCE_SAMPLE_RATE_HZ: f64 = 44_100.0;

impl ScaleClass {
    /// The factor that turns a script value into a per-step value at `sample_rate_hz`.
    pub fn factor(self, mode: SampleRateMode, sample_rate_hz: f64) -> f64 {
        if mode == SampleRateMode::Raw {
            return 1.0;
        }
        let r = REFERENCE_SAMPLE_RATE_HZ / sample_rate_hz;
        match self {
            ScaleClass::None => 1.0,
            ScaleClass::Stiffness => r * r,
            ScaleClass::Damping => r,
            ScaleClass::Gravity => r * r / REFERENCE_SAMPLE_RATE_HZ,
        }
    }
}

/// The macro structures of spec §2.7.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MacroKind {
    /// Fixed ends, nodes 1..N-2 move.
    String,
    /// All nodes move.
    Chain,
    /// A string with extra undamped second-neighbour springs K2.
    StiffString,
    /// A grid with no pinned node.
    Mesh,
    /// A grid with its 4 corners pinned.
    CornerMesh,
    /// A grid with its whole border pinned.
    ClosedMesh,
}

impl MacroKind {
    pub fn keyword(self) -> &'static str {
        match self {
            MacroKind::String => "string",
            MacroKind::Chain => "chain",
            MacroKind::StiffString => "stiffString",
            MacroKind::Mesh => "mesh",
            MacroKind::CornerMesh => "cornerMesh",
            MacroKind::ClosedMesh => "closedMesh",
        }
    }

    /// True for the grid macros, addressed with two coordinates.
    pub fn is_2d(self) -> bool {
        matches!(
            self,
            MacroKind::Mesh | MacroKind::CornerMesh | MacroKind::ClosedMesh
        )
    }
}

/// A macro structure (spec §2.7): `@label TYPE sizes… M K [K2] Z {Zo=0} pos vel`.
#[derive(Clone, Debug, PartialEq)]
pub struct MacroSpec {
    pub kind: MacroKind,
    /// Node count along the string, or the mesh length L (nbX).
    pub length: u32,
    /// Mesh width W (nbY); 1 for the 1-D macros.
    pub width: u32,
    pub m: Expr,
    pub k: Expr,
    /// The stiff string's second-neighbour stiffness Ks; `None` for the other macros.
    pub k2: Option<Expr>,
    pub z: Expr,
    /// Ground friction, class Z.
    pub zo: Expr,
    pub pos: Vector,
    pub vel: Vector,
}

impl MacroSpec {
    /// The number of nodes, fixed ones included.
    pub fn num_nodes(&self) -> usize {
        self.length as usize * self.width.max(1) as usize
    }

    /// The number of internal interactions (spec §2.7): N−1 for strings and chains, 2N−1 for
    /// stiff strings, L(W−1)+(L−1)W for meshes.
    pub fn num_links(&self) -> usize {
        let l = self.length as usize;
        let w = self.width.max(1) as usize;
        match self.kind {
            MacroKind::String | MacroKind::Chain => l.saturating_sub(1),
            MacroKind::StiffString => (2 * l).saturating_sub(1),
            _ => l * w.saturating_sub(1) + l.saturating_sub(1) * w,
        }
    }
}

/// What an element is.
#[derive(Clone, Debug, PartialEq)]
pub enum ElementKind {
    /// `mass M {gravity} pos vel` (spec §2.1.1).
    Mass {
        m: Expr,
        gravity: Expr,
        pos: Vector,
        vel: Vector,
    },
    /// `osc M K Z {gravity} pos vel` (spec §2.1.2).
    Osc {
        m: Expr,
        k: Expr,
        z: Expr,
        gravity: Expr,
        pos: Vector,
        vel: Vector,
    },
    /// `ground pos` (spec §2.1.3).
    Ground { pos: Vector },
    /// Legacy `massG M G X0 XR0`: the last argument is a delayed position (spec §2.1.4).
    MassG {
        m: Expr,
        gravity: Expr,
        pos: Vector,
        delayed: Vector,
    },
    /// A macro structure (spec §2.7). Boxed: a macro is one element of a model and its spec is
    /// the largest kind, which would otherwise set the size of every element.
    Macro(Box<MacroSpec>),
    /// An interaction between two endpoints (spec §2.3–§2.6).
    Interaction { law: Law, a: Endpoint, b: Endpoint },
    /// `@inN posInput pos`: an avatar (spec §2.2.1).
    PosInput { channel: u32, pos: Vector },
    /// `@inN frcInput target` (spec §2.2.2).
    FrcInput { channel: u32, target: Endpoint },
    /// `@outN posOutput target` (spec §2.2.3).
    PosOutput { channel: u32, target: Endpoint },
    /// `@outN frcOutput target` (spec §2.2.4).
    FrcOutput { channel: u32, target: Endpoint },
}

impl ElementKind {
    /// The script keyword.
    pub fn keyword(&self) -> &'static str {
        match self {
            ElementKind::Mass { .. } => "mass",
            ElementKind::Osc { .. } => "osc",
            ElementKind::Ground { .. } => "ground",
            ElementKind::MassG { .. } => "massG",
            ElementKind::Macro(m) => m.kind.keyword(),
            ElementKind::Interaction { law, .. } => law.keyword(),
            ElementKind::PosInput { .. } => "posInput",
            ElementKind::FrcInput { .. } => "frcInput",
            ElementKind::PosOutput { .. } => "posOutput",
            ElementKind::FrcOutput { .. } => "frcOutput",
        }
    }

    /// True for the single material points of stage 2 a (mass, osc, ground, massG).
    pub fn is_single_mass(&self) -> bool {
        matches!(
            self,
            ElementKind::Mass { .. }
                | ElementKind::Osc { .. }
                | ElementKind::Ground { .. }
                | ElementKind::MassG { .. }
        )
    }
}

/// One line of a model: a labelled element.
#[derive(Clone, Debug, PartialEq)]
pub struct Element {
    /// The label without `@` (`in3`, `out1` for inputs and outputs).
    pub label: Label,
    pub kind: ElementKind,
    /// The named motion buffers (indices into [`ModelSpec::buffers`]) the element's points
    /// belong to: the scopes open at its line, and a legacy tag.
    pub buffers: Vec<u32>,
    /// Rendering (x, y) from a legacy trailing buffer tag (spec §6.4).
    pub tag_xy: Option<(f64, f64)>,
    pub span: Span,
}

/// A whole model, in script order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModelSpec {
    pub sample_rate_mode: SampleRateMode,
    pub params: Vec<ParamDecl>,
    pub elements: Vec<Element>,
    /// Named motion buffers, in order of first opening.
    pub buffers: Vec<String>,
    /// How a host plays the model (`~pitch`, `~key`, `~note`, `~route`, `~macro`). The
    /// engine ignores it.
    pub host: HostSpec,
    /// A 3-D model's medium and elements (`~dim 3`, 3-D spec §1.1); `elements` is then
    /// empty. `None` for a 1-D model.
    pub space: Option<Box<space::SpaceSpec>>,
}

impl ModelSpec {
    /// Whether the model is three-dimensional (`~dim 3`).
    pub fn is_3d(&self) -> bool {
        self.space.is_some()
    }

    /// The element labelled `label`.
    pub fn element(&self, label: &str) -> Option<&Element> {
        self.elements.iter().find(|e| e.label == label)
    }

    /// The parameter named `name`.
    pub fn param(&self, name: &str) -> Option<&ParamDecl> {
        self.params.iter().find(|p| p.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_built_inline_equal_the_general_ones() {
        for text in [
            "",
            "n",
            "n0",
            "string_1000_node_99999",
            "é-ü",
            "a\u{1F600}b",
            "  ",
            "\n\n",
        ]
        .into_iter()
        .map(String::from)
        .chain((20..=26).map(|n| "x".repeat(n)))
        {
            let (fast, general) = (label(&text), Label::new(&text));
            assert_eq!(fast, general, "{text:?}");
            assert_eq!(fast.as_str(), text);
            assert_eq!(
                fast.is_heap_allocated(),
                general.is_heap_allocated(),
                "{text:?}"
            );
        }
    }
}
