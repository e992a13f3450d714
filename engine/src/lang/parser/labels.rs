//! Pass 1: the labels of a script.

use super::keywords::{shape_of, sym_kind};
use super::lines::{is_generate, Item};
use super::space::labels::Pass1;
use crate::lang::diagnostics::{Diagnostic, DiagnosticCode, Diags};
use crate::lang::generate::{self, GenRequest, Read, MAX_GENERATED_ELEMENTS};
use crate::lang::lexer::{TokKind, Token};
use crate::lang::symbols::{SymKind, Symbol, Symbols};

/// Pass 1: every label (spec §3.4: names and elements may be used before their declaration
/// line), those a `~generate` directive creates included (§4), with duplicates reported.
/// A `~generate` directive is read here and kept on its item for pass 2.
///
/// In a 3-D script (`space`), labels name what the 3-D keywords make, and the structures and
/// adders record the labels they create ([`Pass1`]); `~generate` is a 1-D directive, reported
/// in pass 2.
pub(super) fn declare_labels<'a>(
    items: &mut [Item],
    all: &[Token<'a>],
    diags: &mut Diags,
    mut space: Option<&mut Pass1<'_>>,
) -> Symbols<'a> {
    let mut symbols = Symbols::with_capacity(items.len());
    let mut budget = MAX_GENERATED_ELEMENTS;
    for item in items.iter_mut() {
        if item.directive && space.is_some() {
            continue;
        }
        if item.directive {
            if let Some(name) = item.broken_generator.take() {
                symbols.insert_broken_generator(name);
            } else if is_generate(item, all) {
                match generate::read(item.tokens(all), item.line, diags, &mut budget) {
                    Read::Ready(req) => {
                        if declare_generated(&req, &mut symbols, diags) {
                            item.generator = Some(req);
                        }
                    }
                    Read::Broken { name: Some(name) } => symbols.insert_broken_generator(name),
                    Read::Broken { name: None } => {}
                }
            }
            continue;
        }
        let tokens = item.tokens(all);
        let Some(first) = tokens.first() else {
            continue;
        };
        let label = first.label();
        if label.is_empty() {
            if item.broken {
                continue; // the lexical error is enough
            }
            diags.push(Diagnostic::new(
                DiagnosticCode::BadLabel,
                item.line,
                first.col,
                "missing label after `@`",
            ));
            continue;
        }
        let keyword = tokens.get(1).filter(|t| t.kind != TokKind::Bracket);
        let kind = match (&space, keyword) {
            (Some(_), Some(k)) => Pass1::kind_of(k.text),
            (None, Some(k)) => shape_of(k.text).map_or(SymKind::Unknown, sym_kind),
            (_, None) => SymKind::Unknown,
        };
        let symbol = Symbol {
            kind,
            line: item.line,
            col: first.col,
            generated: false,
        };
        let declared = symbols.declare(label, symbol);
        if let (Ok(()), Some(pass), Some(k)) = (&declared, space.as_deref_mut(), keyword) {
            let args = tokens.get(2..).unwrap_or(&[]);
            pass.declared(&mut symbols, label, k.text, args, (item.line, first.col));
        }
        if let Err((label, prev)) = declared {
            let message = if prev.generated {
                format!(
                    "duplicate label `@{label}`: the `~generate` at line {} column {} \
                     already creates it",
                    prev.line, prev.col
                )
            } else {
                format!(
                    "duplicate label `@{label}`: already used at line {} column {} \
                     (parameters and elements share one namespace)",
                    prev.line, prev.col
                )
            };
            diags.push(
                Diagnostic::new(
                    DiagnosticCode::DuplicateLabel,
                    item.line,
                    first.col,
                    message,
                )
                .with_label(Some(&label)),
            );
        }
    }
    symbols
}

/// Declares the labels a `~generate` directive creates (pass 1). A clash with a label declared
/// earlier is reported once, at the generator's name; the directive is then not expanded.
/// Returns true when every label was free.
fn declare_generated(req: &GenRequest, symbols: &mut Symbols, diags: &mut Diags) -> bool {
    let plan = match crate::spec::generators::plan(&req.name, &req.topology) {
        Ok(plan) => plan,
        Err(e) => {
            // `generate::read` checked the sizes; report anything else rather than panic.
            diags.push(
                Diagnostic::new(
                    DiagnosticCode::InvalidGeneratorValue,
                    req.line,
                    req.kind_col,
                    e.to_string(),
                )
                .with_label(Some(&req.name)),
            );
            symbols.insert_broken_generator(req.name.clone());
            return false;
        }
    };
    let labels = plan
        .params
        .into_iter()
        .map(|l| (l, SymKind::Param))
        .chain(plan.nodes.into_iter().map(|l| (l, SymKind::Point)))
        .chain(plan.links.into_iter().map(|l| (l, SymKind::Interaction)));
    let mut first_clash: Option<(String, Symbol)> = None;
    let mut clashes = 0usize;
    for (label, kind) in labels {
        match symbols.declared(&label) {
            Some(prev) => {
                clashes += 1;
                if first_clash.is_none() {
                    first_clash = Some((label, prev));
                }
            }
            None => symbols.insert(
                label,
                Symbol {
                    kind,
                    line: req.line,
                    col: req.name_col,
                    generated: true,
                },
            ),
        }
    }
    let Some((label, prev)) = first_clash else {
        return true;
    };
    let by = if prev.generated {
        "the `~generate`"
    } else {
        "the label"
    };
    let more = match clashes {
        1 => String::new(),
        n => format!(" ({} more of its labels clash too)", n - 1),
    };
    diags.push(
        Diagnostic::new(
            DiagnosticCode::DuplicateLabel,
            req.line,
            req.name_col,
            format!(
                "`~generate {} {}` creates `@{label}`, already used by {by} at line {} column \
                 {}{more}; choose another generator name",
                req.keyword, req.name, prev.line, prev.col
            ),
        )
        .with_label(Some(&req.name))
        .with_found(format!("@{label}")),
    );
    false
}
