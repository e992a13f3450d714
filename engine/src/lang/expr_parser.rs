//! Argument expressions and number literals (spec §3.5, normative decision §3.12 c).
//!
//! ```text
//! expr    := term  { ("+" | "-") term }
//! term    := unary { ("*" | "/") unary }
//! unary   := ("-" | "+") unary | primary
//! primary := number | name | call | "(" expr ")"
//! call    := func "(" expr { "," expr } ")"
//! number  := digits [ "." [digits] ] [ exponent ] | "." digits [ exponent ]
//! exponent:= ("e" | "E") [ "+" | "-" ] digits
//! ```
//!
//! A unary minus written directly before a number literal folds into the literal (`-0.2` is
//! `Expr::Num(-0.2)`, as the builder writes it); before anything else, including a parenthesised
//! number, it is [`Expr::Neg`]. Unary plus is dropped. Recursion and tree depth are capped at
//! [`MAX_NESTING`] so no input can overflow the stack.

use super::diagnostics::{Diagnostic, DiagnosticCode, Diags};
use super::lexer::is_blank;
use super::numbers::{plain_number, scan_number, to_f64, NumberError};
use super::symbols::{SymKind, Symbols};
use crate::spec::expr::{BinOp, Expr, Func};

/// The deepest nesting (parentheses, calls, unary operators) and the deepest expression tree the
/// front end accepts. Below the compiler's own limit of 256 (`compile::MAX_EXPR_DEPTH`).
pub const MAX_NESTING: usize = 200;

/// True for identifiers `[A-Za-z_][A-Za-z0-9_]*` (spec §3.4).
pub(crate) fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Ident(String),
    Op(char),
    End,
}

/// Where a name is being resolved from, for messages.
pub(crate) struct ExprContext<'a> {
    pub symbols: &'a Symbols<'a>,
    pub line: u32,
    pub label: Option<&'a str>,
    /// `auto` (3-D spec §1.7): `None` in a 1-D script, where it is an ordinary name; in a 3-D
    /// script a reserved word, allowed (`Some(true)`) only in a length slot.
    pub auto: Option<bool>,
}

struct ExprParser<'a, 'd> {
    toks: Vec<(Tok, u32)>,
    pos: usize,
    nest: usize,
    cx: &'a ExprContext<'a>,
    diags: &'d mut Diags,
    /// A non-fatal error was reported (undefined name, wrong arity): the result is discarded.
    failed: bool,
}

/// Parses `text` (whose first character stands at column `col`) as an expression. Reports every
/// problem and returns `None` when there was any.
pub(crate) fn parse_expression(
    text: &str,
    col: u32,
    cx: &ExprContext<'_>,
    diags: &mut Diags,
) -> Option<Expr> {
    if let Some(v) = plain_number(text) {
        return Some(Expr::Num(v));
    }
    let toks = lex(text, col, cx, diags)?;
    let mut p = ExprParser {
        toks,
        pos: 0,
        nest: 0,
        cx,
        diags,
        failed: false,
    };
    let (e, _) = p.expr()?;
    if p.peek() != &Tok::End {
        let found = p.describe_current();
        p.syntax_error(format!("unexpected {found} after the expression"));
        return None;
    }
    if p.failed {
        None
    } else {
        Some(e)
    }
}

/// Splits an expression into tokens. `i` is a byte offset and `at` its column: every character
/// of a token is ASCII, and any other character is a blank (one column) or an error.
fn lex(text: &str, col: u32, cx: &ExprContext<'_>, diags: &mut Diags) -> Option<Vec<(Tok, u32)>> {
    let bytes = text.as_bytes();
    let mut toks = Vec::new();
    let mut i = 0;
    let mut at = col;
    while let Some(c) = text.get(i..).and_then(|s| s.chars().next()) {
        if is_blank(c) {
            i += c.len_utf8();
            at = at.saturating_add(1);
            continue;
        }
        if c.is_ascii_digit() || (c == '.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            let end = scan_number(bytes, i).unwrap_or(i + 1);
            // A number glued to letters, digits or a dot (`40abc`, `1.2.3`, `1e`) is invalid.
            let glued = text
                .get(end..)
                .unwrap_or("")
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == '.'))
                .map_or(text.len(), |k| end + k);
            let written = text.get(i..glued).unwrap_or("");
            if glued > end {
                diags.push(
                    Diagnostic::new(
                        DiagnosticCode::InvalidNumber,
                        cx.line,
                        at,
                        format!("invalid number `{written}`"),
                    )
                    .with_label(cx.label)
                    .with_found(written),
                );
                return None;
            }
            match to_f64(written) {
                Ok(v) => toks.push((Tok::Num(v), at)),
                Err(e) => {
                    let (code, msg) = match e {
                        NumberError::NonFinite => (
                            DiagnosticCode::NonFiniteNumber,
                            format!("non-finite number `{written}`"),
                        ),
                        NumberError::Invalid => (
                            DiagnosticCode::InvalidNumber,
                            format!("invalid number `{written}`"),
                        ),
                    };
                    diags.push(
                        Diagnostic::new(code, cx.line, at, msg)
                            .with_label(cx.label)
                            .with_found(written),
                    );
                    return None;
                }
            }
            at = at.saturating_add(u32::try_from(end - i).unwrap_or(u32::MAX));
            i = end;
        } else if c.is_ascii_alphabetic() || c == '_' {
            let len = bytes
                .get(i..)
                .unwrap_or(&[])
                .iter()
                .take_while(|b| b.is_ascii_alphanumeric() || **b == b'_')
                .count();
            let name = text.get(i..i + len).unwrap_or("").to_string();
            toks.push((Tok::Ident(name), at));
            at = at.saturating_add(u32::try_from(len).unwrap_or(u32::MAX));
            i += len;
        } else if matches!(c, '+' | '-' | '*' | '/' | '(' | ')' | ',') {
            toks.push((Tok::Op(c), at));
            i += 1;
            at = at.saturating_add(1);
        } else {
            let hint = match c {
                '@' => {
                    " (parameters are referred to without `@`; connection points only go in \
                        endpoint slots)"
                }
                '^' => " (use pow(x, y))",
                _ => "",
            };
            diags.push(
                Diagnostic::new(
                    DiagnosticCode::ExpressionSyntax,
                    cx.line,
                    at,
                    format!("unexpected character `{c}` in expression{hint}"),
                )
                .with_label(cx.label)
                .with_found(c.to_string()),
            );
            return None;
        }
    }
    toks.push((Tok::End, at));
    Some(toks)
}

impl ExprParser<'_, '_> {
    fn peek(&self) -> &Tok {
        self.toks.get(self.pos).map(|t| &t.0).unwrap_or(&Tok::End)
    }

    fn col(&self) -> u32 {
        self.toks
            .get(self.pos)
            .or(self.toks.last())
            .map(|t| t.1)
            .unwrap_or(1)
    }

    fn bump(&mut self) {
        if self.pos < self.toks.len() {
            self.pos += 1;
        }
    }

    fn describe_current(&self) -> String {
        match self.peek() {
            Tok::Num(v) => format!("number `{v}`"),
            Tok::Ident(n) => format!("name `{n}`"),
            Tok::Op(c) => format!("`{c}`"),
            Tok::End => "end of expression".to_string(),
        }
    }

    fn error_at(&mut self, code: DiagnosticCode, col: u32, message: String) {
        self.diags
            .push(Diagnostic::new(code, self.cx.line, col, message).with_label(self.cx.label));
    }

    fn syntax_error(&mut self, message: String) {
        let col = self.col();
        self.error_at(DiagnosticCode::ExpressionSyntax, col, message);
    }

    /// Enters one nesting level; `false` (with an error) beyond [`MAX_NESTING`].
    fn enter(&mut self) -> bool {
        self.nest += 1;
        if self.nest > MAX_NESTING {
            let col = self.col();
            self.error_at(
                DiagnosticCode::ExpressionTooDeep,
                col,
                format!("expression nested deeper than {MAX_NESTING} levels"),
            );
            return false;
        }
        true
    }

    /// Combines subtree depths, rejecting trees deeper than [`MAX_NESTING`].
    fn depth(&mut self, d: usize, col: u32) -> Option<usize> {
        if d > MAX_NESTING {
            self.error_at(
                DiagnosticCode::ExpressionTooDeep,
                col,
                format!("expression nested deeper than {MAX_NESTING} levels"),
            );
            return None;
        }
        Some(d)
    }

    fn expr(&mut self) -> Option<(Expr, usize)> {
        if !self.enter() {
            return None;
        }
        let r = self.expr_inner();
        self.nest -= 1;
        r
    }

    fn expr_inner(&mut self) -> Option<(Expr, usize)> {
        let (mut e, mut d) = self.term()?;
        loop {
            let op = match self.peek() {
                Tok::Op('+') => BinOp::Add,
                Tok::Op('-') => BinOp::Sub,
                _ => return Some((e, d)),
            };
            let col = self.col();
            self.bump();
            let (rhs, rd) = self.term()?;
            d = self.depth(1 + d.max(rd), col)?;
            e = Expr::Binary(op, Box::new(e), Box::new(rhs));
        }
    }

    fn term(&mut self) -> Option<(Expr, usize)> {
        let (mut e, mut d) = self.unary()?;
        loop {
            let op = match self.peek() {
                Tok::Op('*') => BinOp::Mul,
                Tok::Op('/') => BinOp::Div,
                _ => return Some((e, d)),
            };
            let col = self.col();
            self.bump();
            let (rhs, rd) = self.unary()?;
            d = self.depth(1 + d.max(rd), col)?;
            e = Expr::Binary(op, Box::new(e), Box::new(rhs));
        }
    }

    fn unary(&mut self) -> Option<(Expr, usize)> {
        match self.peek() {
            Tok::Op('-') => {
                let col = self.col();
                self.bump();
                if let Tok::Num(v) = *self.peek() {
                    self.bump();
                    return Some((Expr::Num(-v), 1));
                }
                if !self.enter() {
                    return None;
                }
                let r = self.unary();
                self.nest -= 1;
                let (e, d) = r?;
                let d = self.depth(d + 1, col)?;
                Some((Expr::Neg(Box::new(e)), d))
            }
            Tok::Op('+') => {
                self.bump();
                if !self.enter() {
                    return None;
                }
                let r = self.unary();
                self.nest -= 1;
                r
            }
            _ => self.primary(),
        }
    }

    fn primary(&mut self) -> Option<(Expr, usize)> {
        let col = self.col();
        match self.peek().clone() {
            Tok::Num(v) => {
                self.bump();
                Some((Expr::Num(v), 1))
            }
            Tok::Op('(') => {
                self.bump();
                let e = self.expr()?;
                if self.peek() != &Tok::Op(')') {
                    let found = self.describe_current();
                    self.syntax_error(format!("expected `)`, found {found}"));
                    return None;
                }
                self.bump();
                Some(e)
            }
            Tok::Ident(name) => {
                self.bump();
                if self.peek() == &Tok::Op('(') {
                    self.call(name, col)
                } else {
                    self.name(&name, col);
                    Some((Expr::Name(name.into()), 1))
                }
            }
            _ => {
                let found = self.describe_current();
                self.syntax_error(format!("expected a number, a name or `(`, found {found}"));
                None
            }
        }
    }

    /// Resolves a name that is not called (spec §3.5).
    fn name(&mut self, name: &str, col: u32) {
        match (name, self.cx.auto) {
            ("auto", Some(true)) => return,
            ("auto", Some(false)) => {
                self.failed = true;
                self.error_at(
                    DiagnosticCode::UndefinedName,
                    col,
                    "`auto` is the endpoints' distance at stage 0: it stands only in a rest \
                     length L, a contact distance D or a bubble's radius R"
                        .to_string(),
                );
                return;
            }
            _ => {}
        }
        if Func::from_name(name).is_some() {
            self.failed = true;
            self.error_at(
                DiagnosticCode::FunctionWithoutCall,
                col,
                format!("function `{name}` used without a call; write `{name}(…)`"),
            );
            return;
        }
        match self.cx.symbols.get(name).map(|s| s.kind) {
            Some(SymKind::Param | SymKind::Unknown) => {}
            Some(other) => {
                self.failed = true;
                self.diags.push(
                    Diagnostic::new(
                        DiagnosticCode::NotAParameter,
                        self.cx.line,
                        col,
                        format!("`{name}` is {}, not a parameter", other.describe()),
                    )
                    .with_label(self.cx.label)
                    .with_expected("a parameter name")
                    .with_found(name),
                );
            }
            None => {
                self.failed = true;
                self.diags.push(
                    Diagnostic::new(
                        DiagnosticCode::UndefinedName,
                        self.cx.line,
                        col,
                        format!("undefined name `{name}`"),
                    )
                    .with_label(self.cx.label)
                    .with_expected("a declared param or audioParam")
                    .with_found(name),
                );
            }
        }
    }

    fn call(&mut self, name: String, col: u32) -> Option<(Expr, usize)> {
        // At `(`.
        if !self.enter() {
            return None;
        }
        let r = self.call_inner(name, col);
        self.nest -= 1;
        r
    }

    fn call_inner(&mut self, name: String, col: u32) -> Option<(Expr, usize)> {
        self.bump();
        let mut args = Vec::new();
        let mut d = 0;
        if self.peek() == &Tok::Op(')') {
            self.bump();
        } else {
            loop {
                let (a, ad) = self.expr()?;
                d = d.max(ad);
                args.push(a);
                match self.peek() {
                    Tok::Op(',') => self.bump(),
                    Tok::Op(')') => {
                        self.bump();
                        break;
                    }
                    _ => {
                        let found = self.describe_current();
                        self.syntax_error(format!(
                            "expected `,` or `)` in the call of `{name}`, found {found}"
                        ));
                        return None;
                    }
                }
            }
        }
        let d = self.depth(d + 1, col)?;
        let Some(func) = Func::from_name(&name) else {
            self.failed = true;
            let list: Vec<&str> = Func::ALL.iter().map(|f| f.name()).collect();
            self.diags.push(
                Diagnostic::new(
                    DiagnosticCode::UndefinedName,
                    self.cx.line,
                    col,
                    format!("undefined function `{name}`"),
                )
                .with_label(self.cx.label)
                .with_expected(format!("one of {}", list.join(", ")))
                .with_found(name),
            );
            return Some((Expr::Num(f64::NAN), d));
        };
        if args.len() != func.arity() {
            self.failed = true;
            self.diags.push(
                Diagnostic::new(
                    DiagnosticCode::WrongArity,
                    self.cx.line,
                    col,
                    format!(
                        "`{name}` takes {} argument{}, found {}",
                        func.arity(),
                        if func.arity() == 1 { "" } else { "s" },
                        args.len()
                    ),
                )
                .with_label(self.cx.label)
                .with_expected(func.arity().to_string())
                .with_found(args.len().to_string()),
            );
        }
        Some((Expr::Call(func, args.into_boxed_slice()), d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lang::symbols::Symbol;

    fn parse(s: &str) -> (Option<Expr>, Vec<Diagnostic>) {
        let mut symbols = Symbols::default();
        for n in ["a", "b", "kScale"] {
            symbols.insert(
                n.to_string(),
                Symbol {
                    kind: SymKind::Param,
                    line: 1,
                    col: 1,
                    generated: false,
                },
            );
        }
        let cx = ExprContext {
            symbols: &symbols,
            line: 1,
            label: None,
            auto: None,
        };
        let mut d = Diags::default();
        let e = parse_expression(s, 1, &cx, &mut d);
        (e, d.finish())
    }

    #[test]
    fn precedence_and_folding() {
        let (e, d) = parse("1 + 2*-a - -3");
        assert!(d.is_empty(), "{d:?}");
        assert_eq!(e.unwrap().to_string(), "1 + 2*-a - -3");
        assert_eq!(parse("-0.2").0, Some(Expr::Num(-0.2)));
        assert_eq!(parse("-(2)").0, Some(Expr::Neg(Box::new(Expr::Num(2.0)))));
        assert_eq!(parse("+.5e+1").0, Some(Expr::Num(5.0)));
        assert_eq!(parse("1.").0, Some(Expr::Num(1.0)));
    }

    #[test]
    fn errors() {
        let (_, d) = parse("a + kScale3");
        assert_eq!(d[0].code, DiagnosticCode::UndefinedName);
        assert_eq!(d[0].col, 5);
        assert_eq!(parse("sqrt").1[0].code, DiagnosticCode::FunctionWithoutCall);
        assert_eq!(parse("pow(a)").1[0].code, DiagnosticCode::WrongArity);
        assert_eq!(parse("floor(a)").1[0].code, DiagnosticCode::UndefinedName);
        assert_eq!(parse("pi").1[0].code, DiagnosticCode::UndefinedName);
        assert_eq!(parse("1e999").1[0].code, DiagnosticCode::NonFiniteNumber);
        assert_eq!(parse("40abc").1[0].code, DiagnosticCode::InvalidNumber);
        assert_eq!(parse("(a").1[0].code, DiagnosticCode::ExpressionSyntax);
        let deep = "(".repeat(5000) + "1" + &")".repeat(5000);
        assert_eq!(parse(&deep).1[0].code, DiagnosticCode::ExpressionTooDeep);
        let long = vec!["1"; 5000].join("-");
        assert_eq!(parse(&long).1[0].code, DiagnosticCode::ExpressionTooDeep);
        let unary = "-".repeat(5000) + "a";
        assert_eq!(parse(&unary).1[0].code, DiagnosticCode::ExpressionTooDeep);
    }
}
