//! Argument values: expressions (spec §3.5), position and velocity vectors (§3.7), macro
//! sizes (§2.7) and the channel numbers of input and output labels.

use super::{At, Builder, MAX_MACRO_NODES};
use crate::lang::diagnostics::DiagnosticCode;
use crate::lang::expr_parser::{parse_expression, ExprContext};
use crate::lang::lexer::{col_plus, is_blank, split_items, BracketItem, TokKind, Token};
use crate::lang::numbers::plain_number;
use crate::lang::symbols::SymKind;
use crate::spec::expr::Expr;
use crate::spec::Vector;

impl Builder<'_> {
    pub(super) fn expr(&mut self, t: &Token, at: At<'_>) -> Option<Expr> {
        // The commonest argument, a signed literal, is none of the cases checked below.
        if t.kind == TokKind::Bare {
            if let Some(v) = plain_number(t.text) {
                return Some(Expr::Num(v));
            }
        }
        if t.kind == TokKind::Bracket && t.first_non_blank() == Some('@') {
            self.diags.push(
                at.diag(
                    DiagnosticCode::ExpressionSyntax,
                    t.col,
                    "a connection point cannot stand where a value is expected",
                )
                .with_expected("a number, a parameter or an expression")
                .with_found(t.source()),
            );
            return None;
        }
        if t.kind == TokKind::Bare && t.starts_with_at() {
            self.diags.push(
                at.diag(
                    DiagnosticCode::ExpressionSyntax,
                    t.col,
                    format!(
                        "`{}` is a label where a value is expected (parameters are referred to \
                         without `@`)",
                        t.source()
                    ),
                )
                .with_expected("a number, a parameter or an expression")
                .with_found(t.source()),
            );
            return None;
        }
        if t.text.chars().all(is_blank) {
            self.diags.push(
                at.diag(DiagnosticCode::ExpressionSyntax, t.col, "empty expression")
                    .with_found(t.source()),
            );
            return None;
        }
        let cx = ExprContext {
            symbols: self.symbols,
            line: at.line,
            label: at.label,
            auto: self.auto,
        };
        parse_expression(t.text, t.inner_col(), &cx, &mut self.diags)
    }

    /// An expression in an item of a vector or connection bracket.
    pub(super) fn item_expr(
        &mut self,
        t: &Token,
        (text, offset): BracketItem<'_>,
        at: At<'_>,
    ) -> Option<Expr> {
        let cx = ExprContext {
            symbols: self.symbols,
            line: at.line,
            label: at.label,
            auto: self.auto,
        };
        parse_expression(text, col_plus(t.inner_col(), offset), &cx, &mut self.diags)
    }

    /// A position or velocity (spec §3.7): a scalar z, or a bracket `[x y z]` whose items are
    /// space-free tokens or parenthesised expressions. A one-item bracket is a scalar.
    pub(super) fn vector(&mut self, t: &Token, at: At<'_>) -> Option<Vector> {
        if t.kind != TokKind::Bracket || t.first_non_blank() == Some('@') {
            return self.expr(t, at).map(Vector::Scalar);
        }
        let items = split_items(t.text);
        match items.as_slice() {
            [one] => self.item_expr(t, *one, at).map(Vector::Scalar),
            [x, y, z] => {
                let x = self.item_expr(t, *x, at);
                let y = self.item_expr(t, *y, at);
                let z = self.item_expr(t, *z, at);
                Some(Vector::Xyz(Box::new([x?, y?, z?])))
            }
            _ => {
                self.diags.push(
                    at.diag(
                        DiagnosticCode::VectorSize,
                        t.col,
                        format!(
                            "a position or velocity vector has 3 coordinates [x y z], found {} \
                             (write an expression with spaces in parentheses)",
                            items.len()
                        ),
                    )
                    .with_expected("3")
                    .with_found(items.len().to_string()),
                );
                None
            }
        }
    }

    /// A macro size: an integer literal ≥ 2 (`40` or `40.`; spec §2.7, §3.12 a).
    pub(super) fn size(&mut self, t: &Token, at: At<'_>) -> Option<u64> {
        let text = t.string();
        // digits, optionally followed by `.` and zeros only
        let (int_part, frac) = match text.split_once('.') {
            Some((i, f)) => (i, f),
            None => (text.as_str(), ""),
        };
        let is_integer_literal = t.kind == TokKind::Bare
            && !int_part.is_empty()
            && int_part.chars().all(|c| c.is_ascii_digit())
            && frac.chars().all(|c| c == '0');
        if !is_integer_literal {
            let is_param = self
                .symbols
                .get(&text)
                .is_some_and(|s| s.kind == SymKind::Param);
            let message = if is_param {
                format!(
                    "macro sizes must be integer literals; the parameter `{text}` is not allowed"
                )
            } else {
                format!("macro size `{}` is not an integer literal", t.source())
            };
            self.diags.push(
                at.diag(DiagnosticCode::NonIntegerSize, t.col, message)
                    .with_expected("an integer literal ≥ 2, e.g. `40` or `40.`")
                    .with_found(t.source()),
            );
            return None;
        }
        let value = match int_part.parse::<u64>() {
            Ok(v) => v,
            Err(_) => {
                self.diags.push(
                    at.diag(
                        DiagnosticCode::TooLarge,
                        t.col,
                        format!("macro size `{text}` is too large"),
                    )
                    .with_expected(format!("at most {MAX_MACRO_NODES} nodes"))
                    .with_found(text),
                );
                return None;
            }
        };
        if value < 2 {
            self.diags.push(
                at.diag(
                    DiagnosticCode::InvalidSize,
                    t.col,
                    format!("macro size {value} is below 2"),
                )
                .with_expected("an integer ≥ 2")
                .with_found(text),
            );
            return None;
        }
        Some(value)
    }

    pub(super) fn channel(
        &mut self,
        label: &str,
        prefix: &str,
        t: &Token,
        at: At<'_>,
    ) -> Option<u32> {
        let digits = label.strip_prefix(prefix).unwrap_or("");
        let valid = !digits.is_empty()
            && digits.chars().all(|c| c.is_ascii_digit())
            && !digits.starts_with('0');
        let value = if valid {
            digits.parse::<u32>().ok()
        } else {
            None
        };
        if value.is_none() {
            self.diags.push(
                at.diag(
                    DiagnosticCode::BadChannelLabel,
                    t.col,
                    format!(
                        "`@{label}` is not a valid {} label: write `@{prefix}N` with N a \
                         positive decimal integer",
                        if prefix == "in" { "input" } else { "output" }
                    ),
                )
                .with_expected(format!("@{prefix}N"))
                .with_found(format!("@{label}")),
            );
        }
        value
    }
}
