//! Pass 2 of a 3-D script: each command's keyword, argument count and arguments (3-D spec §2,
//! §3, §4.7), and the directives `~dim`, `~gravity` and `~friction` (§1.1, §1.10).

use super::super::lines::Item;
use super::super::{At, Builder};
use super::{arity, one_d_only, shape_of, Shape3};
use crate::lang::diagnostics::DiagnosticCode;
use crate::lang::lexer::{TokKind, Token};
use crate::lang::symbols::SymKind;
use crate::laws::space::{ColShape, SpaceLawKind};
use crate::spec::expr::Expr;
use crate::spec::space::{SpaceElement, SpaceKind};
use crate::spec::{Span, Vector};

impl Builder<'_> {
    /// A command line of a 3-D script.
    pub(in crate::lang::parser) fn space_command(&mut self, item: &Item) {
        let tokens = item.tokens(self.tokens);
        let Some(first) = tokens.first() else {
            return;
        };
        let label = first.label();
        if label.is_empty() {
            return; // reported in pass 1
        }
        let at = At {
            line: item.line,
            label: Some(label),
        };
        let span = Span::new(item.line, first.col);
        let Some(kw) = tokens.get(1) else {
            self.diags.push(
                at.diag(
                    DiagnosticCode::WrongArgumentCount,
                    first.col,
                    format!("`@{label}` has no type keyword"),
                )
                .with_expected("@label keyword arguments…"),
            );
            return;
        };
        let shape = (kw.kind == TokKind::Bare)
            .then(|| shape_of(kw.text))
            .flatten();
        let Some(shape) = shape else {
            self.unknown_3d_keyword(kw, at);
            return;
        };
        let args = tokens.get(2..).unwrap_or(&[]);
        let (min, max, signature) = match shape {
            Shape3::Structure(kind) => {
                let n = super::structure::required(kind);
                (n, n + 1, kind.signature())
            }
            _ => arity(shape),
        };
        if args.len() < min || args.len() > max {
            let expected = if min == max {
                format!(
                    "{min} argument{}: {signature}",
                    if min == 1 { "" } else { "s" }
                )
            } else {
                format!("{min} to {max} arguments: {signature}")
            };
            let (col, message) = if args.len() > max {
                let mut m = format!("too many arguments for `{}` (expected {expected})", kw.text);
                if matches!(
                    shape,
                    Shape3::Law(SpaceLawKind::Spring | SpaceLawKind::Damper)
                ) {
                    m.push_str("; a 3-D `springDamper` is written `springDamper m1 m2 K Z L`");
                }
                (args.get(max).map_or(kw.col, |t| t.col), m)
            } else {
                let mut m = format!("too few arguments for `{}` (expected {expected})", kw.text);
                if let Shape3::Law(k) = shape {
                    if k.row().columns.iter().any(|c| c.shape == ColShape::Length) {
                        m.push_str(
                            "; in 3-D an elastic link takes its rest length (or contact \
                             distance) too, `auto` for the distance at rest",
                        );
                    }
                }
                (kw.col, m)
            };
            self.diags.push(
                at.diag(DiagnosticCode::WrongArgumentCount, col, message)
                    .with_expected(expected)
                    .with_found(args.len().to_string()),
            );
            return;
        }
        let kind = match shape {
            Shape3::Param | Shape3::AudioParam => {
                self.space_param(shape, label, first, args, at, span);
                return;
            }
            _ => self.space_element(shape, label, first, args, at),
        };
        let Some(kind) = kind else {
            return;
        };
        let buffers = self.open.clone();
        if let Some(state) = &mut self.space {
            state.spec.elements.push(SpaceElement {
                label: crate::spec::label(label),
                kind,
                buffers,
                span,
            });
        }
    }

    /// A parameter of a 3-D script: as in 1-D, but `auto` is reserved (3-D spec §1.7).
    fn space_param(
        &mut self,
        shape: Shape3,
        label: &str,
        first: &Token,
        args: &[Token],
        at: At<'_>,
        span: Span,
    ) {
        if label == "auto" {
            self.diags.push(
                at.diag(
                    DiagnosticCode::BadLabel,
                    first.col,
                    "`auto` is a reserved word in a 3-D script (the distance at rest): choose \
                     another parameter name",
                )
                .with_found("@auto"),
            );
            return;
        }
        let one_d = match shape {
            Shape3::Param => super::super::keywords::Shape::Param,
            _ => super::super::keywords::Shape::AudioParam,
        };
        if let Some(p) = self.param(one_d, label, first, args, at, span) {
            self.spec.params.push(p);
        }
    }

    /// Reports a keyword that is not a 3-D one, with what to write when it is 1-D.
    fn unknown_3d_keyword(&mut self, kw: &Token, at: At<'_>) {
        if let Some(hint) = one_d_only(kw.text) {
            self.diags.push(
                at.diag(
                    DiagnosticCode::DimensionMismatch,
                    kw.col,
                    format!(
                        "`{}` is a 1-D element, not available in a `~dim 3` script: {hint}",
                        kw.text
                    ),
                )
                .with_found(kw.source()),
            );
            return;
        }
        let mut d = at.diag(
            DiagnosticCode::UnknownKeyword,
            kw.col,
            format!("unknown 3-D type keyword `{}`", kw.source()),
        );
        if let Some((k, _)) = super::keywords().find(|(k, _)| k.eq_ignore_ascii_case(kw.text)) {
            d.message.push_str(&format!(" (did you mean `{k}`?)"));
            d = d.with_expected(format!("`{k}`"));
        }
        self.diags.push(d.with_found(kw.source()));
    }

    /// The element of a 3-D command with an accepted argument count.
    fn space_element(
        &mut self,
        shape: Shape3,
        label: &str,
        first: &Token,
        args: &[Token],
        at: At<'_>,
    ) -> Option<SpaceKind> {
        let n = args.len();
        let zero_gravity = || Vector::Scalar(Expr::Num(0.0));
        match shape {
            Shape3::Mass(body) => {
                let m = self.expr(&args[0], at);
                let gravity = if n == 4 {
                    self.vector(&args[1], at)
                } else {
                    Some(zero_gravity())
                };
                let pos = self.vector(&args[n - 2], at);
                let vel = self.vector(&args[n - 1], at);
                Some(SpaceKind::Mass {
                    body,
                    m: m?,
                    gravity: gravity?,
                    pos: pos?,
                    vel: vel?,
                })
            }
            Shape3::Osc => {
                let m = self.expr(&args[0], at);
                let k = self.expr(&args[1], at);
                let z = self.expr(&args[2], at);
                let gravity = if n == 6 {
                    self.vector(&args[3], at)
                } else {
                    Some(zero_gravity())
                };
                let pos = self.vector(&args[n - 2], at);
                let vel = self.vector(&args[n - 1], at);
                Some(SpaceKind::Osc {
                    m: m?,
                    k: k?,
                    z: z?,
                    gravity: gravity?,
                    pos: pos?,
                    vel: vel?,
                })
            }
            Shape3::Ground => Some(SpaceKind::Ground {
                pos: self.vector(&args[0], at)?,
            }),
            Shape3::Law(plain) => self.space_law(plain, args, at),
            Shape3::Structure(kind) => self
                .structure(kind, label, args, at)
                .map(|s| SpaceKind::Structure(Box::new(s))),
            Shape3::ContactSet => {
                let a = self.endpoint(&args[0], at);
                let set = self.structure_ref(&args[1], at);
                let row = SpaceLawKind::Contact.row();
                let mut values = self.law_columns(row.columns, &args[2..], at)?;
                values.resize(row.slots(), Expr::Num(0.0));
                Some(SpaceKind::ContactSet {
                    a: a?,
                    set: set?,
                    args: values,
                })
            }
            Shape3::Vdampers => {
                let set = self.structure_ref(&args[0], at);
                let z = self.expr(&args[1], at);
                Some(SpaceKind::Vdampers { set: set?, z: z? })
            }
            Shape3::PosInput => {
                let channel = self.channel(label, "in", first, at);
                let pos = self.vector(&args[0], at);
                let dir = self.optional_direction(args.get(1), at);
                Some(SpaceKind::PosInput {
                    channel: channel?,
                    pos: pos?,
                    dir: dir?,
                })
            }
            Shape3::PosInputXyz => {
                let channel = self.channel(label, "in", first, at)?;
                self.take_xyz_inputs(channel, label, at);
                Some(SpaceKind::PosInputXyz {
                    channel,
                    pos: self.vector(&args[0], at)?,
                })
            }
            Shape3::FrcInput => {
                let channel = self.channel(label, "in", first, at);
                let target = self.endpoint(&args[0], at);
                let dir = self.optional_direction(args.get(1), at);
                Some(SpaceKind::FrcInput {
                    channel: channel?,
                    target: target?,
                    dir: dir?,
                })
            }
            Shape3::FrcInputXyz => {
                let channel = self.channel(label, "in", first, at)?;
                self.take_xyz_inputs(channel, label, at);
                Some(SpaceKind::FrcInputXyz {
                    channel,
                    target: self.endpoint(&args[0], at)?,
                })
            }
            Shape3::Output(probe) => {
                let channel = self.channel(label, "out", first, at);
                let target = self.endpoint(&args[0], at);
                let dir = self.optional_direction(args.get(1), at);
                Some(SpaceKind::Output {
                    channel: channel?,
                    probe,
                    target: target?,
                    dir: dir?,
                })
            }
            Shape3::DistOutput => {
                let channel = self.channel(label, "out", first, at);
                let a = self.endpoint(&args[0], at);
                let b = self.endpoint(&args[1], at);
                Some(SpaceKind::DistOutput {
                    channel: channel?,
                    a: a?,
                    b: b?,
                })
            }
            Shape3::Mic => {
                let channel = self.channel(label, "out", first, at);
                let set = self.mic_set(&args[0], at);
                let p = self.vector(&args[1], at);
                let dir = if args[2].kind == TokKind::Bare && args[2].text == "radial" {
                    Some(None)
                } else {
                    self.direction(&args[2], at).map(Some)
                };
                let q = self.expr(&args[3], at);
                let r0 = self.expr(&args[4], at);
                Some(SpaceKind::Mic {
                    channel: channel?,
                    set: set?,
                    at: p?,
                    dir: dir?,
                    q: q?,
                    r0: r0?,
                })
            }
            Shape3::Param | Shape3::AudioParam => None,
        }
    }

    /// An interaction of the 3-D table: the row the count selects (a directional form when
    /// its direction is written), its endpoints and its columns.
    fn space_law(&mut self, plain: SpaceLawKind, args: &[Token], at: At<'_>) -> Option<SpaceKind> {
        let ends = plain.row().endpoints;
        let given = args.len() - ends;
        let kind = SpaceLawKind::with_keyword(plain.row().keyword)
            .find(|k| (k.row().required..=k.row().columns.len()).contains(&given))
            .unwrap_or(plain);
        let row = kind.row();
        let a = self.endpoint(&args[0], at);
        let b = if ends == 2 {
            self.endpoint(&args[1], at).map(Some)
        } else {
            Some(None)
        };
        let mut values = self.law_columns(row.columns, &args[ends..], at);
        if let Some(v) = &mut values {
            v.resize(row.slots(), Expr::Num(0.0));
        }
        Some(SpaceKind::Interaction {
            law: kind,
            args: values?,
            a: a?,
            b: b?,
        })
    }

    /// The columns written in `args`, slot by slot (a direction three), each by its shape.
    fn law_columns(
        &mut self,
        columns: &[crate::laws::space::SpaceColumn],
        args: &[Token],
        at: At<'_>,
    ) -> Option<Vec<Expr>> {
        let mut out = Vec::new();
        let mut ok = true;
        for (c, t) in columns.iter().zip(args) {
            match c.shape {
                ColShape::Scalar => match self.expr(t, at) {
                    Some(e) => out.push(e),
                    None => ok = false,
                },
                ColShape::Length => match self.with_auto(true, |b| b.expr(t, at)) {
                    Some(e) => out.push(e),
                    None => ok = false,
                },
                ColShape::Direction => match self.direction(t, at) {
                    Some(v) => out.extend(components(v)),
                    None => ok = false,
                },
            }
        }
        ok.then_some(out)
    }

    /// A direction (3-D spec §1.7): a vector, a constant zero one refused.
    fn direction(&mut self, t: &Token, at: At<'_>) -> Option<Vector> {
        let v = self.vector(t, at)?;
        let zero = match &v {
            Vector::Scalar(s) => s.as_number() == Some(0.0),
            Vector::Xyz(c) => c.iter().all(|e| e.as_number() == Some(0.0)),
        };
        if zero {
            self.diags.push(
                at.diag(
                    DiagnosticCode::ZeroDirection,
                    t.col,
                    "a direction cannot be the zero vector",
                )
                .with_expected("a non-zero vector such as `[0 0 1]`")
                .with_found(t.source()),
            );
            return None;
        }
        Some(v)
    }

    /// An optional trailing direction.
    fn optional_direction(&mut self, t: Option<&Token>, at: At<'_>) -> Option<Option<Vector>> {
        match t {
            Some(t) => self.direction(t, at).map(Some),
            None => Some(None),
        }
    }

    /// `@struct` naming a structure (adders, §4.7).
    fn structure_ref(&mut self, t: &Token, at: At<'_>) -> Option<crate::spec::Label> {
        let name = t.label();
        let ok = t.kind == TokKind::Bare && t.starts_with_at();
        let is_structure = self
            .symbols
            .generator(name)
            .is_some_and(|g| g.structure.is_some());
        if ok && is_structure {
            return Some(crate::spec::label(name));
        }
        let unknown = matches!(
            self.symbols.get(name).map(|s| s.kind),
            Some(SymKind::Unknown)
        );
        if !unknown {
            self.diags.push(
                at.diag(
                    DiagnosticCode::NotAMacro,
                    t.col,
                    format!("`{}` is not a structure (string3, mesh3, lattice3, ring3, icosphere, objMesh)", t.source()),
                )
                .with_expected("@struct")
                .with_found(t.source()),
            );
        }
        None
    }

    /// A microphone's set: `@struct` or the name of a buffer scope (3-D spec §3.4).
    fn mic_set(&mut self, t: &Token, at: At<'_>) -> Option<crate::spec::Label> {
        if t.kind == TokKind::Bare && t.starts_with_at() {
            return self.structure_ref(t, at);
        }
        if t.kind == TokKind::Bare && crate::lang::expr_parser::is_identifier(t.text) {
            // A buffer scope: checked once the script is read, since it may open later.
            return Some(crate::spec::label(t.text));
        }
        self.diags.push(
            at.diag(
                DiagnosticCode::ExpectedEndpoint,
                t.col,
                format!(
                    "a microphone listens to `@struct` or a buffer scope's name, found `{}`",
                    t.source()
                ),
            )
            .with_found(t.source()),
        );
        None
    }

    /// Records the channels N+1 and N+2 that an XYZ element takes (3-D spec §3.1, §3.2).
    fn take_xyz_inputs(&mut self, channel: u32, label: &str, at: At<'_>) {
        if let Some(state) = &mut self.space {
            for c in [channel + 1, channel + 2] {
                state.taken_inputs.push((c, at.line, label.to_string()));
            }
        }
    }

    /// `~generate` in a 3-D script: it writes 1-D elements.
    pub(in crate::lang::parser) fn generate_in_3d(&mut self, item: &Item) {
        let col = item.tokens(self.tokens).first().map_or(1, |t| t.col);
        self.diags.push(crate::lang::diagnostics::Diagnostic::new(
            DiagnosticCode::DimensionMismatch,
            item.line,
            col,
            "`~generate` writes 1-D elements: a `~dim 3` script uses the 3-D structures \
                 (string3, mesh3, lattice3, ring3, icosphere, objMesh)",
        ));
    }

    /// `~dim 1|3`, `~gravity g`, `~friction Za` (3-D spec §1.1, §1.10).
    pub(in crate::lang::parser) fn space_directive(
        &mut self,
        name: &str,
        first: &Token,
        args: &[Token],
        at: At<'_>,
    ) {
        let Some(arg) = args.first() else {
            self.diags.push(
                at.diag(
                    DiagnosticCode::InvalidDirectiveArgument,
                    first.col,
                    format!("`~{name}` needs one argument"),
                )
                .with_expected(match name {
                    "dim" => "`1` or `3`",
                    "gravity" => {
                        "an acceleration: a vector `[gx gy gz]` or a scalar g for (0, 0, −g)"
                    }
                    _ => "an air friction Za",
                }),
            );
            return;
        };
        if let Some(extra) = args.get(1) {
            self.diags.push(
                at.diag(
                    DiagnosticCode::InvalidDirectiveArgument,
                    extra.col,
                    format!("`~{name}` takes exactly one argument"),
                )
                .with_found(extra.source()),
            );
            return;
        }
        let line = at.line;
        if name == "dim" {
            let value = arg.text;
            let ok = arg.kind == TokKind::Bare && (value == "1" || value == "3");
            if !ok {
                let why = if value == "2" {
                    "`~dim 2` is reserved: a planar model is a 3-D one with `massXY` points \
                    "
                    .to_string()
                } else {
                    format!("unknown dimension `{}`", arg.source())
                };
                self.diags.push(
                    at.diag(DiagnosticCode::InvalidDirectiveArgument, arg.col, why)
                        .with_expected("`1` or `3`")
                        .with_found(arg.source()),
                );
                return;
            }
            let three = value == "3";
            match &mut self.space {
                Some(_) if !three => self.diags.push(
                    at.diag(
                        DiagnosticCode::ConflictingDirective,
                        arg.col,
                        "`~dim 1` conflicts with the script's `~dim 3`",
                    )
                    .with_found("1"),
                ),
                Some(state) => match state.dim_line {
                    Some(_) => {}
                    None => state.dim_line = Some(line),
                },
                None => {}
            }
            return;
        }
        let Some(state) = &self.space else {
            self.diags.push(
                at.diag(
                    DiagnosticCode::DimensionMismatch,
                    first.col,
                    format!("`~{name}` is a 3-D directive: add `~dim 3` to make the script three-dimensional"),
                )
                .with_found(format!("~{name}")),
            );
            return;
        };
        let before = if name == "gravity" {
            state.gravity_line
        } else {
            state.friction_line
        };
        if let Some(prev) = before {
            self.diags.push(at.diag(
                DiagnosticCode::ConflictingDirective,
                first.col,
                format!("a second `~{name}`: the first is at line {prev}"),
            ));
            return;
        }
        if name == "gravity" {
            let Some(v) = self.vector(arg, at) else {
                return;
            };
            if let Some(state) = &mut self.space {
                state.gravity_line = Some(line);
                state.spec.gravity = Some(v);
            }
        } else {
            let Some(e) = self.expr(arg, at) else {
                return;
            };
            if let Some(state) = &mut self.space {
                state.friction_line = Some(line);
                state.spec.friction = Some(e);
            }
        }
    }
}

/// The three slots of a direction: a scalar s is (0, 0, s) (3-D spec §1.7).
pub(super) fn components(v: Vector) -> [Expr; 3] {
    match v {
        Vector::Scalar(s) => [Expr::Num(0.0), Expr::Num(0.0), s],
        Vector::Xyz(c) => *c,
    }
}
