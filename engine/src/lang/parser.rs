//! Commands, directives and semantic checks of the model language (spec §3).
//!
//! The script is read in two passes over its lines. The first collects every label (spec §3.4:
//! names and elements may be used before their declaration line) and reports duplicates; the
//! second builds parameters and elements in script order, resolving names, endpoints and buffer
//! scopes. Every problem is reported with its line and column, and parsing goes on after errors
//! (spec §3.12 f).
//!
//! * `lines`: the script's lines, tokenised into items (commands and directives);
//! * `labels`: pass 1, the labels, those `~generate` creates included;
//! * pass 2, in this file: the `Builder` goes through the items in script order, with
//!   `directives` (`~begin`, `~samplerate`, the host directives), `command` (a command's
//!   keyword, argument count and legacy forms), `elements` and `params` (each element kind's
//!   arguments), `values` (expressions, vectors, sizes, channels) and `endpoints`;
//! * `keywords`: the type keywords and the argument shape each selects.

use super::diagnostics::{Diagnostic, DiagnosticCode, Diags};
use super::generate::{self, GenRequest};
use super::lexer::Token;
use super::symbols::Symbols;
use super::Parsed;
use crate::spec::{ModelSpec, SampleRateMode};
use lines::is_generate;
use std::collections::HashMap;

mod command;
mod directives;
mod elements;
mod endpoints;
mod keywords;
mod labels;
mod lines;
mod params;
mod space;
mod values;

pub use space::labels::Files;

/// The most nodes one macro may have: 1 048 576 (the compiler's point limit).
pub const MAX_MACRO_NODES: u64 = 1 << 20;

/// The most buffer scopes open at once (§3.10). Every element records the open scopes, so this
/// bounds memory on absurd input; real scripts open a handful.
pub const MAX_OPEN_SCOPES: usize = 64;

pub use directives::MAX_EXCITERS;

/// Parses script text (spec §3). See [`Parsed`]. A 3-D script that imports a mesh file
/// (`objMesh`) needs [`parse_with_files`].
pub fn parse(text: &str) -> Parsed {
    parse_with(text, Diags::default(), &no_files)
}

/// Parses script text whose `objMesh` lines read their files through `files` (3-D spec
/// §4.6): it gets the path as written and returns the file's text or why it cannot.
pub fn parse_with_files(text: &str, files: Files<'_>) -> Parsed {
    parse_with(text, Diags::default(), files)
}

/// The files of a script that was not read from a folder.
fn no_files(path: &str) -> Result<String, String> {
    Err(format!(
        "no file `{path}`: this script was not read from a folder, so it cannot import files"
    ))
}

/// Parses script bytes: invalid UTF-8 is reported with its line and column (each invalid
/// sequence reads as one U+FFFD character), and the rest is parsed as text (spec §3.12 f).
/// Adjacent invalid sequences are one report, the only one of its line.
pub fn parse_bytes(bytes: &[u8]) -> Parsed {
    parse_bytes_with_files(bytes, &no_files)
}

/// [`parse_bytes`] with the files of [`parse_with_files`].
pub fn parse_bytes_with_files(bytes: &[u8], files: Files<'_>) -> Parsed {
    if let Ok(text) = std::str::from_utf8(bytes) {
        return parse_with(text, Diags::default(), files);
    }
    let mut diags = Diags::default();
    let mut text = String::with_capacity(bytes.len());
    let mut pos = Position::default();
    // Invalid bytes with nothing valid between them are one report: (line, col, bytes).
    let mut run: Option<(u32, u32, Vec<String>)> = None;
    let report = |diags: &mut Diags, (line, col, hex): (u32, u32, Vec<String>)| {
        diags.push_invalid_utf8(
            Diagnostic::new(
                DiagnosticCode::InvalidUtf8,
                line,
                col,
                format!("invalid UTF-8 byte sequence {}", hex.join(" ")),
            )
            .with_expected("UTF-8 text")
            .with_found(hex.join(" ")),
        );
    };
    for chunk in bytes.utf8_chunks() {
        let valid = chunk.valid();
        text.push_str(valid);
        if !valid.is_empty() {
            if let Some(r) = run.take() {
                report(&mut diags, r);
            }
        }
        let invalid = chunk.invalid();
        if !invalid.is_empty() {
            valid.chars().for_each(|c| pos.advance(c));
            let hex = invalid.iter().map(|b| format!("{b:02X}"));
            match &mut run {
                Some((_, _, bytes)) => bytes.extend(hex),
                None => run = Some((pos.line, pos.col, hex.collect())),
            }
            text.push('\u{FFFD}');
            pos.advance('\u{FFFD}');
        }
    }
    if let Some(r) = run.take() {
        report(&mut diags, r);
    }
    parse_with(&text, diags, files)
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

fn parse_with(text: &str, mut diags: Diags, files: Files<'_>) -> Parsed {
    // The tokens borrow the script's text.
    let (mut items, tokens) = lines::read_items(text, &mut diags);
    // A 3-D script (`~dim 3`, 3-D spec §1.1) is read with the 3-D keywords.
    let three_d = space::is_3d(&items, &tokens);
    let mut pass1 = three_d.then(|| space::labels::Pass1::new(files));
    let mut symbols = labels::declare_labels(&mut items, &tokens, &mut diags, pass1.as_mut());
    let mesh_errors = match pass1 {
        Some(p) => p.finish(&mut symbols, &mut diags),
        None => Vec::new(),
    };

    // Pass 2: directives and commands in script order.
    let mut b = Builder {
        diags,
        symbols: &symbols,
        tokens: &tokens,
        spec: ModelSpec {
            elements: Vec::with_capacity(items.len()),
            ..ModelSpec::default()
        },
        open: Vec::new(),
        buffer_ids: HashMap::new(),
        samplerate: None,
        space: three_d.then(space::SpaceState::default),
        auto: three_d.then_some(false),
        mesh_errors,
    };
    for item in items.iter().filter(|i| !i.broken) {
        if three_d && is_generate(item, &tokens) {
            b.generate_in_3d(item);
        } else if let Some(req) = &item.generator {
            b.generate(req);
        } else if is_generate(item, &tokens) {
            // Reported in pass 1.
        } else if item.directive {
            b.directive(item);
        } else if three_d {
            b.space_command(item);
        } else {
            b.command(item);
        }
    }
    b.finish_space();
    let Builder {
        diags,
        mut spec,
        samplerate,
        space,
        ..
    } = b;
    if let Some((mode, _)) = samplerate {
        spec.sample_rate_mode = mode;
    }
    if let Some(state) = space {
        spec.space = Some(Box::new(state.spec));
    }
    let ok = diags.error_count() == 0;
    Parsed {
        spec: ok.then_some(spec),
        diagnostics: diags.finish(),
    }
}

/// Pass 2: the spec being built, the open buffer scopes, and the diagnostics.
struct Builder<'s> {
    diags: Diags,
    symbols: &'s Symbols<'s>,
    /// Every item's tokens (see `Item::tokens`).
    tokens: &'s [Token<'s>],
    spec: ModelSpec,
    /// Open scopes, in order of opening (indices into `spec.buffers`).
    open: Vec<u32>,
    /// `spec.buffers` by name.
    buffer_ids: HashMap<String, u32>,
    samplerate: Option<(SampleRateMode, u32)>,
    /// The 3-D model being read (`~dim 3`), `None` for a 1-D script.
    space: Option<space::SpaceState>,
    /// Whether `auto` may stand in the expression being read: `None` in a 1-D script (where it
    /// is an ordinary name), `Some(true)` in a 3-D length slot (3-D spec §1.7).
    auto: Option<bool>,
    /// Why each `objMesh`'s file could not be read in pass 1, by label.
    mesh_errors: Vec<(String, String)>,
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
    /// Runs `f` with `auto` allowed (a 3-D length slot) or not; in a 1-D script `auto` stays an
    /// ordinary name.
    fn with_auto<T>(&mut self, allowed: bool, f: impl FnOnce(&mut Self) -> T) -> T {
        let before = self.auto;
        if before.is_some() {
            self.auto = Some(allowed);
        }
        let out = f(self);
        self.auto = before;
        out
    }

    /// The index of buffer `name` in `spec.buffers`, added at its first use.
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
}
