//! The lines of a script (spec §3.2): command and directive lines become tokenised items.

use super::keywords::shape_of;
use crate::lang::diagnostics::{Diagnostic, DiagnosticCode, Diags};
use crate::lang::generate::{self, GenRequest};
use crate::lang::lexer::{is_blank, line_len, tokenize, width, Lines, TokKind, Token};

/// Reads the script's lines (spec §3.2) into items: command and directive lines tokenised,
/// comments and blank lines skipped, other lines ignored with a warning when they look like a
/// command. The script's bytes are scanned once: a command line is lexed from its start to its
/// break. The tokens of every item are in one vector (one allocation for the script, not one
/// per line).
pub(super) fn read_items<'a>(text: &'a str, diags: &mut Diags) -> (Vec<Item>, Vec<Token<'a>>) {
    // A line is a few dozen bytes; a command has a label, a keyword and a few arguments.
    let breaks = memchr::memchr_iter(b'\n', text.as_bytes()).count() + 1;
    let mut items = Vec::with_capacity(breaks);
    let mut tokens = Vec::with_capacity(breaks * 6);
    let mut lines = Lines::new(text);
    while let Some(rest) = lines.rest() {
        let line = lines.number();
        let lead = rest
            .char_indices()
            .find(|&(_, c)| !is_blank(c) || c == '\n' || c == '\r');
        let len = match lead {
            Some((first, lead @ ('@' | '~'))) => {
                let directive = lead == '~';
                let (range, len) = tokenize(rest, line, diags, &mut tokens);
                match range {
                    Some(range) => items.push(Item {
                        line,
                        directive,
                        broken: false,
                        tokens: range,
                        generator: None,
                        broken_generator: None,
                    }),
                    None => broken_line(
                        rest.get(..len).unwrap_or(""),
                        first,
                        line,
                        directive,
                        &mut items,
                        &mut tokens,
                    ),
                }
                len
            }
            Some((first, '#')) => line_len(rest, first),
            Some((first, '\n' | '\r')) => first,
            Some((first, _)) => {
                let len = line_len(rest, first);
                check_ignored_line(rest.get(..len).unwrap_or(""), line, diags);
                len
            }
            None => rest.len(),
        };
        lines.advance(len);
    }
    (items, tokens)
}

/// A command or directive line with a lexical error (reported): a command keeps its label
/// known so that references to it do not cascade (the line takes part in pass 1 with its label
/// only, kind unknown); a `~generate` directive's labels are unknown, so references to them
/// must not cascade either.
fn broken_line<'a>(
    text: &'a str,
    first: usize,
    line: u32,
    directive: bool,
    items: &mut Vec<Item>,
    tokens: &mut Vec<Token<'a>>,
) {
    if !directive {
        let rest = text.get(first..).unwrap_or("");
        let len = rest
            .find(|c: char| is_blank(c) || matches!(c, '+' | '[' | ']' | '\'' | '#'))
            .unwrap_or(rest.len());
        let label = rest.get(..len).unwrap_or("");
        let col = col_of(text.get(..first).unwrap_or(""));
        tokens.push(Token {
            kind: TokKind::Bare,
            text: label,
            col,
        });
        items.push(Item {
            line,
            directive: false,
            broken: true,
            tokens: tokens.len() - 1..tokens.len(),
            generator: None,
            broken_generator: None,
        });
        return;
    }
    let words: Vec<&str> = text
        .get(first..)
        .unwrap_or("")
        .split(is_blank)
        .filter(|w| !w.is_empty())
        .take(3)
        .collect();
    if let Some(name) = generate::broken_name(&words) {
        items.push(Item {
            line,
            directive: true,
            broken: true,
            tokens: 0..0,
            generator: None,
            broken_generator: Some(name),
        });
    }
}

/// The column of the character after `before`.
fn col_of(before: &str) -> u32 {
    width(before).saturating_add(1)
}

/// Warns when an ignored line looks like a command with a forgotten `@` (spec §3.2): its first
/// word is a type keyword (`mass 1 0 0`), or its second word is one after a label-like first
/// word (`m mass 1 0 0`).
fn check_ignored_line(text: &str, line: u32, diags: &mut Diags) {
    // The first two words, each with its column.
    let mut words: Vec<(u32, String)> = Vec::new();
    let mut rest = text;
    while words.len() < 2 {
        let word_at = rest.find(|c: char| !is_blank(c)).unwrap_or(rest.len());
        let word = rest.get(word_at..).unwrap_or("");
        let len = word
            .find(|c: char| is_blank(c) || c == '#')
            .unwrap_or(word.len());
        if len == 0 {
            break;
        }
        let before = text.len() - rest.len() + word_at;
        words.push((
            col_of(text.get(..before).unwrap_or("")),
            word.get(..len).unwrap_or("").to_string(),
        ));
        rest = word.get(len..).unwrap_or("");
        if rest.starts_with('#') {
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
    if let Some((col, keyword, has_label)) = hit {
        let message = if has_label {
            format!("line ignored: it looks like a `{keyword}` command whose label lacks `@`")
        } else {
            format!(
                "line ignored: it starts with the type keyword `{keyword}`; commands start \
                 with `@label`"
            )
        };
        diags.push(
            Diagnostic::new(DiagnosticCode::IgnoredCommandLike, line, col, message)
                .with_expected("@label keyword arguments…"),
        );
    }
}

/// A command or directive line, tokenised.
pub(super) struct Item {
    pub(super) line: u32,
    pub(super) directive: bool,
    /// A command line with a lexical error: only its label token is kept, for pass 1.
    pub(super) broken: bool,
    /// The line's tokens in the script's token vector (see [`Item::tokens`]).
    pub(super) tokens: std::ops::Range<usize>,
    /// A `~generate` directive read in pass 1 and expanded in pass 2.
    pub(super) generator: Option<Box<GenRequest>>,
    /// The name of a `~generate` line with a lexical error: its labels are unknown.
    pub(super) broken_generator: Option<String>,
}

impl Item {
    /// The line's tokens, from the script's token vector `all`.
    pub(super) fn tokens<'t, 'a>(&self, all: &'t [Token<'a>]) -> &'t [Token<'a>] {
        all.get(self.tokens.clone()).unwrap_or(&[])
    }
}

pub(super) fn is_generate(item: &Item, all: &[Token]) -> bool {
    item.directive
        && item
            .tokens(all)
            .first()
            .is_some_and(|t| t.text == "~generate")
}
