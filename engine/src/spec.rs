//! The model spec: what a model *is*, in user terms (labels, script values, expressions), before
//! it is compiled for a sample rate.
//!
//! Both the script parser and the Rust [`ModelBuilder`] produce a [`ModelSpec`]. It keeps the
//! script order of elements, because the stage order of spec §1.5 and the motion-buffer order of
//! §6.2 are defined by it. Nothing here touches the audio thread: [`crate::compile`] turns a spec
//! into flat arrays.

use crate::expr::Expr;

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
    Xyz([Expr; 3]),
}

impl Vector {
    /// The physics coordinate.
    pub fn z(&self) -> &Expr {
        match self {
            Vector::Scalar(z) => z,
            Vector::Xyz([_, _, z]) => z,
        }
    }

    /// The rendering coordinates, when given.
    pub fn xy(&self) -> Option<(&Expr, &Expr)> {
        match self {
            Vector::Scalar(_) => None,
            Vector::Xyz([x, y, _]) => Some((x, y)),
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
        Vector::Xyz(v.map(Expr::Num))
    }
}

/// One endpoint of an interaction, or the target of an input or output (spec §1.4, §2.8).
#[derive(Clone, Debug, PartialEq)]
pub enum Endpoint {
    /// `@label`: a mass-type element or an avatar (and, for outputs, a ground).
    Label(String),
    /// `[@macro α]` on a string, chain or stiff string: α ∈ [0, 1] along the nodes.
    Line { target: String, alpha: Expr },
    /// `[@mesh u w]` on a mesh: u along the length, w along the width.
    Surface { target: String, u: Expr, w: Expr },
}

impl Endpoint {
    /// `@label`.
    pub fn label(label: &str) -> Endpoint {
        Endpoint::Label(label.to_string())
    }

    /// `[@target alpha]`.
    pub fn at(target: &str, alpha: impl Into<Expr>) -> Endpoint {
        Endpoint::Line {
            target: target.to_string(),
            alpha: alpha.into(),
        }
    }

    /// `[@target u w]`.
    pub fn at2(target: &str, u: impl Into<Expr>, w: impl Into<Expr>) -> Endpoint {
        Endpoint::Surface {
            target: target.to_string(),
            u: u.into(),
            w: w.into(),
        }
    }

    /// The label the endpoint names (the macro's for connection points).
    pub fn target(&self) -> &str {
        match self {
            Endpoint::Label(l) => l,
            Endpoint::Line { target, .. } | Endpoint::Surface { target, .. } => target,
        }
    }
}

/// The law of an interaction (spec §2.3–§2.6), with its arguments in script order.
#[derive(Clone, Debug, PartialEq)]
pub enum Law {
    /// `spring m1 m2 K`: f = K·Δx.
    Spring { k: Expr },
    /// `damper m1 m2 Z`: f = Z·Δv.
    Damper { z: Expr },
    /// `springDamper m1 m2 K Z`: f = K·Δx + Z·Δv.
    SpringDamper { k: Expr, z: Expr },
    /// `contact m1 m2 K Z {thresh=0}`.
    Contact { k: Expr, z: Expr, thresh: Expr },
    /// `nlContact m1 m2 K KnlQ Klim Z {thresh=0}`: (s, c, k, Z, θ).
    NlContact {
        k: Expr,
        q: Expr,
        klim: Expr,
        z: Expr,
        thresh: Expr,
    },
    /// `nlSpring2 m1 m2 K KnlP Z` (alias `nlSpring`).
    NlSpring2 { k: Expr, q: Expr, z: Expr },
    /// `nlSpring3 m1 m2 K KnlQ Z`.
    NlSpring3 { k: Expr, q: Expr, z: Expr },
    /// `nlSpringDamper m1 m2 K KnlQ Klim Z`: (s, c, k, Z).
    NlSpringDamper {
        k: Expr,
        q: Expr,
        klim: Expr,
        z: Expr,
    },
    /// `nlPluck m1 m2 Knl Pscale {Z=0}`.
    NlPluck { k: Expr, scale: Expr, z: Expr },
    /// `nlBow m1 m2 Znl Vscale {smooth=0}`.
    NlBow { z: Expr, scale: Expr, smooth: Expr },
}

impl Law {
    /// The canonical keyword of the law.
    pub fn keyword(&self) -> &'static str {
        match self {
            Law::Spring { .. } => "spring",
            Law::Damper { .. } => "damper",
            Law::SpringDamper { .. } => "springDamper",
            Law::Contact { .. } => "contact",
            Law::NlContact { .. } => "nlContact",
            Law::NlSpring2 { .. } => "nlSpring2",
            Law::NlSpring3 { .. } => "nlSpring3",
            Law::NlSpringDamper { .. } => "nlSpringDamper",
            Law::NlPluck { .. } => "nlPluck",
            Law::NlBow { .. } => "nlBow",
        }
    }

    /// The arguments with their scaling class, in script order.
    pub fn args(&self) -> Vec<(&Expr, ScaleClass)> {
        use ScaleClass::{Damping as Zc, None as N, Stiffness as Kc};
        match self {
            Law::Spring { k } => vec![(k, Kc)],
            Law::Damper { z } => vec![(z, Zc)],
            Law::SpringDamper { k, z } => vec![(k, Kc), (z, Zc)],
            Law::Contact { k, z, thresh } => vec![(k, Kc), (z, Zc), (thresh, N)],
            Law::NlContact {
                k,
                q,
                klim,
                z,
                thresh,
            } => vec![(k, Kc), (q, Kc), (klim, Kc), (z, Zc), (thresh, N)],
            Law::NlSpring2 { k, q, z } | Law::NlSpring3 { k, q, z } => {
                vec![(k, Kc), (q, Kc), (z, Zc)]
            }
            Law::NlSpringDamper { k, q, klim, z } => {
                vec![(k, Kc), (q, Kc), (klim, Kc), (z, Zc)]
            }
            Law::NlPluck { k, scale, z } => vec![(k, Kc), (scale, N), (z, Zc)],
            Law::NlBow { z, scale, smooth } => vec![(z, Zc), (scale, Zc), (smooth, N)],
        }
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
    /// A macro structure (spec §2.7).
    Macro(MacroSpec),
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
    pub label: String,
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
}

/// A host channel a model input can be routed to (`~route inK SOURCE`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RouteSource {
    MainLeft,
    MainRight,
    /// Sidechain channel 1.
    SidechainLeft,
    /// Sidechain channel 2.
    SidechainRight,
    /// Sidechain channel 3 … 8 (`sidechain_3` … `sidechain_8`), in the plugin's multichannel
    /// layout.
    Sidechain(u8),
    /// Fed by nothing but MIDI strikes.
    None,
}

impl RouteSource {
    /// The widest sidechain a host can feed.
    pub const MAX_SIDECHAIN_CHANNELS: u8 = 8;

    /// The script names: `main_left`, `main_right`, `sidechain_left` (also `sidechain_1`),
    /// `sidechain_right` (`sidechain_2`), `sidechain_3` … `sidechain_8`, `none`.
    pub const NAMES: [(&'static str, RouteSource); 11] = [
        ("main_left", RouteSource::MainLeft),
        ("main_right", RouteSource::MainRight),
        ("sidechain_left", RouteSource::SidechainLeft),
        ("sidechain_right", RouteSource::SidechainRight),
        ("sidechain_3", RouteSource::Sidechain(3)),
        ("sidechain_4", RouteSource::Sidechain(4)),
        ("sidechain_5", RouteSource::Sidechain(5)),
        ("sidechain_6", RouteSource::Sidechain(6)),
        ("sidechain_7", RouteSource::Sidechain(7)),
        ("sidechain_8", RouteSource::Sidechain(8)),
        ("none", RouteSource::None),
    ];

    /// The sidechain channel `n` (1-based; 1 and 2 are left and right), if it exists.
    pub fn sidechain(n: u8) -> Option<RouteSource> {
        match n {
            1 => Some(RouteSource::SidechainLeft),
            2 => Some(RouteSource::SidechainRight),
            3..=Self::MAX_SIDECHAIN_CHANNELS => Some(RouteSource::Sidechain(n)),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        RouteSource::NAMES
            .iter()
            .find(|(_, s)| *s == self)
            .map(|(n, _)| *n)
            .unwrap_or("none")
    }

    pub fn from_name(name: &str) -> Option<RouteSource> {
        if let Some(n) = name.strip_prefix("sidechain_").and_then(|n| n.parse().ok()) {
            return RouteSource::sidechain(n);
        }
        RouteSource::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, s)| *s)
    }
}

/// `~route inK SOURCE`.
#[derive(Clone, Debug, PartialEq)]
pub struct Route {
    /// 1-based model input channel.
    pub input: u32,
    pub source: RouteSource,
}

/// `~macro NAME MIN MAX`.
#[derive(Clone, Debug, PartialEq)]
pub struct MacroRange {
    pub name: String,
    pub min: f64,
    pub max: f64,
}

/// How a host plays the model. Every field is optional; a host uses its defaults.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HostSpec {
    /// `~pitch HZ`: the model's pitch at its reference key, in Hz.
    pub pitch_hz: Option<f64>,
    /// `~key NOTE`: the MIDI key at which the model sounds as written (default 60).
    pub key: Option<f64>,
    /// `~note inK [FORCE]`: the input (1-based) that MIDI notes strike, and the force of a
    /// full-velocity note.
    pub note_input: Option<u32>,
    pub note_force: Option<f64>,
    /// `~route` lines, in script order.
    pub routes: Vec<Route>,
    /// `~macro` lines, in script order.
    pub macro_ranges: Vec<MacroRange>,
    /// `~voices N`: how many notes the model plays at once by default (1 … 1024).
    pub voices: Option<u32>,
    /// `~pressure inK [AMOUNT]`: the input (1-based) that key pressure drives, and what full
    /// pressure adds to it.
    pub pressure_input: Option<u32>,
    pub pressure_scale: Option<f64>,
}

impl ModelSpec {
    /// The element labelled `label`.
    pub fn element(&self, label: &str) -> Option<&Element> {
        self.elements.iter().find(|e| e.label == label)
    }

    /// The parameter named `name`.
    pub fn param(&self, name: &str) -> Option<&ParamDecl> {
        self.params.iter().find(|p| p.name == name)
    }
}

/// Builds a [`ModelSpec`] from Rust, in script order. Arguments take anything that converts
/// into an [`Expr`]: an `f64` literal, a `&str` parameter name, or an expression tree.
///
/// ```
/// use ressort_engine::{Endpoint, Law, ModelBuilder, MacroKind};
/// let mut b = ModelBuilder::new();
/// b.param("K", 0.1).param("Z", 0.001);
/// b.macro_1d("s", MacroKind::String, 42, 1.0, "K", "Z");
/// b.interaction("hit", Law::Contact { k: 0.1.into(), z: 0.001.into(), thresh: 0.0.into() },
///               Endpoint::at("s", 0.13), Endpoint::label("h"));
/// b.mass("h", 1.0, 0.1, 0.0);
/// b.frc_input(1, Endpoint::label("h"));
/// b.pos_output(1, Endpoint::at("s", 0.77));
/// let spec = b.build();
/// assert_eq!(spec.elements.len(), 5);
/// ```
#[derive(Debug, Default)]
pub struct ModelBuilder {
    spec: ModelSpec,
    open_scopes: Vec<u32>,
}

impl ModelBuilder {
    pub fn new() -> ModelBuilder {
        ModelBuilder::default()
    }

    /// Switches the whole model to raw per-step values (`~samplerate raw`).
    pub fn raw(&mut self) -> &mut Self {
        self.spec.sample_rate_mode = SampleRateMode::Raw;
        self
    }

    /// `@name param value`.
    pub fn param(&mut self, name: &str, value: f64) -> &mut Self {
        self.spec.params.push(ParamDecl {
            name: name.to_string(),
            kind: ParamKind::Control { value },
            span: Span::default(),
        });
        self
    }

    /// `@name audioParam @inN` (default 0).
    pub fn audio_param(&mut self, name: &str, input: u32) -> &mut Self {
        self.audio_param_with_default(name, input, 0.0)
    }

    /// `@name audioParam @inN default`: default + input N.
    pub fn audio_param_with_default(&mut self, name: &str, input: u32, default: f64) -> &mut Self {
        self.spec.params.push(ParamDecl {
            name: name.to_string(),
            kind: ParamKind::Audio { input, default },
            span: Span::default(),
        });
        self
    }

    /// `~begin name`: points created from now on also join the named buffer.
    pub fn begin_scope(&mut self, name: &str) -> &mut Self {
        let id = match self.spec.buffers.iter().position(|b| b == name) {
            Some(i) => i as u32,
            None => {
                self.spec.buffers.push(name.to_string());
                (self.spec.buffers.len() - 1) as u32
            }
        };
        if !self.open_scopes.contains(&id) {
            self.open_scopes.push(id);
        }
        self
    }

    /// `~end name`.
    pub fn end_scope(&mut self, name: &str) -> &mut Self {
        if let Some(i) = self.spec.buffers.iter().position(|b| b == name) {
            self.open_scopes.retain(|&s| s != i as u32);
        }
        self
    }

    /// Appends an element with the currently open scopes.
    pub fn element(&mut self, label: &str, kind: ElementKind) -> &mut Self {
        self.spec.elements.push(Element {
            label: label.to_string(),
            kind,
            buffers: self.open_scopes.clone(),
            tag_xy: None,
            span: Span::default(),
        });
        self
    }

    /// `@label mass M pos vel` (no gravity).
    pub fn mass(
        &mut self,
        label: &str,
        m: impl Into<Expr>,
        pos: impl Into<Vector>,
        vel: impl Into<Vector>,
    ) -> &mut Self {
        self.mass_with_gravity(label, m, 0.0, pos, vel)
    }

    /// `@label mass M gravity pos vel`.
    pub fn mass_with_gravity(
        &mut self,
        label: &str,
        m: impl Into<Expr>,
        gravity: impl Into<Expr>,
        pos: impl Into<Vector>,
        vel: impl Into<Vector>,
    ) -> &mut Self {
        self.element(
            label,
            ElementKind::Mass {
                m: m.into(),
                gravity: gravity.into(),
                pos: pos.into(),
                vel: vel.into(),
            },
        )
    }

    /// `@label osc M K Z pos vel` (no gravity).
    pub fn osc(
        &mut self,
        label: &str,
        m: impl Into<Expr>,
        k: impl Into<Expr>,
        z: impl Into<Expr>,
        pos: impl Into<Vector>,
        vel: impl Into<Vector>,
    ) -> &mut Self {
        self.element(
            label,
            ElementKind::Osc {
                m: m.into(),
                k: k.into(),
                z: z.into(),
                gravity: Expr::Num(0.0),
                pos: pos.into(),
                vel: vel.into(),
            },
        )
    }

    /// `@label ground pos`.
    pub fn ground(&mut self, label: &str, pos: impl Into<Vector>) -> &mut Self {
        self.element(label, ElementKind::Ground { pos: pos.into() })
    }

    /// A 1-D macro (`string`, `chain`) of `nodes` nodes at rest at 0, without ground friction.
    pub fn macro_1d(
        &mut self,
        label: &str,
        kind: MacroKind,
        nodes: u32,
        m: impl Into<Expr>,
        k: impl Into<Expr>,
        z: impl Into<Expr>,
    ) -> &mut Self {
        self.element(
            label,
            ElementKind::Macro(MacroSpec {
                kind,
                length: nodes,
                width: 1,
                m: m.into(),
                k: k.into(),
                k2: None,
                z: z.into(),
                zo: Expr::Num(0.0),
                pos: 0.0.into(),
                vel: 0.0.into(),
            }),
        )
    }

    /// A mesh macro of `length × width` nodes at rest at 0, without ground friction.
    pub fn mesh(
        &mut self,
        label: &str,
        kind: MacroKind,
        length: u32,
        width: u32,
        m: impl Into<Expr>,
        k: impl Into<Expr>,
        z: impl Into<Expr>,
    ) -> &mut Self {
        self.element(
            label,
            ElementKind::Macro(MacroSpec {
                kind,
                length,
                width,
                m: m.into(),
                k: k.into(),
                k2: None,
                z: z.into(),
                zo: Expr::Num(0.0),
                pos: 0.0.into(),
                vel: 0.0.into(),
            }),
        )
    }

    /// Any macro, fully specified.
    pub fn macro_spec(&mut self, label: &str, spec: MacroSpec) -> &mut Self {
        self.element(label, ElementKind::Macro(spec))
    }

    /// An interaction `@label <law> a b args…`.
    pub fn interaction(&mut self, label: &str, law: Law, a: Endpoint, b: Endpoint) -> &mut Self {
        self.element(label, ElementKind::Interaction { law, a, b })
    }

    /// `@label springDamper a b K Z`.
    pub fn spring_damper(
        &mut self,
        label: &str,
        a: Endpoint,
        b: Endpoint,
        k: impl Into<Expr>,
        z: impl Into<Expr>,
    ) -> &mut Self {
        self.interaction(
            label,
            Law::SpringDamper {
                k: k.into(),
                z: z.into(),
            },
            a,
            b,
        )
    }

    /// `@label contact a b K Z thresh`.
    pub fn contact(
        &mut self,
        label: &str,
        a: Endpoint,
        b: Endpoint,
        k: impl Into<Expr>,
        z: impl Into<Expr>,
        thresh: impl Into<Expr>,
    ) -> &mut Self {
        self.interaction(
            label,
            Law::Contact {
                k: k.into(),
                z: z.into(),
                thresh: thresh.into(),
            },
            a,
            b,
        )
    }

    /// `@inN posInput pos`.
    pub fn pos_input(&mut self, channel: u32, pos: impl Into<Vector>) -> &mut Self {
        self.element(
            &format!("in{channel}"),
            ElementKind::PosInput {
                channel,
                pos: pos.into(),
            },
        )
    }

    /// `@inN frcInput target`.
    pub fn frc_input(&mut self, channel: u32, target: Endpoint) -> &mut Self {
        self.element(
            &format!("in{channel}"),
            ElementKind::FrcInput { channel, target },
        )
    }

    /// `@outN posOutput target`.
    pub fn pos_output(&mut self, channel: u32, target: Endpoint) -> &mut Self {
        self.element(
            &format!("out{channel}"),
            ElementKind::PosOutput { channel, target },
        )
    }

    /// `@outN frcOutput target`.
    pub fn frc_output(&mut self, channel: u32, target: Endpoint) -> &mut Self {
        self.element(
            &format!("out{channel}"),
            ElementKind::FrcOutput { channel, target },
        )
    }

    /// The finished spec.
    pub fn build(&self) -> ModelSpec {
        self.spec.clone()
    }

    /// The finished spec, without copying it.
    pub fn finish(self) -> ModelSpec {
        self.spec
    }
}
