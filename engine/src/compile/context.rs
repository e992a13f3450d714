//! The compiler's shared state ([`Cx`]) and what every pass uses: error reporting, expression
//! checks and compilation, argument binding, and the resolution of an endpoint to a point.

use super::errors::{CompileError, CompileErrorKind};
use super::MAX_EXPR_DEPTH;
use crate::laws::ArgClass;
use crate::sim::engine::{Binding, Proxies};
use crate::spec::expr::{Expr, ExprRef, Program};
use crate::spec::label_map::{LabelKey, LabelMap};
use crate::spec::{ElementKind, Endpoint, ModelSpec, Span};

/// What a label resolves to: a parameter, or an element with what it is.
#[derive(Clone, Copy, Debug)]
pub(super) enum Symbol {
    Param(u32),
    Element(usize, Role),
}

/// What an element is, as an endpoint or target sees it: found once, when its label is
/// declared, so that resolving an endpoint does not read the element again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Role {
    /// A single mass or an avatar: it has one point.
    Point,
    Macro,
    Interaction,
    ForceInput,
    Output,
}

impl Role {
    pub fn of(kind: &ElementKind) -> Role {
        match kind {
            ElementKind::Macro(_) => Role::Macro,
            ElementKind::Interaction { .. } => Role::Interaction,
            ElementKind::FrcInput { .. } => Role::ForceInput,
            ElementKind::PosOutput { .. } | ElementKind::FrcOutput { .. } => Role::Output,
            _ => Role::Point,
        }
    }

    /// The role in an error message.
    fn describe(self) -> &'static str {
        match self {
            Role::Point => "a point",
            Role::Macro => "a macro",
            Role::Interaction => "an interaction",
            Role::ForceInput => "a force input",
            Role::Output => "an output",
        }
    }
}

/// Compile-time state, shared by the passes: the symbol table, the errors, and the argument
/// slots and expression program that binding fills.
pub(super) struct Cx<'a> {
    pub spec: &'a ModelSpec,
    pub symbols: LabelMap<LabelKey<'a>, Symbol>,
    pub errors: Vec<CompileError>,
    pub program: Program,
    pub args: Vec<f64>,
    pub control_bindings: Vec<Binding>,
    pub audio_bindings: Vec<Binding>,
    /// Parameter id → audio-rate.
    pub param_is_audio: Vec<bool>,
    /// Parameter id → named in a connection-point coordinate.
    pub param_is_coordinate: Vec<bool>,
    /// Element index → first point (single masses, avatars) or first node (macros).
    pub element_point: Vec<Option<u32>>,
    pub proxies: Proxies,
    /// Connection points whose coordinates depend on an audio-rate parameter.
    pub proxy_audio: Vec<u32>,
    /// The endpoint that created each connection point, to find points at the same location.
    pub proxy_endpoints: Vec<&'a Endpoint>,
    /// Each connection point's element and coordinates (α and 0, or u and w), bound to
    /// argument slots by the binding pass.
    pub proxy_coords: Vec<(usize, [&'a Expr; 2])>,
}

impl<'a> Cx<'a> {
    pub fn new(spec: &'a ModelSpec) -> Cx<'a> {
        // About four arguments an element (a mass binds four and has two initial values, a
        // link binds two), each most often a one-instruction program: room for a script
        // written element by element, so that binding does not grow these arrays step by step.
        let args = 4 * spec.elements.len();
        let mut program = Program::default();
        program.reserve(args);
        Cx {
            spec,
            symbols: LabelMap::with_capacity_and_hasher(
                spec.params.len() + spec.elements.len(),
                Default::default(),
            ),
            errors: Vec::new(),
            program,
            args: Vec::with_capacity(args),
            control_bindings: Vec::with_capacity(args),
            audio_bindings: Vec::new(),
            param_is_audio: Vec::new(),
            param_is_coordinate: Vec::new(),
            element_point: vec![None; spec.elements.len()],
            proxies: Proxies::default(),
            proxy_audio: Vec::new(),
            proxy_endpoints: Vec::new(),
            proxy_coords: Vec::new(),
        }
    }

    pub fn error(&mut self, element: Option<usize>, kind: CompileErrorKind) {
        let (label, span) = match (element, &self.spec.space) {
            // A 3-D model's elements are its space's.
            (Some(i), Some(space)) => space
                .elements
                .get(i)
                .map_or((String::new(), Span::default()), |e| {
                    (e.label.to_string(), e.span)
                }),
            (Some(i), None) => (
                self.spec.elements[i].label.to_string(),
                self.spec.elements[i].span,
            ),
            (None, _) => (String::new(), Span::default()),
        };
        self.errors.push(CompileError { kind, label, span });
    }

    /// Checks an expression's names and calls; returns true when it is usable.
    pub fn check_expr(&mut self, expr: &Expr, element: usize) -> bool {
        if expr.depth() > MAX_EXPR_DEPTH {
            self.error(Some(element), CompileErrorKind::ExpressionTooDeep);
            return false;
        }
        let mut ok = true;
        let mut names = Vec::new();
        expr.for_each_name(&mut |n| names.push(n.to_string()));
        for n in names {
            match self.symbols.get(&LabelKey(&n)) {
                Some(Symbol::Param(_)) => {}
                Some(Symbol::Element(..)) => {
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
    pub fn expr(&mut self, expr: &Expr, element: usize) -> (ExprRef, bool) {
        if let Expr::Num(v) = expr {
            // The commonest argument: nothing to check, resolve or mark audio-rate.
            return (self.program.push_const(*v), false);
        }
        let valid = self.check_expr(expr, element);
        let nan = Expr::Num(f64::NAN);
        let expr = if valid { expr } else { &nan };
        let symbols = &self.symbols;
        let resolve = |n: &str| match symbols.get(&LabelKey(n)) {
            Some(Symbol::Param(id)) => Some(*id),
            _ => None,
        };
        let r = self
            .program
            .push(expr, &resolve)
            .expect("names were checked");
        let mut audio = false;
        expr.for_each_name(&mut |n| {
            if let Some(Symbol::Param(id)) = self.symbols.get(&LabelKey(n)) {
                audio |= self.param_is_audio[*id as usize];
            }
        });
        (r, audio)
    }

    /// Binds `expr` (of `class`) to argument slot `slot`. Returns true when it is audio-rate.
    pub fn bind(&mut self, expr: &Expr, class: ArgClass, slot: usize, element: usize) -> bool {
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
    pub fn slot(&mut self, expr: &Expr, class: ArgClass, element: usize) -> (usize, bool) {
        let slot = self.args.len();
        self.args.push(0.0);
        let audio = self.bind(expr, class, slot, element);
        (slot, audio)
    }

    /// Checks that a constant argument is finite and, where `positive`, > 0.
    pub fn check_constant(
        &mut self,
        expr: &Expr,
        what: &'static str,
        positive: bool,
        element: usize,
    ) {
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
    /// bracket reference (its coordinates are bound later, by the binding pass). `proxy_base`
    /// is the index of the first connection point.
    pub fn endpoint(&mut self, ep: &'a Endpoint, element: usize, proxy_base: usize) -> Option<u32> {
        let target = ep.target();
        let Some(&symbol) = self.symbols.get(&LabelKey(target)) else {
            self.error(
                Some(element),
                CompileErrorKind::UndefinedElement(target.to_string()),
            );
            return None;
        };
        match (ep, symbol) {
            (Endpoint::Label(_), Symbol::Element(j, Role::Point)) => self.element_point[j],
            (Endpoint::Label(_), Symbol::Element(_, Role::Macro)) => {
                self.error(
                    Some(element),
                    CompileErrorKind::BareMacroReference(target.to_string()),
                );
                None
            }
            (Endpoint::Label(_), _) => {
                let found = match symbol {
                    Symbol::Param(_) => "a parameter",
                    Symbol::Element(_, role) => role.describe(),
                };
                self.error(
                    Some(element),
                    CompileErrorKind::NotAPoint {
                        target: target.to_string(),
                        found,
                    },
                );
                None
            }
            (
                Endpoint::Line { .. } | Endpoint::Surface { .. } | Endpoint::Volume { .. },
                Symbol::Element(j, Role::Macro),
            ) => {
                let ElementKind::Macro(mac) = &self.spec.elements[j].kind else {
                    return None;
                };
                let (coords, found_count): (Vec<&Expr>, usize) = match ep {
                    Endpoint::Line { alpha, .. } => (vec![alpha], 1),
                    Endpoint::Surface { u, w, .. } => (vec![u, w], 2),
                    // A lattice's bracket (3-D models only): the count is reported below.
                    Endpoint::Volume { coords, .. } => (coords.iter().collect(), 3),
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
                        if let Some(Symbol::Param(id)) = self.symbols.get(&LabelKey(n)) {
                            self.param_is_coordinate[*id as usize] = true;
                        }
                    });
                }
                static ZERO: Expr = Expr::Num(0.0);
                let index = self.proxies.len();
                let width = if mac.kind.is_2d() { mac.width } else { 0 };
                self.proxies.geometry.push((base, mac.length, width));
                self.proxies.nodes.push([base; 4]);
                self.proxies.weights.push([1.0, 0.0, 0.0, 0.0]);
                self.proxy_endpoints.push(ep);
                let second = coords.get(1).copied().unwrap_or(&ZERO);
                self.proxy_coords.push((element, [coords[0], second]));
                Some((proxy_base + index) as u32)
            }
            (Endpoint::Line { .. } | Endpoint::Surface { .. } | Endpoint::Volume { .. }, _) => {
                self.error(
                    Some(element),
                    CompileErrorKind::NotAMacro(target.to_string()),
                );
                None
            }
        }
    }
}
