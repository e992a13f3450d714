//! One command line: its label and keyword, the argument count, a legacy trailing buffer tag
//! (spec §6.4) and the legacy proxy forms (spec §3.14), then the element or parameter it
//! declares, in the open buffer scopes.

use super::keywords::{arity, keywords, shape_of, Shape};
use super::lines::Item;
use super::{At, Builder};
use crate::lang::diagnostics::DiagnosticCode;
use crate::lang::expr_parser::is_identifier;
use crate::lang::legacy;
use crate::lang::lexer::{TokKind, Token};
use crate::lang::numbers::token_number_literal;
use crate::lang::symbols::{SymKind, Symbol};
use crate::spec::{Element, Span};

/// A legacy trailing buffer tag `NAME x y` (spec §6.4).
struct Tag {
    name: String,
    x: f64,
    y: f64,
}

impl Builder<'_> {
    pub(super) fn command(&mut self, item: &Item) {
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
        let shape = if kw.kind == TokKind::Bracket {
            None
        } else {
            shape_of(kw.text)
        };
        let Some(shape) = shape else {
            let keyword = kw.string();
            let mut d = at.diag(
                DiagnosticCode::UnknownKeyword,
                kw.col,
                format!("unknown type keyword `{}`", kw.source()),
            );
            if let Some((k, _)) = keywords().find(|(k, _)| k.eq_ignore_ascii_case(&keyword)) {
                d.message.push_str(&format!(" (did you mean `{k}`?)"));
                d = d.with_expected(format!("`{k}`"));
            }
            self.diags.push(d.with_found(kw.source()));
            return;
        };
        let args = tokens.get(2..).unwrap_or(&[]);
        let (min, max, signature) = arity(shape);
        let (args, tag) = match shape {
            Shape::Mass | Shape::Osc | Shape::Ground | Shape::MassG => {
                self.split_tag(args, min, max, at)
            }
            _ => (Some(args), None),
        };
        let Some(args) = args else {
            return; // a malformed tag, reported
        };
        // The legacy syntax of the MIMS proxy branch (spec §3.14), read as its modern form.
        let form = match shape {
            Shape::Law(_) => legacy::Form::Endpoints(2),
            Shape::FrcInput | Shape::PosOutput | Shape::FrcOutput => legacy::Form::Endpoints(1),
            Shape::Macro(_) => legacy::Form::Macro,
            _ => legacy::Form::Other,
        };
        let place = legacy::Place {
            line: item.line,
            label,
        };
        let read = legacy::read(form, (min, max), args, self.symbols, place, &mut self.diags);
        let (args, points) = match &read {
            Some(r) => (r.args.as_slice(), r.points.as_slice()),
            None => (args, &[][..]),
        };
        if args.len() < min || args.len() > max {
            self.report_count(shape, &kw.string(), kw, args, (min, max, signature), at);
            return;
        }
        let kind = match shape {
            Shape::Param | Shape::AudioParam => {
                if let Some(p) = self.param(shape, label, first, args, at, span) {
                    self.spec.params.push(p);
                }
                return;
            }
            _ => self.element(shape, label, first, args, points, at),
        };
        let Some(kind) = kind else {
            return;
        };
        let mut buffers = self.open.clone();
        let mut tag_xy = None;
        if let Some(tag) = tag {
            let id = self.buffer_index(&tag.name);
            if !buffers.contains(&id) {
                buffers.push(id);
            }
            tag_xy = Some((tag.x, tag.y));
        }
        self.spec.elements.push(Element {
            label: crate::spec::label(label),
            kind,
            buffers,
            tag_xy,
            span,
        });
    }

    /// Recognises a legacy trailing buffer tag `NAME x y` on a mass-type element (spec §6.4):
    /// three tokens more than an accepted argument count, the third from the end a bare name
    /// that is not a declared parameter. Returns the arguments without the tag (or `None` when
    /// the tag's coordinates are not numbers, which is reported).
    fn split_tag<'t, 'c>(
        &mut self,
        args: &'t [Token<'c>],
        min: usize,
        max: usize,
        at: At<'_>,
    ) -> (Option<&'t [Token<'c>]>, Option<Tag>) {
        let n = args.len();
        if n < 3 || !(min..=max).contains(&(n - 3)) {
            return (Some(args), None);
        }
        let (base, tag) = args.split_at(n - 3);
        let [name, x, y] = tag else {
            return (Some(args), None);
        };
        let name_s = name.string();
        let is_param = self
            .symbols
            .get(&name_s)
            .is_some_and(|s| s.kind == SymKind::Param);
        if name.kind != TokKind::Bare || !is_identifier(&name_s) || is_param {
            return (Some(args), None);
        }
        let coord = |t: &Token, this: &mut Self| -> Option<f64> {
            match token_number_literal(t) {
                Ok(v) => Some(v),
                Err(e) => {
                    this.diags.push(
                        at.diag(
                            e.code(),
                            t.col,
                            format!(
                                "the coordinates of the legacy buffer tag `{name_s}` must be \
                                 numeric literals"
                            ),
                        )
                        .with_expected("a number")
                        .with_found(t.source()),
                    );
                    None
                }
            }
        };
        let x = coord(x, self);
        let y = coord(y, self);
        match (x, y) {
            (Some(x), Some(y)) => (Some(base), Some(Tag { name: name_s, x, y })),
            _ => (None, None),
        }
    }

    fn report_count(
        &mut self,
        shape: Shape,
        keyword: &str,
        kw: &Token,
        args: &[Token],
        (min, max, signature): (usize, usize, &'static str),
        at: At<'_>,
    ) {
        let expected = if min == max {
            format!(
                "{min} argument{}: {signature}",
                if min == 1 { "" } else { "s" }
            )
        } else {
            format!("{min} or {max} arguments: {signature}")
        };
        let found = args.len().to_string();
        let (col, message) = if shape == Shape::Ground && args.len() > 1 {
            (
                args.first().map_or(kw.col, |t| t.col),
                "extra tokens before the ground's position: `ground` takes exactly one \
                 position"
                    .to_string(),
            )
        } else if args.len() > max {
            let mut m = format!("too many arguments for `{keyword}` (expected {expected})");
            // A legacy trailing proxy (`@in1 frcInput @s 0.3`, §3.14) names a macro bare.
            let slots = match shape {
                Shape::Law(_) => 2,
                Shape::FrcInput | Shape::PosOutput | Shape::FrcOutput => 1,
                _ => 0,
            };
            let names_macro = args.iter().take(slots).any(|t| {
                t.kind == TokKind::Bare
                    && t.starts_with_at()
                    && matches!(
                        self.symbols.get(t.label()),
                        Some(Symbol {
                            kind: SymKind::Macro { .. },
                            ..
                        })
                    )
            });
            if names_macro {
                m.push_str(
                    "; a connection point is written in brackets, e.g. `[@s 0.3]` or \
                     `[@mesh u w]`",
                );
            }
            (args.get(max).map_or(kw.col, |t| t.col), m)
        } else {
            (
                kw.col,
                format!("too few arguments for `{keyword}` (expected {expected})"),
            )
        };
        self.diags.push(
            at.diag(DiagnosticCode::WrongArgumentCount, col, message)
                .with_expected(expected)
                .with_found(found),
        );
    }
}
