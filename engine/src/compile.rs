//! Compiles a [`ModelSpec`] for one sample rate into an [`Engine`]: labels are resolved to point
//! indices, arguments to slots of one flat array, elements are grouped by kind. Runs off the
//! audio thread; every problem is collected in one pass (spec §3.12 f).

use crate::engine::{
    ArgClass, Binding, Engine, Group, InitRule, InitRun, Interactions, LineMacro, MacroSlots,
    Macros, MeshMacro, Points, Proxies, Route, SingleMasses, DEFAULT_POSITION_LIMIT,
    NUM_ARG_CLASSES,
};
use crate::expr::{Expr, ExprRef, Func, Program};
use crate::info::{InputUse, ModelInfo, OutputUse, OwnerInfo, ParamInfo, PointInfo, PointKind};
use crate::motion::{MotionLayout, NamedBuffer, DEFAULT_MOTION_INTERVAL_SAMPLES};
use crate::spec::{
    ElementKind, Endpoint, Law, MacroKind, MacroSpec, ModelSpec, ParamKind, SampleRateMode,
    ScaleClass, Span, Vector, REFERENCE_SAMPLE_RATE_HZ,
};
use label_map::LabelMap;
use std::collections::HashMap;
use std::fmt;

pub(crate) mod label_map;

/// The most material points a model may have (about 100 MB of state and scratch).
pub const MAX_POINTS: usize = 1 << 20;
/// The deepest expression tree accepted.
pub const MAX_EXPR_DEPTH: usize = 256;
/// The sample rates accepted, in Hz.
pub const SAMPLE_RATE_RANGE_HZ: std::ops::RangeInclusive<f64> = 1.0..=10_000_000.0;

/// How to compile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompileOptions {
    /// The running sample rate in Hz.
    pub sample_rate_hz: f64,
    /// The motion refresh interval R in samples (spec §6.1), ≥ 1.
    pub motion_interval: u32,
}

impl Default for CompileOptions {
    fn default() -> Self {
        CompileOptions {
            sample_rate_hz: REFERENCE_SAMPLE_RATE_HZ,
            motion_interval: DEFAULT_MOTION_INTERVAL_SAMPLES,
        }
    }
}

impl CompileOptions {
    /// Options for `sample_rate_hz` with the default motion interval.
    pub fn at(sample_rate_hz: f64) -> CompileOptions {
        CompileOptions {
            sample_rate_hz,
            ..CompileOptions::default()
        }
    }
}

/// What went wrong compiling one element (or the whole model).
#[derive(Clone, Debug, PartialEq)]
pub enum CompileErrorKind {
    /// The sample rate is not a finite number in [`SAMPLE_RATE_RANGE_HZ`].
    InvalidSampleRate(f64),
    /// The motion interval is 0.
    InvalidMotionInterval,
    /// The label is already used by the element or parameter at `first`.
    DuplicateLabel { first: Span },
    /// A parameter name that is not an identifier, or is a function name.
    InvalidParamName,
    /// An expression names something that is not declared.
    UndefinedName(String),
    /// An expression names an element, not a parameter.
    NotAParameter(String),
    /// A function called with the wrong number of arguments.
    WrongArity {
        func: &'static str,
        expected: usize,
        found: usize,
    },
    /// An expression nested deeper than [`MAX_EXPR_DEPTH`].
    ExpressionTooDeep,
    /// An endpoint or target names no element.
    UndefinedElement(String),
    /// An endpoint or target names something that is not a point (`found` says what).
    NotAPoint { target: String, found: &'static str },
    /// A macro referred to without connection-point brackets.
    BareMacroReference(String),
    /// Connection-point brackets on something that is not a macro.
    NotAMacro(String),
    /// The wrong number of connection coordinates for the macro.
    WrongCoordinateCount {
        target: String,
        expected: usize,
        found: usize,
    },
    /// A macro size below 2.
    InvalidSize(u32),
    /// The model would have more than [`MAX_POINTS`] points.
    TooLarge { points: usize },
    /// An input or output channel numbered 0.
    InvalidChannel,
    /// A constant argument outside its domain (e.g. a mass that is not > 0).
    InvalidValue { what: &'static str, value: f64 },
}

/// A compile error: what, on which element, and where in the script.
#[derive(Clone, Debug, PartialEq)]
pub struct CompileError {
    pub kind: CompileErrorKind,
    /// The label of the element or parameter involved (empty for model-wide errors).
    pub label: String,
    pub span: Span,
}

impl fmt::Display for CompileErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use CompileErrorKind::*;
        match self {
            InvalidSampleRate(v) => write!(
                f,
                "sample rate {v} Hz is outside {}..={} Hz",
                SAMPLE_RATE_RANGE_HZ.start(),
                SAMPLE_RATE_RANGE_HZ.end()
            ),
            InvalidMotionInterval => write!(f, "motion interval must be at least 1 sample"),
            DuplicateLabel { first } if first.is_known() => write!(
                f,
                "duplicate label, first used at line {} column {}",
                first.line, first.col
            ),
            DuplicateLabel { .. } => write!(f, "duplicate label"),
            InvalidParamName => write!(
                f,
                "a parameter name must be an identifier that is not a function name"
            ),
            UndefinedName(n) => write!(f, "undefined name `{n}` in expression"),
            NotAParameter(n) => write!(f, "`{n}` is an element, not a parameter"),
            WrongArity {
                func,
                expected,
                found,
            } => write!(f, "`{func}` takes {expected} argument(s), found {found}"),
            ExpressionTooDeep => write!(f, "expression nested deeper than {MAX_EXPR_DEPTH}"),
            UndefinedElement(t) => write!(f, "undefined element `@{t}`"),
            NotAPoint { target, found } => {
                write!(f, "`@{target}` is {found}, not a point")
            }
            BareMacroReference(t) => write!(
                f,
                "macro `@{t}` must be addressed through a connection point such as `[@{t} 0.5]`"
            ),
            NotAMacro(t) => write!(f, "connection point on `@{t}`, which is not a macro"),
            WrongCoordinateCount {
                target,
                expected,
                found,
            } => write!(
                f,
                "connection point on `@{target}` needs {expected} coordinate(s), found {found}"
            ),
            InvalidSize(v) => write!(f, "macro size {v} is below 2"),
            TooLarge { points } => write!(
                f,
                "model has {points} points, more than the limit of {MAX_POINTS}"
            ),
            InvalidChannel => write!(f, "channel numbers start at 1"),
            InvalidValue { what, value } => write!(f, "{what}, found {value}"),
        }
    }
}

impl fmt::Display for CompileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if !self.label.is_empty() {
            write!(f, "@{}: ", self.label)?;
        }
        write!(f, "{}", self.kind)?;
        if self.span.is_known() {
            write!(f, " at line {} column {}", self.span.line, self.span.col)?;
        }
        Ok(())
    }
}

impl std::error::Error for CompileError {}

/// Every error of one compilation.
#[derive(Clone, Debug, PartialEq)]
pub struct CompileErrors(pub Vec<CompileError>);

impl fmt::Display for CompileErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for CompileErrors {}

/// What a label resolves to.
#[derive(Clone, Copy, Debug)]
enum Symbol {
    Param(u32),
    Element(usize),
}

/// A row of an interaction group before columns are laid out.
struct Row<'a> {
    a: u32,
    b: u32,
    args: Vec<(&'a Expr, ArgClass)>,
    element: usize,
}

/// Compile-time state.
struct Cx<'a> {
    spec: &'a ModelSpec,
    symbols: LabelMap<&'a str, Symbol>,
    errors: Vec<CompileError>,
    program: Program,
    args: Vec<f64>,
    control_bindings: Vec<Binding>,
    audio_bindings: Vec<Binding>,
    /// Parameter id → audio-rate.
    param_is_audio: Vec<bool>,
    /// Parameter id → named in a connection-point coordinate.
    param_is_coordinate: Vec<bool>,
    /// Element index → first point (single masses, avatars) or first node (macros).
    element_point: Vec<Option<u32>>,
    proxies: Proxies,
    /// Connection points whose coordinates depend on an audio-rate parameter.
    proxy_audio: Vec<u32>,
    /// The endpoint that created each connection point, to find points at the same location.
    proxy_endpoints: Vec<&'a Endpoint>,
}

impl<'a> Cx<'a> {
    fn error(&mut self, element: Option<usize>, kind: CompileErrorKind) {
        let (label, span) = match element {
            Some(i) => (
                self.spec.elements[i].label.clone(),
                self.spec.elements[i].span,
            ),
            None => (String::new(), Span::default()),
        };
        self.errors.push(CompileError { kind, label, span });
    }

    /// Checks an expression's names and calls; returns true when it is usable.
    fn check_expr(&mut self, expr: &Expr, element: usize) -> bool {
        if expr.depth() > MAX_EXPR_DEPTH {
            self.error(Some(element), CompileErrorKind::ExpressionTooDeep);
            return false;
        }
        let mut ok = true;
        let mut names = Vec::new();
        expr.for_each_name(&mut |n| names.push(n.to_string()));
        for n in names {
            match self.symbols.get(n.as_str()) {
                Some(Symbol::Param(_)) => {}
                Some(Symbol::Element(_)) => {
                    self.error(Some(element), CompileErrorKind::NotAParameter(n));
                    ok = false;
                }
                None => {
                    self.error(Some(element), CompileErrorKind::UndefinedName(n));
                    ok = false;
                }
            }
        }
        ok &= self.check_arity(expr, element);
        ok
    }

    fn check_arity(&mut self, expr: &Expr, element: usize) -> bool {
        match expr {
            Expr::Num(_) | Expr::Name(_) => true,
            Expr::Neg(e) => self.check_arity(e, element),
            Expr::Binary(_, a, b) => self.check_arity(a, element) & self.check_arity(b, element),
            Expr::Call(func, args) => {
                let mut ok = true;
                if args.len() != func.arity() {
                    self.error(
                        Some(element),
                        CompileErrorKind::WrongArity {
                            func: func.name(),
                            expected: func.arity(),
                            found: args.len(),
                        },
                    );
                    ok = false;
                }
                for a in args {
                    ok &= self.check_arity(a, element);
                }
                ok
            }
        }
    }

    /// Compiles `expr` into the program. Invalid expressions become NaN constants (the
    /// model is not built anyway, since an error was recorded).
    fn expr(&mut self, expr: &Expr, element: usize) -> (ExprRef, bool) {
        if let Expr::Num(_) = expr {
            // The commonest argument: nothing to check, resolve or mark audio-rate.
            let r = self
                .program
                .push(expr, &|_| None)
                .expect("a number names nothing");
            return (r, false);
        }
        let valid = self.check_expr(expr, element);
        let nan = Expr::Num(f64::NAN);
        let expr = if valid { expr } else { &nan };
        let symbols = &self.symbols;
        let resolve = |n: &str| match symbols.get(n) {
            Some(Symbol::Param(id)) => Some(*id),
            _ => None,
        };
        let r = self
            .program
            .push(expr, &resolve)
            .expect("names were checked");
        let mut audio = false;
        expr.for_each_name(&mut |n| {
            if let Some(Symbol::Param(id)) = self.symbols.get(n) {
                audio |= self.param_is_audio[*id as usize];
            }
        });
        (r, audio)
    }

    /// Binds `expr` (of `class`) to argument slot `slot`. Returns true when it is audio-rate.
    fn bind(&mut self, expr: &Expr, class: ArgClass, slot: usize, element: usize) -> bool {
        let (r, audio) = self.expr(expr, element);
        let b = Binding {
            slot: slot as u32,
            expr: r,
            class,
        };
        if audio {
            self.audio_bindings.push(b);
        } else {
            self.control_bindings.push(b);
        }
        audio
    }

    /// A fresh argument slot bound to `expr`.
    fn slot(&mut self, expr: &Expr, class: ArgClass, element: usize) -> (usize, bool) {
        let slot = self.args.len();
        self.args.push(0.0);
        let audio = self.bind(expr, class, slot, element);
        (slot, audio)
    }

    /// Checks that a constant argument is finite and, where `positive`, > 0.
    fn check_constant(&mut self, expr: &Expr, what: &'static str, positive: bool, element: usize) {
        if let Some(v) = expr.as_number() {
            if !v.is_finite() || (positive && v <= 0.0) {
                self.error(
                    Some(element),
                    CompileErrorKind::InvalidValue { what, value: v },
                );
            }
        }
    }

    /// Resolves an endpoint or target to a point index, creating a connection point for a
    /// bracket reference. `proxy_base` is the index of the first connection point.
    fn endpoint(&mut self, ep: &'a Endpoint, element: usize, proxy_base: usize) -> Option<u32> {
        let target = ep.target();
        let Some(&symbol) = self.symbols.get(target) else {
            self.error(
                Some(element),
                CompileErrorKind::UndefinedElement(target.to_string()),
            );
            return None;
        };
        let found = match symbol {
            Symbol::Param(_) => "a parameter",
            Symbol::Element(j) => match &self.spec.elements[j].kind {
                ElementKind::Macro(_) => "a macro",
                ElementKind::Interaction { .. } => "an interaction",
                ElementKind::FrcInput { .. } => "a force input",
                ElementKind::PosOutput { .. } | ElementKind::FrcOutput { .. } => "an output",
                _ => "a point",
            },
        };
        match (ep, symbol) {
            (Endpoint::Label(_), Symbol::Element(j)) if found == "a point" => self.element_point[j],
            (Endpoint::Label(_), _) if found == "a macro" => {
                self.error(
                    Some(element),
                    CompileErrorKind::BareMacroReference(target.to_string()),
                );
                None
            }
            (Endpoint::Label(_), _) => {
                self.error(
                    Some(element),
                    CompileErrorKind::NotAPoint {
                        target: target.to_string(),
                        found,
                    },
                );
                None
            }
            (Endpoint::Line { .. } | Endpoint::Surface { .. }, Symbol::Element(j))
                if found == "a macro" =>
            {
                let ElementKind::Macro(mac) = &self.spec.elements[j].kind else {
                    return None;
                };
                let (coords, found_count): (Vec<&Expr>, usize) = match ep {
                    Endpoint::Line { alpha, .. } => (vec![alpha], 1),
                    Endpoint::Surface { u, w, .. } => (vec![u, w], 2),
                    Endpoint::Label(_) => return None,
                };
                let expected = if mac.kind.is_2d() { 2 } else { 1 };
                if expected != found_count {
                    self.error(
                        Some(element),
                        CompileErrorKind::WrongCoordinateCount {
                            target: target.to_string(),
                            expected,
                            found: found_count,
                        },
                    );
                    return None;
                }
                let base = self.element_point[j]?;
                for c in &coords {
                    c.for_each_name(&mut |n| {
                        if let Some(Symbol::Param(id)) = self.symbols.get(n) {
                            self.param_is_coordinate[*id as usize] = true;
                        }
                    });
                }
                let zero = Expr::Num(0.0);
                let (s0, audio0) = self.slot(coords[0], ArgClass::None, element);
                let (s1, audio1) = self.slot(
                    coords.get(1).copied().unwrap_or(&zero),
                    ArgClass::None,
                    element,
                );
                let index = self.proxies.len();
                let width = if mac.kind.is_2d() { mac.width } else { 0 };
                self.proxies.geometry.push((base, mac.length, width));
                self.proxies.coord_slots.push([s0, s1]);
                self.proxies.nodes.push([base; 4]);
                self.proxies.weights.push([1.0, 0.0, 0.0, 0.0]);
                self.proxy_endpoints.push(ep);
                if audio0 || audio1 {
                    // Recomputed every sample.
                    self.proxy_audio.push(index as u32);
                }
                Some((proxy_base + index) as u32)
            }
            (Endpoint::Line { .. } | Endpoint::Surface { .. }, _) => {
                self.error(
                    Some(element),
                    CompileErrorKind::NotAMacro(target.to_string()),
                );
                None
            }
        }
    }
}

/// The text of an endpoint, for metadata (`@h`, `[@s 0.3]`).
fn describe_endpoint(ep: &Endpoint) -> String {
    match ep {
        Endpoint::Label(l) => format!("@{l}"),
        Endpoint::Line { target, alpha } => format!("[@{target} {}]", bracket_coord(alpha)),
        Endpoint::Surface { target, u, w } => {
            format!("[@{target} {} {}]", bracket_coord(u), bracket_coord(w))
        }
    }
}

fn bracket_coord(e: &Expr) -> String {
    let text = e.to_string();
    if text.contains(' ') {
        format!("({text})")
    } else {
        text
    }
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Compiles `spec` for `options.sample_rate_hz`. Returns every error found, or an engine in its
/// initial state (spec §1.5 stage 0).
pub fn compile(spec: &ModelSpec, options: &CompileOptions) -> Result<Engine, CompileErrors> {
    Compiler::new(spec).run(options)
}

/// The compiler proper; `Cx` plus the per-kind assembly.
struct Compiler<'a> {
    cx: Cx<'a>,
}

impl<'a> std::ops::Deref for Compiler<'a> {
    type Target = Cx<'a>;
    fn deref(&self) -> &Cx<'a> {
        &self.cx
    }
}

impl<'a> std::ops::DerefMut for Compiler<'a> {
    fn deref_mut(&mut self) -> &mut Cx<'a> {
        &mut self.cx
    }
}

impl<'a> Compiler<'a> {
    fn new(spec: &'a ModelSpec) -> Compiler<'a> {
        Compiler {
            cx: Cx {
                spec,
                symbols: LabelMap::with_capacity_and_hasher(
                    spec.params.len() + spec.elements.len(),
                    Default::default(),
                ),
                errors: Vec::new(),
                program: Program::default(),
                args: Vec::new(),
                control_bindings: Vec::new(),
                audio_bindings: Vec::new(),
                param_is_audio: Vec::new(),
                param_is_coordinate: Vec::new(),
                element_point: vec![None; spec.elements.len()],
                proxies: Proxies::default(),
                proxy_audio: Vec::new(),
                proxy_endpoints: Vec::new(),
            },
        }
    }

    fn run(mut self, options: &CompileOptions) -> Result<Engine, CompileErrors> {
        let spec = self.spec;
        let sr = options.sample_rate_hz;
        if !(sr.is_finite() && SAMPLE_RATE_RANGE_HZ.contains(&sr)) {
            self.error(None, CompileErrorKind::InvalidSampleRate(sr));
        }
        if options.motion_interval == 0 {
            self.error(None, CompileErrorKind::InvalidMotionInterval);
        }
        let sr = if self.errors.is_empty() {
            sr
        } else {
            REFERENCE_SAMPLE_RATE_HZ
        };
        let mode = spec.sample_rate_mode;

        // Symbols: parameters and elements share one label space (spec §3.4).
        let mut first_span: LabelMap<&str, Span> =
            LabelMap::with_capacity_and_hasher(self.symbols.capacity(), Default::default());
        for (id, p) in spec.params.iter().enumerate() {
            if let Some(&first) = first_span.get(p.name.as_str()) {
                self.errors.push(CompileError {
                    kind: CompileErrorKind::DuplicateLabel { first },
                    label: p.name.clone(),
                    span: p.span,
                });
                continue;
            }
            first_span.insert(&p.name, p.span);
            if !is_identifier(&p.name) || Func::from_name(&p.name).is_some() {
                self.errors.push(CompileError {
                    kind: CompileErrorKind::InvalidParamName,
                    label: p.name.clone(),
                    span: p.span,
                });
            }
            self.symbols.insert(&p.name, Symbol::Param(id as u32));
        }
        for (i, e) in spec.elements.iter().enumerate() {
            if let Some(&first) = first_span.get(e.label.as_str()) {
                self.error(Some(i), CompileErrorKind::DuplicateLabel { first });
                continue;
            }
            first_span.insert(&e.label, e.span);
            self.symbols.insert(&e.label, Symbol::Element(i));
        }
        let mut params = Vec::with_capacity(spec.params.len());
        let mut param_info = Vec::with_capacity(spec.params.len());
        let mut audio_params = Vec::new();
        for (id, p) in spec.params.iter().enumerate() {
            let (value, audio_input) = match p.kind {
                ParamKind::Control { value } => {
                    if !value.is_finite() {
                        self.errors.push(CompileError {
                            kind: CompileErrorKind::InvalidValue {
                                what: "a parameter value must be finite",
                                value,
                            },
                            label: p.name.clone(),
                            span: p.span,
                        });
                    }
                    (value, None)
                }
                ParamKind::Audio { input, default } => {
                    if !default.is_finite() {
                        self.errors.push(CompileError {
                            kind: CompileErrorKind::InvalidValue {
                                what: "an audio-rate parameter's default must be finite",
                                value: default,
                            },
                            label: p.name.clone(),
                            span: p.span,
                        });
                    }
                    if input == 0 {
                        self.errors.push(CompileError {
                            kind: CompileErrorKind::InvalidChannel,
                            label: p.name.clone(),
                            span: p.span,
                        });
                    } else {
                        audio_params.push(Route {
                            channel: input - 1,
                            index: id as u32,
                        });
                    }
                    (default, Some(input))
                }
            };
            params.push(if value.is_finite() { value } else { 0.0 });
            self.param_is_audio.push(audio_input.is_some());
            self.param_is_coordinate.push(false);
            param_info.push(ParamInfo {
                name: p.name.clone(),
                default: value,
                audio_input,
                coordinate: false,
            });
        }

        // Points: single masses, macro nodes, avatars (spec §6.2 order).
        let mut owners = Vec::new();
        let mut points: Vec<PointInfo> = Vec::new();
        let mut owner_element = Vec::new();
        let mut too_large = false;
        for pass in 0..3 {
            for (i, e) in spec.elements.iter().enumerate() {
                let (count, kind, width) = match (&e.kind, pass) {
                    (ElementKind::Mass { .. }, 0) => (1, PointKind::Mass, 0),
                    (ElementKind::Osc { .. }, 0) => (1, PointKind::Osc, 0),
                    (ElementKind::Ground { .. }, 0) => (1, PointKind::Ground, 0),
                    (ElementKind::MassG { .. }, 0) => (1, PointKind::MassG, 0),
                    (ElementKind::Macro(m), 1) => {
                        let sizes_ok = self.check_macro_sizes(m, i);
                        if !sizes_ok {
                            continue;
                        }
                        let w = if m.kind.is_2d() { m.width } else { 0 };
                        (m.num_nodes(), PointKind::MacroNode { fixed: false }, w)
                    }
                    (ElementKind::PosInput { .. }, 2) => (1, PointKind::Avatar, 0),
                    _ => continue,
                };
                if points.len() + count > MAX_POINTS {
                    too_large = true;
                    continue;
                }
                let owner = owners.len() as u32;
                owners.push(OwnerInfo {
                    label: e.label.clone(),
                    keyword: e.kind.keyword(),
                    mesh_width: width,
                });
                owner_element.push(i);
                self.element_point[i] = Some(points.len() as u32);
                points.extend((0..count).map(|node| PointInfo {
                    owner,
                    node: node as u32,
                    kind,
                }));
            }
        }
        if too_large {
            let total: usize = spec
                .elements
                .iter()
                .map(|e| match &e.kind {
                    ElementKind::Macro(m) => m.num_nodes(),
                    k if k.is_single_mass() => 1,
                    ElementKind::PosInput { .. } => 1,
                    _ => 0,
                })
                .sum();
            self.error(None, CompileErrorKind::TooLarge { points: total });
        }
        let num_points = points.len();

        // Single masses: columns M, K, Z, gravity.
        let singles_elems: Vec<usize> = (0..spec.elements.len())
            .filter(|&i| spec.elements[i].kind.is_single_mass())
            .filter(|&i| self.element_point[i].is_some())
            .collect();
        let n_single = singles_elems.len();
        let cols = [0, 1, 2, 3].map(|c| self.args.len() + c * n_single);
        let new_len = self.args.len() + 4 * n_single;
        self.args.resize(new_len, 0.0);
        let mut singles = SingleMasses {
            a: vec![0.0; n_single],
            b: vec![0.0; n_single],
            inv_m: vec![0.0; n_single],
            gravity: vec![0.0; n_single],
            fixed: vec![false; n_single],
            cols,
        };
        let mut init_runs = Vec::new();
        let mut audio_masses = Vec::new();
        let velocity_factor = match mode {
            SampleRateMode::Scaled => 1.0 / sr,
            SampleRateMode::Raw => 1.0,
        };
        let zero = Expr::Num(0.0);
        for (row, &i) in singles_elems.iter().enumerate() {
            let e = &spec.elements[i];
            let (m, k, z, g, gclass) = match &e.kind {
                ElementKind::Mass { m, gravity, .. } => {
                    (m, &zero, &zero, gravity, ArgClass::Gravity)
                }
                ElementKind::Osc {
                    m, k, z, gravity, ..
                } => (m, k, z, gravity, ArgClass::Gravity),
                ElementKind::MassG { m, gravity, .. } => {
                    (m, &zero, &zero, gravity, ArgClass::LegacyGravity)
                }
                _ => (&zero, &zero, &zero, &zero, ArgClass::None),
            };
            let fixed = matches!(e.kind, ElementKind::Ground { .. });
            singles.fixed[row] = fixed;
            if !fixed {
                self.check_constant(m, "mass M must be > 0", true, i);
            }
            let mut audio = false;
            audio |= self.bind(m, ArgClass::None, cols[0] + row, i);
            audio |= self.bind(k, ArgClass::Stiffness, cols[1] + row, i);
            audio |= self.bind(z, ArgClass::Damping, cols[2] + row, i);
            audio |= self.bind(g, gclass, cols[3] + row, i);
            if audio {
                audio_masses.push(row as u32);
            }
            let first = row as u32;
            let run = match &e.kind {
                ElementKind::Mass { pos, vel, .. } | ElementKind::Osc { pos, vel, .. } => {
                    let (x0, _) = self.expr(pos.z(), i);
                    let (v, _) = self.expr(vel.z(), i);
                    InitRun {
                        first,
                        count: 1,
                        x0,
                        rule: InitRule::Velocity {
                            v,
                            factor: velocity_factor,
                        },
                    }
                }
                ElementKind::MassG { pos, delayed, .. } => {
                    let (x0, _) = self.expr(pos.z(), i);
                    let (xr0, _) = self.expr(delayed.z(), i);
                    let factor = match mode {
                        SampleRateMode::Scaled => REFERENCE_SAMPLE_RATE_HZ / sr,
                        SampleRateMode::Raw => 1.0,
                    };
                    InitRun {
                        first,
                        count: 1,
                        x0,
                        rule: InitRule::Delayed { xr0, factor },
                    }
                }
                ElementKind::Ground { pos } => {
                    let (x0, _) = self.expr(pos.z(), i);
                    InitRun {
                        first,
                        count: 1,
                        x0,
                        rule: InitRule::Fixed,
                    }
                }
                _ => continue,
            };
            init_runs.push(run);
        }

        // Macros.
        let mut macros = Macros::default();
        let mut init_fixed_points = Vec::new();
        let mut largest_macro = 0;
        let mut num_interactions = 0;
        for (i, e) in spec.elements.iter().enumerate() {
            let ElementKind::Macro(mac) = &e.kind else {
                continue;
            };
            let Some(base) = self.element_point[i] else {
                continue;
            };
            self.check_constant(&mac.m, "mass M must be > 0", true, i);
            let (m, _) = self.slot(&mac.m, ArgClass::None, i);
            let (k, _) = self.slot(&mac.k, ArgClass::Stiffness, i);
            let (k2, _) = self.slot(mac.k2.as_ref().unwrap_or(&zero), ArgClass::Stiffness, i);
            let (z, _) = self.slot(&mac.z, ArgClass::Damping, i);
            let (zo, _) = self.slot(&mac.zo, ArgClass::Damping, i);
            let slots = MacroSlots { m, k, k2, z, zo };
            let n = mac.num_nodes();
            largest_macro = largest_macro.max(n);
            num_interactions += mac.num_links();
            let base_us = base as usize;
            let fixed_local: Vec<u32> = fixed_nodes(mac);
            for &p in &fixed_local {
                init_fixed_points.push(base + p);
                points[base_us + p as usize].kind = PointKind::MacroNode { fixed: true };
            }
            let (x0, _) = self.expr(mac.pos.z(), i);
            let (v, _) = self.expr(mac.vel.z(), i);
            init_runs.push(InitRun {
                first: base,
                count: n as u32,
                x0,
                rule: InitRule::Velocity {
                    v,
                    factor: velocity_factor,
                },
            });
            match mac.kind {
                MacroKind::String | MacroKind::Chain => macros.lines.push(LineMacro {
                    base: base_us,
                    len: n,
                    fixed_ends: mac.kind == MacroKind::String,
                    slots,
                }),
                MacroKind::StiffString => macros.stiff.push(LineMacro {
                    base: base_us,
                    len: n,
                    fixed_ends: true,
                    slots,
                }),
                MacroKind::Mesh | MacroKind::CornerMesh | MacroKind::ClosedMesh => {
                    macros.meshes.push(MeshMacro {
                        base: base_us,
                        length: mac.length as usize,
                        width: mac.width as usize,
                        pinned: fixed_local,
                        slots,
                    })
                }
            }
        }
        macros.scratch_v = vec![0.0; largest_macro];
        macros.scratch_s = vec![0.0; largest_macro];

        // Avatars.
        let mut avatars = Vec::new();
        let mut inputs: Vec<Vec<InputUse>> = Vec::new();
        let use_input = |inputs: &mut Vec<Vec<InputUse>>, channel: u32, u: InputUse| {
            let c = channel as usize;
            if inputs.len() < c {
                inputs.resize(c, Vec::new());
            }
            inputs[c - 1].push(u);
        };
        for (i, e) in spec.elements.iter().enumerate() {
            let ElementKind::PosInput { channel, pos } = &e.kind else {
                continue;
            };
            let Some(point) = self.element_point[i] else {
                continue;
            };
            if *channel == 0 {
                self.error(Some(i), CompileErrorKind::InvalidChannel);
                continue;
            }
            avatars.push(Route {
                channel: channel - 1,
                index: point,
            });
            use_input(&mut inputs, *channel, InputUse::Position(e.label.clone()));
            let (x0, _) = self.expr(pos.z(), i);
            init_runs.push(InitRun {
                first: point,
                count: 1,
                x0,
                rule: InitRule::Fixed,
            });
        }
        for r in &audio_params {
            let name = spec.params[r.index as usize].name.clone();
            use_input(&mut inputs, r.channel + 1, InputUse::Param(name));
        }

        // Interactions, in script order; connection points are created as endpoints appear.
        let proxy_base = num_points;
        let mut groups: [Vec<Row<'a>>; 8] = Default::default();
        for (i, e) in spec.elements.iter().enumerate() {
            let ElementKind::Interaction { law, a, b } = &e.kind else {
                continue;
            };
            num_interactions += 1;
            let pa = self.endpoint(a, i, proxy_base);
            let pb = self.endpoint(b, i, proxy_base);
            let (group, args) = law_row(law);
            if let (Some(a), Some(b)) = (pa, pb) {
                groups[group].push(Row {
                    a,
                    b,
                    args,
                    element: i,
                });
            }
        }
        // Then inputs and outputs, in script order.
        let mut force_inputs = Vec::new();
        let mut pos_outputs = Vec::new();
        let mut frc_outputs = Vec::new();
        let mut frc_sources = Vec::new();
        let mut outputs: Vec<OutputUse> = Vec::new();
        for (i, e) in spec.elements.iter().enumerate() {
            let (channel, target, is_input, is_force) = match &e.kind {
                ElementKind::FrcInput { channel, target } => (*channel, target, true, true),
                ElementKind::PosOutput { channel, target } => (*channel, target, false, false),
                ElementKind::FrcOutput { channel, target } => (*channel, target, false, true),
                _ => continue,
            };
            let point = self.endpoint(target, i, proxy_base);
            if channel == 0 {
                self.error(Some(i), CompileErrorKind::InvalidChannel);
                continue;
            }
            let Some(point) = point else { continue };
            let route = Route {
                channel: channel - 1,
                index: point,
            };
            let text = describe_endpoint(target);
            if is_input {
                force_inputs.push(route);
                use_input(&mut inputs, channel, InputUse::Force(text));
            } else {
                let c = channel as usize;
                if outputs.len() < c {
                    outputs.resize(c, OutputUse::Unused);
                }
                if is_force {
                    // Each bracket creates its own connection point (spec §2.8), so a force
                    // output on a bracket reads the force applied at that location: the sum
                    // over every connection point with the same macro and coordinates, its own
                    // included (spec §3.12 e).
                    let start = frc_sources.len() as u32;
                    match target {
                        Endpoint::Label(_) => frc_sources.push(point),
                        _ => frc_sources.extend(
                            self.proxy_endpoints
                                .iter()
                                .enumerate()
                                .filter(|(_, ep)| **ep == target)
                                .map(|(i, _)| (proxy_base + i) as u32),
                        ),
                    }
                    let len = frc_sources.len() as u32 - start;
                    frc_outputs.push((route.channel, start, len));
                    outputs[c - 1] = OutputUse::Force(text);
                } else {
                    pos_outputs.push(route);
                    outputs[c - 1] = OutputUse::Position(text);
                }
            }
        }
        let mut interactions = Interactions::default();
        {
            let targets: [&mut Group; 8] = [
                &mut interactions.linear,
                &mut interactions.contact,
                &mut interactions.nl_contact,
                &mut interactions.nl_spring2,
                &mut interactions.nl_spring3,
                &mut interactions.nl_spring_damper,
                &mut interactions.pluck,
                &mut interactions.bow,
            ];
            for ((rows, group), ncols) in groups.iter().zip(targets).zip(LAW_COLUMNS) {
                let n = rows.len();
                group.cols = (0..ncols).map(|c| self.cx.args.len() + c * n).collect();
                let new_len = self.cx.args.len() + ncols * n;
                self.cx.args.resize(new_len, 0.0);
                for (r, row) in rows.iter().enumerate() {
                    group.a.push(row.a);
                    group.b.push(row.b);
                    for (c, (expr, class)) in row.args.iter().enumerate() {
                        let slot = group.cols[c] + r;
                        self.cx.bind(expr, *class, slot, row.element);
                    }
                }
            }
        }

        // Motion layout: rendering coordinates and named buffers.
        let defaults: HashMap<&str, f64> = spec
            .params
            .iter()
            .zip(&params)
            .map(|(p, v)| (p.name.as_str(), *v))
            .collect();
        let lookup = |n: &str| defaults.get(n).copied();
        let mut motion = MotionLayout {
            x: vec![0.0; num_points],
            y: vec![0.0; num_points],
            named: spec
                .buffers
                .iter()
                .map(|name| NamedBuffer {
                    name: name.clone(),
                    members: Vec::new(),
                })
                .collect(),
        };
        for (owner, &i) in owner_element.iter().enumerate() {
            let e = &spec.elements[i];
            let first = self.element_point[i].unwrap_or(0) as usize;
            let count = points[first..]
                .iter()
                .take_while(|p| p.owner == owner as u32)
                .count();
            layout_points(e, first, count, &lookup, &mut motion);
            for &b in &e.buffers {
                if let Some(buf) = motion.named.get_mut(b as usize) {
                    buf.members.extend(first as u32..(first + count) as u32);
                }
            }
        }

        if !self.cx.errors.is_empty() {
            return Err(CompileErrors(self.cx.errors));
        }

        let num_proxies = self.proxies.len();
        let total = num_points + num_proxies;
        let mut proxies = std::mem::take(&mut self.cx.proxies);
        proxies.base = proxy_base;
        let class_scale = class_scales(mode, sr);
        let cx = self.cx;
        let stack = cx.program.new_stack();
        let info = ModelInfo {
            sample_rate_hz: sr,
            sample_rate_mode: mode,
            num_points,
            num_connection_points: num_proxies,
            num_interactions,
            points,
            owners,
            params: param_info
                .into_iter()
                .zip(&cx.param_is_coordinate)
                .map(|(p, &coordinate)| ParamInfo { coordinate, ..p })
                .collect(),
            inputs,
            outputs,
            motion,
        };
        // Parameters start at their declared values: an audio-rate one at its default.
        let audio_defaults = audio_params
            .iter()
            .map(|r| params[r.index as usize])
            .collect();
        let mut engine = Engine {
            info,
            points: Points {
                x: vec![0.0; total],
                xp: vec![0.0; total],
                f: vec![0.0; total],
            },
            args: cx.args,
            singles,
            macros,
            proxies,
            interactions,
            avatars,
            audio_params,
            audio_defaults,
            force_inputs,
            pos_outputs,
            frc_outputs,
            frc_sources,
            program: cx.program,
            stack,
            params,
            control_bindings: cx.control_bindings,
            audio_bindings: cx.audio_bindings,
            audio_masses,
            audio_proxies: cx.proxy_audio,
            class_scale,
            class_gain: [1.0; NUM_ARG_CLASSES],
            params_dirty: true,
            init_runs,
            init_fixed_points,
            position_limit: DEFAULT_POSITION_LIMIT,
            guard: None,
            samples_since_reset: 0,
            motion: None,
            motion_interval: options.motion_interval.max(1),
            motion_counter: 0,
        };
        engine.reset();
        Ok(engine)
    }

    /// Checks a macro's sizes (≥ 2; 1-D macros have width 1).
    fn check_macro_sizes(&mut self, m: &MacroSpec, element: usize) -> bool {
        let mut ok = true;
        if m.length < 2 {
            self.error(Some(element), CompileErrorKind::InvalidSize(m.length));
            ok = false;
        }
        if m.kind.is_2d() && m.width < 2 {
            self.error(Some(element), CompileErrorKind::InvalidSize(m.width));
            ok = false;
        }
        if ok && m.num_nodes() > MAX_POINTS {
            self.error(
                Some(element),
                CompileErrorKind::TooLarge {
                    points: m.num_nodes(),
                },
            );
            ok = false;
        }
        ok
    }
}

/// The scale factor of every argument class at `sr` (spec §1.7).
fn class_scales(mode: SampleRateMode, sr: f64) -> [f64; NUM_ARG_CLASSES] {
    let k = ScaleClass::Stiffness.factor(mode, sr);
    let z = ScaleClass::Damping.factor(mode, sr);
    let mut s = [1.0; NUM_ARG_CLASSES];
    s[ArgClass::None as usize] = 1.0;
    s[ArgClass::Stiffness as usize] = k;
    s[ArgClass::Damping as usize] = z;
    s[ArgClass::Gravity as usize] = ScaleClass::Gravity.factor(mode, sr);
    s[ArgClass::LegacyGravity as usize] = k;
    s[ArgClass::VelocityScale as usize] = z;
    s
}

/// The local indices of a macro's fixed nodes (spec §2.7).
fn fixed_nodes(mac: &MacroSpec) -> Vec<u32> {
    let (l, w) = (mac.length, mac.width);
    match mac.kind {
        MacroKind::String | MacroKind::StiffString => vec![0, l - 1],
        MacroKind::Chain | MacroKind::Mesh => Vec::new(),
        MacroKind::CornerMesh => {
            let mut v = vec![0, w - 1, (l - 1) * w, (l - 1) * w + w - 1];
            v.dedup();
            v
        }
        MacroKind::ClosedMesh => (0..l * w)
            .filter(|n| {
                let (i, j) = (n / w, n % w);
                i == 0 || i == l - 1 || j == 0 || j == w - 1
            })
            .collect(),
    }
}

/// The interaction group index and argument list of a law.
fn law_row(law: &Law) -> (usize, Vec<(&Expr, ArgClass)>) {
    use ArgClass::{Damping as Z, None as N, Stiffness as K, VelocityScale as V};
    static ZERO: Expr = Expr::Num(0.0);
    let zero = &ZERO;
    match law {
        Law::Spring { k } => (0, vec![(k, K), (zero, Z)]),
        Law::Damper { z } => (0, vec![(zero, K), (z, Z)]),
        Law::SpringDamper { k, z } => (0, vec![(k, K), (z, Z)]),
        Law::Contact { k, z, thresh } => (1, vec![(k, K), (z, Z), (thresh, N)]),
        Law::NlContact {
            k,
            q,
            klim,
            z,
            thresh,
        } => (2, vec![(k, K), (q, K), (klim, K), (z, Z), (thresh, N)]),
        Law::NlSpring2 { k, q, z } => (3, vec![(k, K), (q, K), (z, Z)]),
        Law::NlSpring3 { k, q, z } => (4, vec![(k, K), (q, K), (z, Z)]),
        Law::NlSpringDamper { k, q, klim, z } => (5, vec![(k, K), (q, K), (klim, K), (z, Z)]),
        Law::NlPluck { k, scale, z } => (6, vec![(k, K), (scale, N), (z, Z)]),
        Law::NlBow { z, scale, smooth } => (7, vec![(z, Z), (scale, V), (smooth, N)]),
    }
}

/// The number of argument columns of each interaction group, in `law_row` order.
const LAW_COLUMNS: [usize; 8] = [2, 3, 5, 3, 3, 4, 3, 3];

/// Rendering coordinates of an element's points (spec §2.7 "Rendering coordinates", §6.3).
fn layout_points(
    e: &crate::spec::Element,
    first: usize,
    count: usize,
    lookup: &impl Fn(&str) -> Option<f64>,
    motion: &mut MotionLayout,
) {
    let xy = |v: &Vector| -> (f64, f64) {
        match v.xy() {
            Some((x, y)) => (x.eval(lookup), y.eval(lookup)),
            None => (0.0, 0.0),
        }
    };
    let mut put = |k: usize, (x, y): (f64, f64)| {
        motion.x[first + k] = if x.is_finite() { x } else { 0.0 };
        motion.y[first + k] = if y.is_finite() { y } else { 0.0 };
    };
    match &e.kind {
        ElementKind::Macro(mac) => {
            let (x0, y0) = xy(&mac.pos);
            let both = mac.pos.xy().is_some() && mac.vel.xy().is_some();
            let (x1, y1) = if both { xy(&mac.vel) } else { (x0, y0) };
            let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
            for k in 0..count {
                let p = if mac.kind.is_2d() {
                    let w = mac.width as usize;
                    let (i, j) = (k / w, k % w);
                    let ti = i as f64 / (mac.length as f64 - 1.0);
                    let tj = j as f64 / (mac.width as f64 - 1.0);
                    (lerp(x0, x1, ti), lerp(y0, y1, tj))
                } else {
                    let t = k as f64 / (count as f64 - 1.0).max(1.0);
                    (lerp(x0, x1, t), lerp(y0, y1, t))
                };
                put(k, p);
            }
        }
        ElementKind::Mass { pos, .. }
        | ElementKind::Osc { pos, .. }
        | ElementKind::Ground { pos }
        | ElementKind::MassG { pos, .. }
        | ElementKind::PosInput { pos, .. } => {
            put(0, e.tag_xy.unwrap_or_else(|| xy(pos)));
        }
        _ => {}
    }
}
