//! The lines of a script (spec §3.2): command and directive lines become tokenised items.

use super::keywords::shape_of;
use crate::lang::diagnostics::{Diagnostic, DiagnosticCode, Diags};
use crate::lang::generate::{self, GenRequest};
use crate::lang::lexer::{is_blank, tokenize, width, TokKind, Token};

/// Reads the script's lines (`(line number, text)`) into items: command and
/// directive lines tokenised, comments and blank lines skipped, other lines ignored with a
/// warning when they look like a command. The tokens of every item are in one vector (one
/// allocation for the script, not one per line).
pub(super) fn read_items<'a>(
    lines: Vec<(u32, &'a str)>,
    diags: &mut Diags,
) -> (Vec<Item>, Vec<Token<'a>>) {
    let mut items = Vec::with_capacity(lines.len());
    // A command has a label, a keyword and a few arguments.
    let mut tokens = Vec::with_capacity(lines.len() * 6);
    for (line, text) in lines {
        let Some((first, lead)) = text.char_indices().find(|(_, c)| !is_blank(*c)) else {
            continue;
        };
        match lead {
            '@' | '~' => {
                let directive = lead == '~';
                match tokenize(text, line, diags, &mut tokens) {
                    Some(range) => items.push(Item {
                        line,
                        directive,
                        broken: false,
                        tokens: range,
                        generator: None,
                        broken_generator: None,
                    }),
                    None if !directive => {
                        // Keep the label known so references to it do not cascade: the line
                        // takes part in pass 1 with its label only (kind unknown).
                        let rest = text.get(first..).unwrap_or("");
                        let len = rest
                            .find(|c: char| {
                                is_blank(c) || matches!(c, '+' | '[' | ']' | '\'' | '#')
                            })
                            .unwrap_or(rest.len());
                        let label = rest.get(..len).unwrap_or("");
                        let col = col_of(text.get(..first).unwrap_or(""));
                        tokens.push(Token {
                            kind: TokKind::Bare,
                            text: label,
                            col,
                            inner_col: col,
                        });
                        items.push(Item {
                            line,
                            directive: false,
                            broken: true,
                            tokens: tokens.len() - 1..tokens.len(),
                            generator: None,
                            broken_generator: None,
                        });
                    }
                    None => {
                        // A `~generate` line with a lexical error: its labels are unknown, so
                        // references to them must not cascade.
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
                }
            }
            '#' => {}
            _ => check_ignored_line(text, line, diags),
        }
    }
    (items, tokens)
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
