//! Endpoints and targets (spec §3.4, §2.8): a point's `@label`, or a connection point
//! `[@macro α]` / `[@mesh u w]`, legacy bare forms included (§3.14).

use super::{At, Builder};
use crate::lang::diagnostics::DiagnosticCode;
use crate::lang::legacy;
use crate::lang::lexer::{after_first, col_plus, split_items, TokKind, Token};
use crate::lang::symbols::SymKind;
use crate::spec::expr::Expr;
use crate::spec::{label, Endpoint};

impl Builder<'_> {
    /// An endpoint or target (spec §3.4, §2.8): `@label` of a point, or `[@macro α]` /
    /// `[@mesh u w]`.
    pub(super) fn endpoint(&mut self, t: &Token, at: At<'_>) -> Option<Endpoint> {
        match t.kind {
            TokKind::Bare if t.starts_with_at() => {
                let name = t.label();
                if name.is_empty() {
                    self.diags.push(at.diag(
                        DiagnosticCode::BadLabel,
                        t.col,
                        "missing label after `@`",
                    ));
                    return None;
                }
                let ok = match self.symbols.get(name).map(|s| s.kind) {
                    Some(SymKind::Point | SymKind::Unknown) => true,
                    None => {
                        self.diags.push(
                            at.diag(
                                DiagnosticCode::UndefinedElement,
                                t.col,
                                format!("undefined element `@{name}`"),
                            )
                            .with_found(format!("@{name}")),
                        );
                        false
                    }
                    Some(SymKind::Macro { dims }) => {
                        let example = match dims {
                            0 => format!("@{name}_m0"),
                            3 => format!("[@{name} u v w]"),
                            2 => format!("[@{name} u w]"),
                            _ => format!("[@{name} α]"),
                        };
                        let example = if self.space.is_some() && dims != 0 {
                            format!("`@{name}_m0` or `{example}`")
                        } else {
                            example
                        };
                        self.diags.push(
                            at.diag(
                                DiagnosticCode::BareMacroReference,
                                t.col,
                                format!(
                                    "`@{name}` is a macro: refer to a point on it with a \
                                     connection point such as `{example}`"
                                ),
                            )
                            .with_expected(example)
                            .with_found(format!("@{name}")),
                        );
                        false
                    }
                    Some(other) => {
                        self.diags.push(
                            at.diag(
                                DiagnosticCode::NotAPoint,
                                t.col,
                                format!("`@{name}` is {}, not a point", other.describe()),
                            )
                            .with_expected("a mass-type element, an avatar or a connection point")
                            .with_found(format!("@{name}")),
                        );
                        false
                    }
                };
                ok.then(|| Endpoint::Label(label(name)))
            }
            TokKind::Bracket if t.first_non_blank() == Some('@') => self.connection_point(t, at),
            _ => {
                self.diags.push(
                    at.diag(
                        DiagnosticCode::ExpectedEndpoint,
                        t.col,
                        format!("expected an endpoint, found `{}`", t.source()),
                    )
                    .with_expected("@label, [@macro α] or [@mesh u w]")
                    .with_found(t.source()),
                );
                None
            }
        }
    }

    /// The endpoint in argument slot `slot`: a legacy bare connection point when `points` has
    /// one there (spec §2.8, §3.14; the same endpoint as the bracket form), otherwise
    /// [`Self::endpoint`].
    pub(super) fn slot_endpoint(
        &mut self,
        args: &[Token],
        slot: usize,
        points: &[legacy::Point],
        at: At<'_>,
    ) -> Option<Endpoint> {
        let Some(p) = points.iter().find(|p| p.slot == slot) else {
            return self.endpoint(args.get(slot)?, at);
        };
        let coords: Vec<Option<Expr>> = p.coords.iter().map(|t| self.expr(t, at)).collect();
        let target = label(p.target.as_str());
        match <[Option<Expr>; 2]>::try_from(coords) {
            Ok([u, w]) => Some(Endpoint::Surface {
                target,
                u: Box::new(u?),
                w: Box::new(w?),
            }),
            Err(mut one) => Some(Endpoint::Line {
                target,
                alpha: Box::new(one.pop()??),
            }),
        }
    }

    fn connection_point(&mut self, t: &Token, at: At<'_>) -> Option<Endpoint> {
        let items = split_items(t.text);
        let &(first, offset) = items.first()?;
        let target = label(after_first(first));
        let target_col = col_plus(t.inner_col(), offset);
        if target.is_empty() || target.contains(['(', ')']) {
            self.diags.push(
                at.diag(
                    DiagnosticCode::BadLabel,
                    target_col,
                    "a connection point starts with the macro's `@label`",
                )
                .with_found(t.source()),
            );
            return None;
        }
        let coords = items.get(1..).unwrap_or(&[]);
        let found = coords.len();
        let mut ok = true;
        match self.symbols.get(&target).map(|s| s.kind) {
            None => {
                self.diags.push(
                    at.diag(
                        DiagnosticCode::UndefinedElement,
                        target_col,
                        format!("undefined element `@{target}`"),
                    )
                    .with_found(format!("@{target}")),
                );
                ok = false;
            }
            Some(SymKind::Macro { dims }) if usize::from(dims) != found => {
                let what = match (dims, self.space.is_some()) {
                    (0, _) => "an icosphere's or a mesh file's nodes are addressed by label,                                e.g. `@b_m3`; it takes no coordinate",
                    (3, _) => "a lattice takes 3 coordinates [@c u v w]",
                    (2, true) => "a membrane takes 2 coordinates [@me u w]",
                    (1, true) => "a string or ring takes 1 coordinate [@s α]",
                    (2, false) => "a mesh takes 2 coordinates [@mesh u w]",
                    _ => "a string, chain or stiff string takes 1 coordinate [@s α]",
                };
                self.diags.push(
                    at.diag(
                        DiagnosticCode::WrongCoordinateCount,
                        t.col,
                        format!(
                            "wrong number of connection coordinates for `@{target}`: {what}, \
                             found {found} (an expression with spaces goes in parentheses)"
                        ),
                    )
                    .with_expected(dims.to_string())
                    .with_found(found.to_string()),
                );
                ok = false;
            }
            Some(SymKind::Macro { .. } | SymKind::Unknown) => {}
            Some(other) => {
                self.diags.push(
                    at.diag(
                        DiagnosticCode::NotAMacro,
                        target_col,
                        format!(
                            "`@{target}` is {}: connection-point brackets need a macro",
                            other.describe()
                        ),
                    )
                    .with_expected("a string, chain, stiffString or mesh")
                    .with_found(format!("@{target}")),
                );
                ok = false;
            }
        }
        // A 3-D lattice takes three (3-D spec §2.6).
        let most = if self.space.is_some() { 3 } else { 2 };
        let count_in_range = (1..=most).contains(&found);
        if ok && !count_in_range {
            let expected = if most == 3 { "1, 2 or 3" } else { "1 or 2" };
            self.diags.push(
                at.diag(
                    DiagnosticCode::WrongCoordinateCount,
                    t.col,
                    format!(
                        "a connection point has {expected} coordinates, found {found} (an \
                         expression with spaces goes in parentheses)"
                    ),
                )
                .with_expected(expected)
                .with_found(found.to_string()),
            );
            ok = false;
        }
        // Coordinates are parsed only when their count is right: with a wrong count the items
        // are usually pieces of a spaced expression, already explained by the message above.
        let dims_mismatch = matches!(
            self.symbols.get(&target).map(|s| s.kind),
            Some(SymKind::Macro { dims }) if usize::from(dims) != found
        );
        let count_ok = count_in_range && !dims_mismatch;
        if !count_ok {
            return None;
        }
        let exprs: Vec<Option<Expr>> = coords
            .iter()
            .map(|&item| self.item_expr(t, item, at))
            .collect();
        let exprs: Option<Vec<Expr>> = exprs.into_iter().collect();
        let exprs = exprs?;
        if !ok {
            return None;
        }
        match <[Expr; 1]>::try_from(exprs) {
            Ok([alpha]) => Some(Endpoint::Line {
                target,
                alpha: Box::new(alpha),
            }),
            Err(exprs) => match <[Expr; 2]>::try_from(exprs) {
                Ok([u, w]) => Some(Endpoint::Surface {
                    target,
                    u: Box::new(u),
                    w: Box::new(w),
                }),
                Err(exprs) => <[Expr; 3]>::try_from(exprs)
                    .ok()
                    .map(|coords| Endpoint::Volume {
                        target,
                        coords: Box::new(coords),
                    }),
            },
        }
    }
}
