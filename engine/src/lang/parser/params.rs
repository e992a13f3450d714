//! `param` and `audioParam` commands (spec §3.8): the parameter name, a control parameter's
//! value, and an audio-rate parameter's input and optional default.

use super::keywords::Shape;
use super::{At, Builder};
use crate::lang::diagnostics::DiagnosticCode;
use crate::lang::expr_parser::is_identifier;
use crate::lang::lexer::{TokKind, Token};
use crate::lang::numbers::{parse_number_literal, token_number_literal, NumberError};
use crate::spec::expr::Func;
use crate::spec::{ParamDecl, ParamKind, Span};

impl Builder<'_> {
    /// A `param` or `audioParam` with an accepted argument count.
    pub(super) fn param(
        &mut self,
        shape: Shape,
        label: &str,
        first: &Token,
        args: &[Token],
        at: At<'_>,
        span: Span,
    ) -> Option<ParamDecl> {
        let name_ok = is_identifier(label) && Func::from_name(label).is_none();
        if !name_ok {
            self.diags.push(
                at.diag(
                    DiagnosticCode::BadLabel,
                    first.col,
                    format!(
                        "parameter name `{label}` must be an identifier ([A-Za-z_][A-Za-z0-9_]*) \
                         that is not a function name"
                    ),
                )
                .with_found(label.to_string()),
            );
        }
        let v = args.first()?;
        let kind = if shape == Shape::Param {
            self.literal(v, "a param value", at)
                .map(|value| ParamKind::Control { value })
        } else {
            self.audio_param(args, at)
        };
        let kind = kind?;
        name_ok.then(|| ParamDecl {
            name: label.to_string(),
            kind,
            span,
        })
    }

    /// `audioParam @inN [default]`. The default is a numeric literal after the input label;
    /// one written first (`audioParam 0.3 @in3`) is reported with the right order.
    fn audio_param(&mut self, args: &[Token], at: At<'_>) -> Option<ParamKind> {
        let v = &args[0];
        let is_label = v.kind == TokKind::Bare && v.starts_with_at();
        if !is_label {
            let swapped = args.len() == 2
                && args[1].kind == TokKind::Bare
                && args[1].starts_with_at()
                && parse_number_literal(v.text).is_ok();
            let message = if swapped {
                format!(
                    "`audioParam` takes its input first and its default after it: write `{} {}`",
                    args[1].source(),
                    v.source()
                )
            } else {
                format!(
                    "`audioParam` takes an input label `@inN`, found `{}`",
                    v.source()
                )
            };
            self.diags.push(
                at.diag(DiagnosticCode::BadChannelLabel, v.col, message)
                    .with_expected("@inN")
                    .with_found(v.source()),
            );
            return None;
        }
        let input = self.channel(v.label(), "in", v, at);
        let default = match args.get(1) {
            Some(d) => Some(self.literal(d, "an audioParam default", at)?),
            None => Some(0.0),
        };
        Some(ParamKind::Audio {
            input: input?,
            default: default?,
        })
    }

    /// A numeric literal with an optional sign (a `param` value, an `audioParam` default),
    /// or a diagnostic at its column.
    fn literal(&mut self, v: &Token, what: &str, at: At<'_>) -> Option<f64> {
        match token_number_literal(v) {
            Ok(value) => Some(value),
            Err(e) => {
                let message = match e {
                    NumberError::Invalid => format!(
                        "{what} is a numeric literal with an optional sign, found `{}`",
                        v.source()
                    ),
                    NumberError::NonFinite => format!("non-finite number `{}`", v.source()),
                };
                self.diags.push(
                    at.diag(e.code(), v.col, message)
                        .with_expected("a number such as `0.5` or `-1e-3`")
                        .with_found(v.source()),
                );
                None
            }
        }
    }
}
