//! Commands, directives and semantic checks of the model language (spec §3).
//!
//! The script is read in two passes over its lines. The first collects every label (spec §3.4:
//! names and elements may be used before their declaration line) and reports duplicates; the
//! second builds parameters and elements in script order, resolving names, endpoints and buffer
//! scopes. Every problem is reported with its line and column, and parsing goes on after errors
//! (spec §3.12 f).

use super::diagnostics::{Diagnostic, DiagnosticCode, Diags};
use super::expr_parser::{
    is_identifier, parse_expression, token_number_literal, ExprContext, SymKind, Symbol, Symbols,
};
use super::generate::{self, GenRequest, Read, MAX_GENERATED_ELEMENTS};
use super::legacy;
use super::lexer::{is_blank, split_items, split_lines, tokenize, TokKind, Token};
use super::Parsed;
use crate::expr::Expr;
use crate::spec::{
    Element, ElementKind, Endpoint, Law, MacroKind, MacroRange, MacroSpec, ModelSpec, Route,
    RouteSource, SampleRateMode, Span, Vector,
};
use std::collections::HashMap;

mod params;

/// The most nodes one macro may have: 1 048 576 (the compiler's point limit).
pub const MAX_MACRO_NODES: u64 = 1 << 20;

/// The most buffer scopes open at once (§3.10). Every element records the open scopes, so this
/// bounds memory on absurd input; real scripts open a handful.
pub const MAX_OPEN_SCOPES: usize = 64;

/// The interaction laws, before their arguments are known.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LawKind {
    Spring,
    Damper,
    SpringDamper,
    Contact,
    NlContact,
    NlSpring2,
    NlSpring3,
    NlSpringDamper,
    NlPluck,
    NlBow,
}

/// The argument shape a type keyword selects (spec §3.4, §2.9).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Shape {
    Mass,
    Osc,
    Ground,
    MassG,
    Law(LawKind),
    Macro(MacroKind),
    PosInput,
    FrcInput,
    PosOutput,
    FrcOutput,
    Param,
    AudioParam,
}

/// Every type keyword of spec §2.9, with the legacy aliases of §3.12 a.
const KEYWORDS: [(&str, Shape); 27] = [
    ("mass", Shape::Mass),
    ("osc", Shape::Osc),
    ("ground", Shape::Ground),
    ("massG", Shape::MassG),
    ("spring", Shape::Law(LawKind::Spring)),
    ("damper", Shape::Law(LawKind::Damper)),
    ("springDamper", Shape::Law(LawKind::SpringDamper)),
    ("contact", Shape::Law(LawKind::Contact)),
    ("nlContact", Shape::Law(LawKind::NlContact)),
    ("nlSpring2", Shape::Law(LawKind::NlSpring2)),
    ("nlSpring", Shape::Law(LawKind::NlSpring2)),
    ("nlSpring3", Shape::Law(LawKind::NlSpring3)),
    ("nlSpringDamper", Shape::Law(LawKind::NlSpringDamper)),
    ("nlPluck", Shape::Law(LawKind::NlPluck)),
    ("nlBow", Shape::Law(LawKind::NlBow)),
    ("string", Shape::Macro(MacroKind::String)),
    ("chain", Shape::Macro(MacroKind::Chain)),
    ("stiffString", Shape::Macro(MacroKind::StiffString)),
    ("mesh", Shape::Macro(MacroKind::Mesh)),
    ("cornerMesh", Shape::Macro(MacroKind::CornerMesh)),
    ("closedMesh", Shape::Macro(MacroKind::ClosedMesh)),
    ("posInput", Shape::PosInput),
    ("frcInput", Shape::FrcInput),
    ("posOutput", Shape::PosOutput),
    ("frcOutput", Shape::FrcOutput),
    ("param", Shape::Param),
    ("audioParam", Shape::AudioParam),
];

fn shape_of(keyword: &str) -> Option<Shape> {
    KEYWORDS
        .iter()
        .find(|(k, _)| *k == keyword)
        .map(|(_, s)| *s)
}

/// [`shape_of`] a token's text, without making a string of it.
fn shape_of_chars(keyword: &[char]) -> Option<Shape> {
    KEYWORDS
        .iter()
        .find(|(k, _)| k.len() == keyword.len() && k.chars().eq(keyword.iter().copied()))
        .map(|(_, s)| *s)
}

/// The accepted argument counts (after the keyword) and the signature for messages (§2.9).
fn arity(shape: Shape) -> (usize, usize, &'static str) {
    use LawKind as L;
    match shape {
        Shape::Mass => (3, 4, "M {gravity} pos vel"),
        Shape::Osc => (5, 6, "M K Z {gravity} pos vel"),
        Shape::Ground => (1, 1, "pos"),
        Shape::MassG => (4, 4, "M G X0 XR0"),
        Shape::Law(L::Spring) => (3, 4, "m1 m2 K {Z}"),
        Shape::Law(L::Damper) => (3, 3, "m1 m2 Z"),
        Shape::Law(L::SpringDamper) => (4, 4, "m1 m2 K Z"),
        Shape::Law(L::Contact) => (4, 5, "m1 m2 K Z {thresh}"),
        Shape::Law(L::NlContact) => (6, 7, "m1 m2 K KnlQ Klim Z {thresh}"),
        Shape::Law(L::NlSpring2) => (5, 5, "m1 m2 K KnlP Z"),
        Shape::Law(L::NlSpring3) => (5, 5, "m1 m2 K KnlQ Z"),
        Shape::Law(L::NlSpringDamper) => (6, 6, "m1 m2 K KnlQ Klim Z"),
        Shape::Law(L::NlPluck) => (4, 5, "m1 m2 Knl Pscale {Z}"),
        Shape::Law(L::NlBow) => (4, 5, "m1 m2 Znl Vscale {smooth}"),
        Shape::Macro(MacroKind::String | MacroKind::Chain) => (6, 7, "nbMass M K Z {Zo} pos vel"),
        Shape::Macro(MacroKind::StiffString) => (7, 8, "nbMass M K K2 Z {Zo} pos vel"),
        Shape::Macro(_) => (7, 8, "nbX nbY M K Z {Zo} pos vel"),
        Shape::PosInput => (1, 1, "pos"),
        Shape::FrcInput | Shape::PosOutput | Shape::FrcOutput => (1, 1, "target"),
        Shape::Param => (1, 1, "value"),
        Shape::AudioParam => (1, 2, "@inN {default}"),
    }
}

fn sym_kind(shape: Shape) -> SymKind {
    match shape {
        Shape::Mass | Shape::Osc | Shape::Ground | Shape::MassG | Shape::PosInput => SymKind::Point,
        Shape::Law(_) => SymKind::Interaction,
        Shape::Macro(k) => SymKind::Macro {
            dims: if k.is_2d() { 2 } else { 1 },
        },
        Shape::FrcInput => SymKind::FrcInput,
        Shape::PosOutput | Shape::FrcOutput => SymKind::Output,
        Shape::Param | Shape::AudioParam => SymKind::Param,
    }
}

/// A command or directive line, tokenised.
struct Item<'a> {
    line: u32,
    directive: bool,
    /// A command line with a lexical error: only its label token is kept, for pass 1.
    broken: bool,
    tokens: Vec<Token<'a>>,
    /// A `~generate` directive read in pass 1 and expanded in pass 2.
    generator: Option<Box<GenRequest>>,
    /// The name of a `~generate` line with a lexical error: its labels are unknown.
    broken_generator: Option<String>,
}

fn is_generate(item: &Item) -> bool {
    item.directive && item.tokens.first().is_some_and(|t| *t.text == GENERATE)
}

const GENERATE: [char; 9] = ['~', 'g', 'e', 'n', 'e', 'r', 'a', 't', 'e'];

/// Parses script text (spec §3). See [`Parsed`].
pub fn parse(text: &str) -> Parsed {
    parse_with(text, Diags::default())
}

/// Parses script bytes: invalid UTF-8 is reported with its line and column (each invalid
/// sequence reads as one U+FFFD character), and the rest is parsed as text (spec §3.12 f).
pub fn parse_bytes(bytes: &[u8]) -> Parsed {
    if let Ok(text) = std::str::from_utf8(bytes) {
        return parse_with(text, Diags::default());
    }
    let mut diags = Diags::default();
    let mut text = String::with_capacity(bytes.len());
    let mut pos = Position::default();
    for chunk in bytes.utf8_chunks() {
        let valid = chunk.valid();
        text.push_str(valid);
        let invalid = chunk.invalid();
        if !invalid.is_empty() {
            valid.chars().for_each(|c| pos.advance(c));
            let hex: Vec<String> = invalid.iter().map(|b| format!("{b:02X}")).collect();
            diags.push(
                Diagnostic::new(
                    DiagnosticCode::InvalidUtf8,
                    pos.line,
                    pos.col,
                    format!("invalid UTF-8 byte sequence {}", hex.join(" ")),
                )
                .with_expected("UTF-8 text")
                .with_found(hex.join(" ")),
            );
            text.push('\u{FFFD}');
            pos.advance('\u{FFFD}');
        }
    }
    parse_with(&text, diags)
}

/// A running 1-based line and column, with the line breaks of spec §3.2 (CR LF, CR, LF).
struct Position {
    line: u32,
    col: u32,
    prev_cr: bool,
}

impl Default for Position {
    fn default() -> Self {
        Position {
            line: 1,
            col: 1,
            prev_cr: false,
        }
    }
}

impl Position {
    fn advance(&mut self, c: char) {
        match c {
            '\n' if self.prev_cr => self.prev_cr = false,
            '\n' | '\r' => {
                self.line = self.line.saturating_add(1);
                self.col = 1;
                self.prev_cr = c == '\r';
            }
            _ => {
                self.col = self.col.saturating_add(1);
                self.prev_cr = false;
            }
        }
    }
}

fn parse_with(text: &str, mut diags: Diags) -> Parsed {
    // Every line's characters in one buffer, which the tokens borrow.
    let mut buffer: Vec<char> = Vec::with_capacity(text.len());
    let mut lines = Vec::new();
    for (line, s) in split_lines(text) {
        let start = buffer.len();
        buffer.extend(s.chars());
        lines.push((line, start..buffer.len()));
    }
    let mut items = Vec::with_capacity(lines.len());
    for (line, range) in lines {
        let chars = buffer.get(range).unwrap_or(&[]);
        let Some(first) = chars.iter().position(|c| !is_blank(*c)) else {
            continue;
        };
        match chars.get(first) {
            Some('@') | Some('~') => {
                let directive = chars.get(first) == Some(&'~');
                match tokenize(chars, line, &mut diags) {
                    Some(tokens) => items.push(Item {
                        line,
                        directive,
                        broken: false,
                        tokens,
                        generator: None,
                        broken_generator: None,
                    }),
                    None if !directive => {
                        // Keep the label known so references to it do not cascade: the line
                        // takes part in pass 1 with its label only (kind unknown).
                        let rest = chars.get(first..).unwrap_or(&[]);
                        let len = rest
                            .iter()
                            .take_while(|c| {
                                !is_blank(**c) && !matches!(c, '+' | '[' | ']' | '\'' | '#')
                            })
                            .count();
                        let label = rest.get(..len).unwrap_or(&[]);
                        items.push(Item {
                            line,
                            directive: false,
                            broken: true,
                            tokens: vec![Token {
                                kind: TokKind::Bare,
                                text: label,
                                col: col_of(first),
                                inner_col: col_of(first),
                            }],
                            generator: None,
                            broken_generator: None,
                        });
                    }
                    None => {
                        // A `~generate` line with a lexical error: its labels are unknown, so
                        // references to them must not cascade.
                        let text: String = chars.iter().skip(first).collect();
                        let words: Vec<&str> = text
                            .split(is_blank)
                            .filter(|w| !w.is_empty())
                            .take(3)
                            .collect();
                        if let Some(name) = generate::broken_name(&words) {
                            items.push(Item {
                                line,
                                directive: true,
                                broken: true,
                                tokens: Vec::new(),
                                generator: None,
                                broken_generator: Some(name),
                            });
                        }
                    }
                }
            }
            Some('#') => {}
            _ => check_ignored_line(chars, line, &mut diags),
        }
    }

    // Pass 1: labels (spec §3.4), including those `~generate` creates (§4).
    let mut symbols = Symbols::with_capacity(items.len());
    let mut budget = MAX_GENERATED_ELEMENTS;
    for item in items.iter_mut() {
        if item.directive {
            if let Some(name) = item.broken_generator.take() {
                symbols.insert_broken_generator(name);
            } else if is_generate(item) {
                match generate::read(&item.tokens, item.line, &mut diags, &mut budget) {
                    Read::Ready(req) => {
                        if declare_generated(&req, &mut symbols, &mut diags) {
                            item.generator = Some(req);
                        }
                    }
                    Read::Broken { name: Some(name) } => symbols.insert_broken_generator(name),
                    Read::Broken { name: None } => {}
                }
            }
            continue;
        }
        let Some(first) = item.tokens.first() else {
            continue;
        };
        let label: String = first.text.iter().skip(1).collect();
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
        let kind = item
            .tokens
            .get(1)
            .filter(|t| t.kind != TokKind::Bracket)
            .and_then(|t| shape_of_chars(t.text))
            .map(sym_kind)
            .unwrap_or(SymKind::Unknown);
        if let Some(prev) = symbols.declared(&label) {
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
            continue;
        }
        let symbol = Symbol {
            kind,
            line: item.line,
            col: first.col,
            generated: false,
        };
        symbols.insert(label, symbol);
    }

    // Pass 2: directives and commands in script order.
    let mut b = Builder {
        diags,
        symbols: &symbols,
        spec: ModelSpec {
            elements: Vec::with_capacity(items.len()),
            ..ModelSpec::default()
        },
        open: Vec::new(),
        buffer_ids: HashMap::new(),
        samplerate: None,
    };
    for item in items.iter().filter(|i| !i.broken) {
        if let Some(req) = &item.generator {
            b.generate(req);
        } else if is_generate(item) {
            // Reported in pass 1.
        } else if item.directive {
            b.directive(item);
        } else {
            b.command(item);
        }
    }
    let Builder {
        diags,
        mut spec,
        samplerate,
        ..
    } = b;
    if let Some((mode, _)) = samplerate {
        spec.sample_rate_mode = mode;
    }
    let ok = diags.error_count() == 0;
    Parsed {
        spec: ok.then_some(spec),
        diagnostics: diags.finish(),
    }
}

/// The highest model input a host directive may name.
const MAX_HOST_INPUT: u32 = 64;

fn plural_args(count: &[usize]) -> String {
    match count {
        [1] => "one argument".into(),
        [n] => format!("{n} arguments"),
        [a, b] => format!("{a} or {b} arguments"),
        _ => "arguments".into(),
    }
}

/// Declares the labels a `~generate` directive creates (pass 1). A clash with a label declared
/// earlier is reported once, at the generator's name; the directive is then not expanded.
/// Returns true when every label was free.
fn declare_generated(req: &GenRequest, symbols: &mut Symbols, diags: &mut Diags) -> bool {
    let plan = match crate::generators::plan(&req.name, &req.topology) {
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

fn col_of(i: usize) -> u32 {
    u32::try_from(i.saturating_add(1)).unwrap_or(u32::MAX)
}

/// Warns when an ignored line looks like a command with a forgotten `@` (spec §3.2): its first
/// word is a type keyword (`mass 1 0 0`), or its second word is one after a label-like first
/// word (`m mass 1 0 0`).
fn check_ignored_line(chars: &[char], line: u32, diags: &mut Diags) {
    let mut words: Vec<(usize, String)> = Vec::new();
    let mut i = 0;
    while words.len() < 2 {
        while chars.get(i).is_some_and(|c| is_blank(*c)) {
            i += 1;
        }
        let start = i;
        while chars.get(i).is_some_and(|c| !is_blank(*c) && *c != '#') {
            i += 1;
        }
        if i == start {
            break;
        }
        words.push((start, chars.get(start..i).unwrap_or(&[]).iter().collect()));
        if chars.get(i) == Some(&'#') {
            break;
        }
    }
    let hit = match words.as_slice() {
        [(c, w), ..] if shape_of(w).is_some() => Some((*c, w.clone(), false)),
        [(c, l), (_, w)]
            if shape_of(w).is_some() && l.chars().all(|c| c.is_alphanumeric() || c == '_') =>
        {
            Some((*c, w.clone(), true))
        }
        _ => None,
    };
    if let Some((c, keyword, has_label)) = hit {
        let message = if has_label {
            format!("line ignored: it looks like a `{keyword}` command whose label lacks `@`")
        } else {
            format!(
                "line ignored: it starts with the type keyword `{keyword}`; commands start \
                 with `@label`"
            )
        };
        diags.push(
            Diagnostic::new(DiagnosticCode::IgnoredCommandLike, line, col_of(c), message)
                .with_expected("@label keyword arguments…"),
        );
    }
}

/// A legacy trailing buffer tag `NAME x y` (spec §6.4).
struct Tag {
    name: String,
    x: f64,
    y: f64,
}

struct Builder<'s> {
    diags: Diags,
    symbols: &'s Symbols,
    spec: ModelSpec,
    /// Open scopes, in order of opening (indices into `spec.buffers`).
    open: Vec<u32>,
    /// `spec.buffers` by name.
    buffer_ids: HashMap<String, u32>,
    samplerate: Option<(SampleRateMode, u32)>,
}

/// Where a command stands, for diagnostics.
#[derive(Clone, Copy)]
struct At<'a> {
    line: u32,
    label: Option<&'a str>,
}

impl At<'_> {
    fn diag(&self, code: DiagnosticCode, col: u32, message: impl Into<String>) -> Diagnostic {
        Diagnostic::new(code, self.line, col, message).with_label(self.label)
    }
}

impl Builder<'_> {
    fn buffer_index(&mut self, name: &str) -> u32 {
        if let Some(&i) = self.buffer_ids.get(name) {
            return i;
        }
        let i = u32::try_from(self.spec.buffers.len()).unwrap_or(u32::MAX);
        self.spec.buffers.push(name.to_string());
        self.buffer_ids.insert(name.to_string(), i);
        i
    }

    /// Expands a `~generate` directive at its place in script order (spec §4): its parameters
    /// and elements join the spec, its points the open scopes.
    fn generate(&mut self, req: &GenRequest) {
        if let Some((params, elements)) = generate::expand(
            req,
            self.symbols,
            &self.spec.params,
            &self.open,
            &mut self.diags,
        ) {
            self.spec.params.extend(params);
            self.spec.elements.extend(elements);
        }
    }

    /// `~begin`, `~end`, `~samplerate` (spec §3.10, §3.11).
    fn directive(&mut self, item: &Item) {
        let Some(first) = item.tokens.first() else {
            return;
        };
        let name: String = first.text.iter().skip(1).collect();
        let args = item.tokens.get(1..).unwrap_or(&[]);
        let at = At {
            line: item.line,
            label: None,
        };
        if matches!(name.as_str(), "pitch" | "key" | "note" | "route" | "macro") {
            self.host_directive(item, &name, first.col, args);
            return;
        }
        let expected = match name.as_str() {
            "begin" | "end" => "a buffer name (an identifier)",
            "samplerate" => "`raw` or `scaled`",
            _ => {
                self.diags.push(
                    at.diag(
                        DiagnosticCode::UnknownDirective,
                        first.col,
                        format!("unknown directive `~{name}` ignored"),
                    )
                    .with_expected(
                        "~begin, ~end, ~samplerate, ~generate, ~pitch, ~key, ~note, ~route or ~macro",
                    )
                    .with_found(format!("~{name}")),
                );
                return;
            }
        };
        let arg = match args {
            [a] if a.kind == TokKind::Bare => a,
            [] => {
                self.diags.push(
                    at.diag(
                        DiagnosticCode::InvalidDirectiveArgument,
                        first.col,
                        format!("`~{name}` needs one argument"),
                    )
                    .with_expected(expected),
                );
                return;
            }
            [a, ..] => {
                let bad = if a.kind == TokKind::Bare {
                    args.get(1).unwrap_or(a)
                } else {
                    a
                };
                self.diags.push(
                    at.diag(
                        DiagnosticCode::InvalidDirectiveArgument,
                        bad.col,
                        format!("`~{name}` takes exactly one argument"),
                    )
                    .with_expected(expected)
                    .with_found(bad.source()),
                );
                return;
            }
        };
        let value = arg.string();
        if name == "samplerate" {
            let mode = match value.as_str() {
                "raw" => SampleRateMode::Raw,
                "scaled" => SampleRateMode::Scaled,
                _ => {
                    self.diags.push(
                        at.diag(
                            DiagnosticCode::InvalidDirectiveArgument,
                            arg.col,
                            format!("unknown sample-rate mode `{value}`"),
                        )
                        .with_expected(expected)
                        .with_found(value),
                    );
                    return;
                }
            };
            match self.samplerate {
                Some((prev, line)) if prev != mode => self.diags.push(
                    at.diag(
                        DiagnosticCode::ConflictingDirective,
                        arg.col,
                        format!(
                            "`~samplerate {value}` conflicts with the `~samplerate` at line {line}"
                        ),
                    )
                    .with_found(value),
                ),
                Some(_) => {}
                None => self.samplerate = Some((mode, item.line)),
            }
            return;
        }
        if !is_identifier(&value) {
            self.diags.push(
                at.diag(
                    DiagnosticCode::InvalidDirectiveArgument,
                    arg.col,
                    format!("buffer name `{value}` is not an identifier"),
                )
                .with_expected(expected)
                .with_found(value),
            );
            return;
        }
        if name == "begin" {
            if self.open.len() >= MAX_OPEN_SCOPES {
                self.diags.push(
                    at.diag(
                        DiagnosticCode::TooLarge,
                        first.col,
                        format!("more than {MAX_OPEN_SCOPES} buffer scopes open at once"),
                    )
                    .with_found(value),
                );
                return;
            }
            let id = self.buffer_index(&value);
            if self.open.contains(&id) {
                self.diags.push(at.diag(
                    DiagnosticCode::ScopeAlreadyOpen,
                    first.col,
                    format!("`~begin {value}`: the scope `{value}` is already open"),
                ));
            } else {
                self.open.push(id);
            }
        } else {
            let id = self.buffer_ids.get(&value).copied();
            let pos = id.and_then(|id| self.open.iter().position(|&o| o == id));
            match pos {
                Some(p) => {
                    self.open.remove(p);
                }
                None => self.diags.push(at.diag(
                    DiagnosticCode::ScopeNotOpen,
                    first.col,
                    format!("`~end {value}`: the scope `{value}` is not open"),
                )),
            }
        }
    }

    /// The host directives: `~pitch HZ`, `~key NOTE`, `~note inK [FORCE]`,
    /// `~route inK SOURCE`, `~macro NAME MIN MAX`. They tell a host how to play the model;
    /// the engine ignores them.
    fn host_directive(&mut self, item: &Item, name: &str, col: u32, args: &[Token]) {
        let at = At {
            line: item.line,
            label: None,
        };
        let (expected, count): (&str, &[usize]) = match name {
            "pitch" => ("a frequency in Hz (a positive number)", &[1]),
            "key" => ("a MIDI key number, 0 to 127", &[1]),
            "note" => ("an input (`in1`…) and optionally the force of a full-velocity note", &[1, 2]),
            "route" => (
                "an input (`in1`…) and main_left, main_right, sidechain_left, sidechain_right or none",
                &[2],
            ),
            _ => ("a param name, then its minimum and maximum", &[3]),
        };
        let bad = |diags: &mut Diags, col: u32, message: String, found: Option<String>| {
            let mut d = at
                .diag(DiagnosticCode::InvalidDirectiveArgument, col, message)
                .with_expected(expected);
            if let Some(f) = found {
                d = d.with_found(f);
            }
            diags.push(d);
        };
        if !count.contains(&args.len()) || args.iter().any(|a| a.kind != TokKind::Bare) {
            let at_col = args
                .iter()
                .find(|a| a.kind != TokKind::Bare)
                .or(args.get(count.iter().copied().max().unwrap_or(1)))
                .map(|a| a.col)
                .unwrap_or(col);
            bad(
                &mut self.diags,
                at_col,
                format!("`~{name}` takes {}", plural_args(count)),
                None,
            );
            return;
        }
        let number =
            |t: &Token| -> Option<f64> { t.string().parse::<f64>().ok().filter(|v| v.is_finite()) };
        let input = |t: &Token| -> Option<u32> {
            let s = t.string();
            let digits = s.strip_prefix("in")?;
            if digits.starts_with('0') || digits.is_empty() {
                return None;
            }
            digits
                .parse::<u32>()
                .ok()
                .filter(|k| (1..=MAX_HOST_INPUT).contains(k))
        };
        let conflict = |diags: &mut Diags, what: &str| {
            diags.push(at.diag(
                DiagnosticCode::ConflictingDirective,
                col,
                format!("a second `~{name}` for {what}"),
            ));
        };
        // `~note` and `~route` start with an input.
        let k = if matches!(name, "note" | "route") {
            let Some(k) = input(&args[0]) else {
                bad(
                    &mut self.diags,
                    args[0].col,
                    format!("`{}` is not an input", args[0].source()),
                    Some(args[0].source()),
                );
                return;
            };
            k
        } else {
            0
        };
        let host = &mut self.spec.host;
        match name {
            "pitch" => match number(&args[0]).filter(|v| *v > 0.0) {
                Some(v) if host.pitch_hz.is_none() => host.pitch_hz = Some(v),
                Some(_) => conflict(&mut self.diags, "the model"),
                None => bad(
                    &mut self.diags,
                    args[0].col,
                    "the pitch must be a positive number of Hz".into(),
                    Some(args[0].source()),
                ),
            },
            "key" => match number(&args[0]).filter(|v| (0.0..=127.0).contains(v)) {
                Some(v) if host.key.is_none() => host.key = Some(v),
                Some(_) => conflict(&mut self.diags, "the model"),
                None => bad(
                    &mut self.diags,
                    args[0].col,
                    "the key must be a MIDI key number from 0 to 127".into(),
                    Some(args[0].source()),
                ),
            },
            "note" => {
                let force = match args.get(1) {
                    Some(t) => match number(t) {
                        Some(v) => Some(v),
                        None => {
                            bad(
                                &mut self.diags,
                                t.col,
                                "the note force must be a number".into(),
                                Some(t.source()),
                            );
                            return;
                        }
                    },
                    None => None,
                };
                if host.note_input.is_some() {
                    conflict(&mut self.diags, "the model");
                    return;
                }
                host.note_input = Some(k);
                host.note_force = force;
            }
            "route" => {
                let Some(source) = RouteSource::from_name(&args[1].string()) else {
                    bad(
                        &mut self.diags,
                        args[1].col,
                        format!("unknown input source `{}`", args[1].source()),
                        Some(args[1].source()),
                    );
                    return;
                };
                if host.routes.iter().any(|r| r.input == k) {
                    conflict(&mut self.diags, &format!("in{k}"));
                    return;
                }
                host.routes.push(Route { input: k, source });
            }
            _ => {
                let param = args[0].string();
                let (Some(min), Some(max)) = (number(&args[1]), number(&args[2])) else {
                    let t = if number(&args[1]).is_none() {
                        &args[1]
                    } else {
                        &args[2]
                    };
                    bad(
                        &mut self.diags,
                        t.col,
                        "the range must be two finite numbers".into(),
                        Some(t.source()),
                    );
                    return;
                };
                let is_param = self
                    .symbols
                    .get(&param)
                    .is_some_and(|p| matches!(p.kind, SymKind::Param));
                if !is_param {
                    self.diags.push(
                        at.diag(
                            DiagnosticCode::UndefinedName,
                            args[0].col,
                            format!("`~macro {param}`: no param `{param}`"),
                        )
                        .with_expected("the name of a `param`")
                        .with_found(param),
                    );
                    return;
                }
                if !(min < max) {
                    bad(
                        &mut self.diags,
                        args[1].col,
                        format!("the range {min} … {max} is empty"),
                        None,
                    );
                    return;
                }
                if host.macro_ranges.iter().any(|r| r.name == param) {
                    conflict(&mut self.diags, &format!("`{param}`"));
                    return;
                }
                host.macro_ranges.push(MacroRange {
                    name: param,
                    min,
                    max,
                });
            }
        }
    }

    fn command(&mut self, item: &Item) {
        let Some(first) = item.tokens.first() else {
            return;
        };
        let label: String = first.text.iter().skip(1).collect();
        if label.is_empty() {
            return; // reported in pass 1
        }
        let at = At {
            line: item.line,
            label: Some(&label),
        };
        let span = Span::new(item.line, first.col);
        let Some(kw) = item.tokens.get(1) else {
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
            shape_of_chars(kw.text)
        };
        let Some(shape) = shape else {
            let keyword = kw.string();
            let mut d = at.diag(
                DiagnosticCode::UnknownKeyword,
                kw.col,
                format!("unknown type keyword `{}`", kw.source()),
            );
            if let Some((k, _)) = KEYWORDS
                .iter()
                .find(|(k, _)| k.eq_ignore_ascii_case(&keyword))
            {
                d.message.push_str(&format!(" (did you mean `{k}`?)"));
                d = d.with_expected(format!("`{k}`"));
            }
            self.diags.push(d.with_found(kw.source()));
            return;
        };
        let args = item.tokens.get(2..).unwrap_or(&[]);
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
            label: &label,
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
                if let Some(p) = self.param(shape, &label, first, args, at, span) {
                    self.spec.params.push(p);
                }
                return;
            }
            _ => self.element(shape, &label, first, args, points, at),
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
            label,
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
                    && t.text.first() == Some(&'@')
                    && matches!(
                        self.symbols.get(&t.text.iter().skip(1).collect::<String>()),
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

    fn expr(&mut self, t: &Token, at: At<'_>) -> Option<Expr> {
        let trimmed_first = t.text.iter().find(|c| !is_blank(**c));
        if t.kind == TokKind::Bracket && trimmed_first == Some(&'@') {
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
        if t.kind == TokKind::Bare && t.text.first() == Some(&'@') {
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
        if t.text.iter().all(|c| is_blank(*c)) {
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
        };
        parse_expression(t.text, t.inner_col, &cx, &mut self.diags)
    }

    /// An expression in an item of a vector or connection bracket.
    fn item_expr(&mut self, t: &Token, (s, e): (usize, usize), at: At<'_>) -> Option<Expr> {
        let chars = t.text.get(s..e).unwrap_or(&[]);
        let cx = ExprContext {
            symbols: self.symbols,
            line: at.line,
            label: at.label,
        };
        let col = t
            .inner_col
            .saturating_add(u32::try_from(s).unwrap_or(u32::MAX));
        parse_expression(chars, col, &cx, &mut self.diags)
    }

    /// A position or velocity (spec §3.7): a scalar z, or a bracket `[x y z]` whose items are
    /// space-free tokens or parenthesised expressions. A one-item bracket is a scalar.
    fn vector(&mut self, t: &Token, at: At<'_>) -> Option<Vector> {
        if t.kind != TokKind::Bracket || t.text.iter().find(|c| !is_blank(**c)) == Some(&'@') {
            return self.expr(t, at).map(Vector::Scalar);
        }
        let items = split_items(t.text);
        match items.as_slice() {
            [one] => self.item_expr(t, *one, at).map(Vector::Scalar),
            [x, y, z] => {
                let x = self.item_expr(t, *x, at);
                let y = self.item_expr(t, *y, at);
                let z = self.item_expr(t, *z, at);
                Some(Vector::Xyz([x?, y?, z?]))
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

    /// An endpoint or target (spec §3.4, §2.8): `@label` of a point, or `[@macro α]` /
    /// `[@mesh u w]`.
    fn endpoint(&mut self, t: &Token, at: At<'_>) -> Option<Endpoint> {
        match t.kind {
            TokKind::Bare if t.text.first() == Some(&'@') => {
                let name: String = t.text.iter().skip(1).collect();
                if name.is_empty() {
                    self.diags.push(at.diag(
                        DiagnosticCode::BadLabel,
                        t.col,
                        "missing label after `@`",
                    ));
                    return None;
                }
                let ok = match self.symbols.get(&name).map(|s| s.kind) {
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
                        let example = if dims == 2 {
                            format!("[@{name} u w]")
                        } else {
                            format!("[@{name} α]")
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
                ok.then_some(Endpoint::Label(name))
            }
            TokKind::Bracket if t.text.iter().find(|c| !is_blank(**c)) == Some(&'@') => {
                self.connection_point(t, at)
            }
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
    fn slot_endpoint(
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
        let target = p.target.clone();
        match <[Option<Expr>; 2]>::try_from(coords) {
            Ok([u, w]) => Some(Endpoint::Surface {
                target,
                u: u?,
                w: w?,
            }),
            Err(mut one) => Some(Endpoint::Line {
                target,
                alpha: one.pop()??,
            }),
        }
    }

    fn connection_point(&mut self, t: &Token, at: At<'_>) -> Option<Endpoint> {
        let items = split_items(t.text);
        let &(s, e) = items.first()?;
        let target: String = t.text.get(s + 1..e).unwrap_or(&[]).iter().collect();
        let target_col = t
            .inner_col
            .saturating_add(u32::try_from(s).unwrap_or(u32::MAX));
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
            Some(SymKind::Macro { dims }) if dims != found => {
                let what = if dims == 2 {
                    "a mesh takes 2 coordinates [@mesh u w]"
                } else {
                    "a string, chain or stiff string takes 1 coordinate [@s α]"
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
        if ok && !(found == 1 || found == 2) {
            self.diags.push(
                at.diag(
                    DiagnosticCode::WrongCoordinateCount,
                    t.col,
                    format!(
                        "a connection point has 1 or 2 coordinates, found {found} (an \
                         expression with spaces goes in parentheses)"
                    ),
                )
                .with_expected("1 or 2")
                .with_found(found.to_string()),
            );
            ok = false;
        }
        // Coordinates are parsed only when their count is right: with a wrong count the items
        // are usually pieces of a spaced expression, already explained by the message above.
        let dims_mismatch = matches!(
            self.symbols.get(&target).map(|s| s.kind),
            Some(SymKind::Macro { dims }) if dims != found
        );
        let count_ok = (found == 1 || found == 2) && !dims_mismatch;
        if !count_ok {
            return None;
        }
        let exprs: Vec<Option<Expr>> = coords
            .iter()
            .map(|&range| self.item_expr(t, range, at))
            .collect();
        let exprs: Option<Vec<Expr>> = exprs.into_iter().collect();
        let exprs = exprs?;
        if !ok {
            return None;
        }
        match <[Expr; 1]>::try_from(exprs) {
            Ok([alpha]) => Some(Endpoint::Line { target, alpha }),
            Err(exprs) => match <[Expr; 2]>::try_from(exprs) {
                Ok([u, w]) => Some(Endpoint::Surface { target, u, w }),
                Err(_) => None,
            },
        }
    }

    /// A macro size: an integer literal ≥ 2 (`40` or `40.`; spec §2.7, §3.12 a).
    fn size(&mut self, t: &Token, at: At<'_>) -> Option<u64> {
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

    fn channel(&mut self, label: &str, prefix: &str, t: &Token, at: At<'_>) -> Option<u32> {
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

    /// Builds an element from arguments of an accepted count. `points` are the legacy bare
    /// connection points found in the endpoint slots (see [`legacy::read`]).
    fn element(
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
            Shape::Law(kind) => {
                let a = self.slot_endpoint(args, 0, points, at);
                let b = self.slot_endpoint(args, 1, points, at);
                let params: Vec<Option<Expr>> = args
                    .get(2..)
                    .unwrap_or(&[])
                    .iter()
                    .map(|t| self.expr(t, at))
                    .collect();
                let (a, b) = (a?, b?);
                let mut p: Vec<Expr> = params.into_iter().collect::<Option<Vec<Expr>>>()?;
                // Optional trailing arguments default to 0 (spec §2.9).
                let (_, max, _) = arity(shape);
                p.resize(max - 2, Expr::Num(0.0));
                let law = make_law(kind, n - 2, p)?;
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
                Some(ElementKind::Macro(MacroSpec {
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
                }))
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

/// Builds a law from its parameters (padded with 0 for optional ones); `given` is the number
/// written, which selects the legacy two-parameter `spring` (= springDamper, spec §3.12 a).
fn make_law(kind: LawKind, given: usize, p: Vec<Expr>) -> Option<Law> {
    let mut it = p.into_iter();
    let mut next = || it.next();
    Some(match kind {
        LawKind::Spring if given == 2 => Law::SpringDamper {
            k: next()?,
            z: next()?,
        },
        LawKind::Spring => Law::Spring { k: next()? },
        LawKind::Damper => Law::Damper { z: next()? },
        LawKind::SpringDamper => Law::SpringDamper {
            k: next()?,
            z: next()?,
        },
        LawKind::Contact => Law::Contact {
            k: next()?,
            z: next()?,
            thresh: next()?,
        },
        LawKind::NlContact => Law::NlContact {
            k: next()?,
            q: next()?,
            klim: next()?,
            z: next()?,
            thresh: next()?,
        },
        LawKind::NlSpring2 => Law::NlSpring2 {
            k: next()?,
            q: next()?,
            z: next()?,
        },
        LawKind::NlSpring3 => Law::NlSpring3 {
            k: next()?,
            q: next()?,
            z: next()?,
        },
        LawKind::NlSpringDamper => Law::NlSpringDamper {
            k: next()?,
            q: next()?,
            klim: next()?,
            z: next()?,
        },
        LawKind::NlPluck => Law::NlPluck {
            k: next()?,
            scale: next()?,
            z: next()?,
        },
        LawKind::NlBow => Law::NlBow {
            z: next()?,
            scale: next()?,
            smooth: next()?,
        },
    })
}
