//! Each element kind's arguments (spec §2.9): masses, interactions and their laws, macros,
//! inputs and outputs.

use super::keywords::Shape;
use super::{At, Builder, MAX_MACRO_NODES};
use crate::lang::diagnostics::DiagnosticCode;
use crate::lang::legacy;
use crate::lang::lexer::Token;
use crate::laws::LawKind;
use crate::spec::expr::Expr;
use crate::spec::LawForm;
use crate::spec::{ElementKind, Law, MacroKind, MacroSpec};

impl Builder<'_> {
    /// Builds an element from arguments of an accepted count. `points` are the legacy bare
    /// connection points found in the endpoint slots (see [`legacy::read`]). Inlined into
    /// `command`, which pushes the element: the kind (some 400 bytes) is then copied once less.
    #[inline(always)]
    pub(super) fn element(
        &mut self,
        shape: Shape,
        label: &str,
        first: &Token,
        args: &[Token],
        points: &[legacy::Point],
        at: At<'_>,
    ) -> Option<ElementKind> {
        let n = args.len();
        // Arguments are checked left to right, all of them, before anything is returned.
        match shape {
            Shape::Mass => {
                let m = self.expr(args.first()?, at);
                let gravity = if n == 4 {
                    self.expr(args.get(1)?, at)
                } else {
                    Some(Expr::Num(0.0))
                };
                let pos = self.vector(args.get(n - 2)?, at);
                let vel = self.vector(args.get(n - 1)?, at);
                Some(ElementKind::Mass {
                    m: m?,
                    gravity: gravity?,
                    pos: pos?,
                    vel: vel?,
                })
            }
            Shape::Osc => {
                let m = self.expr(args.first()?, at);
                let k = self.expr(args.get(1)?, at);
                let z = self.expr(args.get(2)?, at);
                let gravity = if n == 6 {
                    self.expr(args.get(3)?, at)
                } else {
                    Some(Expr::Num(0.0))
                };
                let pos = self.vector(args.get(n - 2)?, at);
                let vel = self.vector(args.get(n - 1)?, at);
                Some(ElementKind::Osc {
                    m: m?,
                    k: k?,
                    z: z?,
                    gravity: gravity?,
                    pos: pos?,
                    vel: vel?,
                })
            }
            Shape::Ground => {
                let pos = self.vector(args.first()?, at)?;
                Some(ElementKind::Ground { pos })
            }
            Shape::MassG => {
                let m = self.expr(args.first()?, at);
                let gravity = self.expr(args.get(1)?, at);
                let pos = self.vector(args.get(2)?, at);
                let delayed = self.vector(args.get(3)?, at);
                Some(ElementKind::MassG {
                    m: m?,
                    gravity: gravity?,
                    pos: pos?,
                    delayed: delayed?,
                })
            }
            Shape::Law(form) => {
                let a = self.slot_endpoint(args, 0, points, at);
                let b = self.slot_endpoint(args, 1, points, at);
                // Optional trailing arguments default to 0 (spec §2.9).
                let mut p: [Expr; LawKind::MAX_ARITY] = std::array::from_fn(|_| Expr::Num(0.0));
                let mut params_ok = true;
                for (slot, t) in p.iter_mut().zip(args.get(2..).unwrap_or(&[])) {
                    match self.expr(t, at) {
                        Some(e) => *slot = e,
                        None => params_ok = false,
                    }
                }
                let (a, b) = (a?, b?);
                if !params_ok {
                    return None;
                }
                let law = make_law(form, n - 2, p);
                Some(ElementKind::Interaction { law, a, b })
            }
            Shape::Macro(kind) => {
                let sizes = if kind.is_2d() { 2 } else { 1 };
                let length = self.size(args.first()?, at);
                let width = if kind.is_2d() {
                    self.size(args.get(1)?, at)
                } else {
                    Some(1)
                };
                let nparams = if kind == MacroKind::StiffString { 4 } else { 3 };
                let rest = args.get(sizes..)?;
                let exprs: Vec<Option<Expr>> = rest
                    .get(..rest.len().saturating_sub(2))
                    .unwrap_or(&[])
                    .iter()
                    .map(|t| self.expr(t, at))
                    .collect();
                let pos = self.vector(rest.get(rest.len().checked_sub(2)?)?, at);
                let vel = self.vector(rest.get(rest.len().checked_sub(1)?)?, at);
                let (length, width) = (length?, width?);
                if length.saturating_mul(width) > MAX_MACRO_NODES {
                    self.diags.push(
                        at.diag(
                            DiagnosticCode::TooLarge,
                            args.first()?.col,
                            format!(
                                "macro `@{label}` would have {} nodes, more than the limit of \
                                 {MAX_MACRO_NODES}",
                                length.saturating_mul(width)
                            ),
                        )
                        .with_expected(format!("at most {MAX_MACRO_NODES} nodes"))
                        .with_found(length.saturating_mul(width).to_string()),
                    );
                    return None;
                }
                let mut e = exprs
                    .into_iter()
                    .collect::<Option<Vec<Expr>>>()?
                    .into_iter();
                let (pos, vel) = (pos?, vel?);
                let m = e.next()?;
                let k = e.next()?;
                let k2 = if nparams == 4 { Some(e.next()?) } else { None };
                let z = e.next()?;
                let zo = e.next().unwrap_or(Expr::Num(0.0));
                Some(ElementKind::Macro(Box::new(MacroSpec {
                    kind,
                    length: u32::try_from(length).ok()?,
                    width: u32::try_from(width).ok()?,
                    m,
                    k,
                    k2,
                    z,
                    zo,
                    pos,
                    vel,
                })))
            }
            Shape::PosInput => {
                let channel = self.channel(label, "in", first, at);
                let pos = self.vector(args.first()?, at);
                Some(ElementKind::PosInput {
                    channel: channel?,
                    pos: pos?,
                })
            }
            Shape::FrcInput | Shape::PosOutput | Shape::FrcOutput => {
                let prefix = if shape == Shape::FrcInput {
                    "in"
                } else {
                    "out"
                };
                let channel = self.channel(label, prefix, first, at);
                let target = self.slot_endpoint(args, 0, points, at);
                let (channel, target) = (channel?, target?);
                Some(match shape {
                    Shape::FrcInput => ElementKind::FrcInput { channel, target },
                    Shape::PosOutput => ElementKind::PosOutput { channel, target },
                    _ => ElementKind::FrcOutput { channel, target },
                })
            }
            Shape::Param | Shape::AudioParam => None,
        }
    }
}

/// Builds a law from its parameters (0 for the optional ones not written, and in the slots past
/// the law's own); `given` is the number written, which selects the legacy two-parameter
/// `spring` (= springDamper, spec §3.12 a).
fn make_law(form: LawForm, given: usize, p: [Expr; LawKind::MAX_ARITY]) -> Law {
    match form {
        LawForm::Spring if given == 2 => Law::new(LawKind::SpringDamper, p),
        form => Law::of_form(form, p),
    }
}
