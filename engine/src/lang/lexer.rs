//! Lines, comments and tokens of the model language (spec §3.2, §3.3).

use super::diagnostics::{Diagnostic, DiagnosticCode, Diags};

/// Blank characters: Unicode whitespace, plus a byte-order mark (so a BOM before the first
/// command does not hide it).
pub(crate) fn is_blank(c: char) -> bool {
    c.is_whitespace() || c == '\u{feff}'
}

/// Splits `text` into lines at CR LF, CR or LF (spec §3.2). Returns (1-based line number, line).
pub(crate) fn split_lines(text: &str) -> Vec<(u32, &str)> {
    let mut lines = Vec::new();
    let bytes = text.as_bytes();
    let mut start = 0;
    let mut i = 0;
    let mut number: u32 = 1;
    while i < bytes.len() {
        match bytes.get(i) {
            Some(b'\n') => {
                lines.push((number, text.get(start..i).unwrap_or("")));
                number = number.saturating_add(1);
                i += 1;
                start = i;
            }
            Some(b'\r') => {
                lines.push((number, text.get(start..i).unwrap_or("")));
                number = number.saturating_add(1);
                i += 1;
                if bytes.get(i) == Some(&b'\n') {
                    i += 1;
                }
                start = i;
            }
            _ => i += 1,
        }
    }
    if start < bytes.len() {
        lines.push((number, text.get(start..).unwrap_or("")));
    }
    lines
}

/// The three token forms of spec §3.3.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TokKind {
    /// A run of characters other than blanks, `+`, `[`, `]`, `'` and `#`.
    Bare,
    /// `[ … ]`; `text` is the content without the brackets.
    Bracket,
    /// `' … '`; `text` is the content without the quotes.
    Quoted,
}

/// A token of a command or directive line. Its text borrows the script's characters, so
/// reading a line allocates only the token list.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Token<'a> {
    pub kind: TokKind,
    /// The content (without brackets or quotes).
    pub text: &'a [char],
    /// Column of the token's first character (the `[` or `'` for groups).
    pub col: u32,
    /// Column of the content's first character.
    pub inner_col: u32,
}

/// The characters as a string. ASCII text, which nearly every label and number is, is copied
/// byte for byte rather than encoded character by character.
pub(crate) fn text_of(chars: &[char]) -> String {
    if chars.iter().all(char::is_ascii) {
        let bytes: Vec<u8> = chars.iter().map(|&c| c as u8).collect();
        String::from_utf8(bytes).unwrap_or_default()
    } else {
        chars.iter().collect()
    }
}

impl Token<'_> {
    pub(crate) fn string(&self) -> String {
        text_of(self.text)
    }

    /// The text after the first character: a label token's label, without its `@`.
    pub(crate) fn label(&self) -> String {
        text_of(self.text.get(1..).unwrap_or(&[]))
    }

    /// The token as written in the script, for messages.
    pub(crate) fn source(&self) -> String {
        match self.kind {
            TokKind::Bare => self.string(),
            TokKind::Bracket => format!("[{}]", self.string()),
            TokKind::Quoted => format!("'{}'", self.string()),
        }
    }
}

fn col_of(i: usize) -> u32 {
    u32::try_from(i.saturating_add(1)).unwrap_or(u32::MAX)
}

fn is_bare_char(c: char) -> bool {
    !is_blank(c) && !matches!(c, '+' | '[' | ']' | '\'' | '#')
}

/// True when `tok` (the bare token scanned so far) ends with the mantissa of a number followed
/// by `e`/`E`, i.e. a following `+digits` is the exponent of a numeric literal (spec §3.3).
fn ends_with_exponent_marker(tok: &[char]) -> bool {
    let Some((&last, rest)) = tok.split_last() else {
        return false;
    };
    if last != 'e' && last != 'E' {
        return false;
    }
    let mantissa_len = rest
        .iter()
        .rev()
        .take_while(|c| c.is_ascii_digit() || **c == '.')
        .count();
    let split = rest.len() - mantissa_len;
    let (before, mantissa) = rest.split_at(split);
    if !mantissa.iter().any(char::is_ascii_digit)
        || mantissa.iter().filter(|c| **c == '.').count() > 1
    {
        return false;
    }
    match before.last() {
        Some(c) => !(c.is_alphanumeric() || *c == '_'),
        None => true,
    }
}

/// Tokenises one command or directive line (spec §3.3) onto the end of `tokens`, the tokens
/// of the whole script in one vector, and returns the line's range in it. A `#` outside a
/// quoted group starts a comment (spec §3.2). Reports the first lexical error of the line and
/// returns `None` then, with `tokens` as it was; warns about `+` separators between two
/// non-blank characters.
pub(crate) fn tokenize<'a>(
    chars: &'a [char],
    line: u32,
    diags: &mut Diags,
    tokens: &mut Vec<Token<'a>>,
) -> Option<std::ops::Range<usize>> {
    let start = tokens.len();
    let lexed = lex_line(chars, line, diags, tokens);
    if lexed.is_none() {
        tokens.truncate(start);
    }
    lexed.map(|()| start..tokens.len())
}

fn lex_line<'a>(
    chars: &'a [char],
    line: u32,
    diags: &mut Diags,
    tokens: &mut Vec<Token<'a>>,
) -> Option<()> {
    let mut i = 0;
    while let Some(&c) = chars.get(i) {
        if is_blank(c) {
            i += 1;
            continue;
        }
        match c {
            '#' => break,
            '+' => {
                let prev = i.checked_sub(1).and_then(|p| chars.get(p));
                let next = chars.get(i + 1);
                if let (Some(&p), Some(&n)) = (prev, next) {
                    if !is_blank(p) && !is_blank(n) && n != '#' {
                        diags.push(
                            Diagnostic::new(
                                DiagnosticCode::PlusSeparator,
                                line,
                                col_of(i),
                                "`+` outside brackets separates tokens (as in MIMS4Max); \
                                 write the expression inside [ ]",
                            )
                            .with_found("+"),
                        );
                    }
                }
                i += 1;
            }
            '[' => {
                let mut j = i + 1;
                loop {
                    match chars.get(j) {
                        None | Some('#') => {
                            diags.push(Diagnostic::new(
                                DiagnosticCode::UnterminatedBracket,
                                line,
                                col_of(i),
                                "unterminated `[`: no matching `]` on this line",
                            ));
                            return None;
                        }
                        Some('[') => {
                            diags.push(Diagnostic::new(
                                DiagnosticCode::NestedBracket,
                                line,
                                col_of(j),
                                "`[` inside a bracket group: bracket groups do not nest; use \
                                 parentheses inside brackets",
                            ));
                            return None;
                        }
                        Some(']') => break,
                        Some(_) => j += 1,
                    }
                }
                tokens.push(Token {
                    kind: TokKind::Bracket,
                    text: chars.get(i + 1..j).unwrap_or(&[]),
                    col: col_of(i),
                    inner_col: col_of(i + 1),
                });
                i = j + 1;
            }
            ']' => {
                diags.push(Diagnostic::new(
                    DiagnosticCode::StrayBracket,
                    line,
                    col_of(i),
                    "stray `]` without a matching `[`",
                ));
                return None;
            }
            '\'' => {
                let Some(len) = chars
                    .get(i + 1..)
                    .and_then(|r| r.iter().position(|&c| c == '\''))
                else {
                    diags.push(Diagnostic::new(
                        DiagnosticCode::UnterminatedQuote,
                        line,
                        col_of(i),
                        "unterminated quote: no closing `'` on this line",
                    ));
                    return None;
                };
                let j = i + 1 + len;
                tokens.push(Token {
                    kind: TokKind::Quoted,
                    text: chars.get(i + 1..j).unwrap_or(&[]),
                    col: col_of(i),
                    inner_col: col_of(i + 1),
                });
                i = j + 1;
            }
            _ => {
                let start = i;
                while let Some(&c) = chars.get(i) {
                    if is_bare_char(c)
                        || (c == '+'
                            && chars.get(i + 1).is_some_and(char::is_ascii_digit)
                            && ends_with_exponent_marker(chars.get(start..i).unwrap_or(&[])))
                    {
                        // `2.5e+3`: the `+` belongs to the number (spec §3.3).
                        i += 1;
                    } else {
                        break;
                    }
                }
                tokens.push(Token {
                    kind: TokKind::Bare,
                    text: chars.get(start..i).unwrap_or(&[]),
                    col: col_of(start),
                    inner_col: col_of(start),
                });
            }
        }
    }
    Some(())
}

/// Splits the content of a vector or connection-point bracket into items separated by blanks
/// outside parentheses (spec §3.3). Returns (start, end) index ranges into `text`.
pub(crate) fn split_items(text: &[char]) -> Vec<(usize, usize)> {
    let mut items = Vec::new();
    let mut depth: usize = 0;
    let mut start: Option<usize> = None;
    for (i, &c) in text.iter().enumerate() {
        if is_blank(c) && depth == 0 {
            if let Some(s) = start.take() {
                items.push((s, i));
            }
            continue;
        }
        if start.is_none() {
            start = Some(i);
        }
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    if let Some(s) = start {
        items.push((s, text.len()));
    }
    items
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(s: &str) -> Vec<String> {
        let chars: Vec<char> = s.chars().collect();
        let mut d = Diags::default();
        let mut tokens = Vec::new();
        tokenize(&chars, 1, &mut d, &mut tokens).unwrap();
        tokens.iter().map(Token::source).collect()
    }

    #[test]
    fn lines_split_at_crlf_cr_lf() {
        let l = split_lines("a\r\nb\rc\nd");
        assert_eq!(l, vec![(1, "a"), (2, "b"), (3, "c"), (4, "d")]);
        assert_eq!(split_lines("a\n"), vec![(1, "a")]);
        assert_eq!(split_lines("\n\n"), vec![(1, ""), (2, "")]);
    }

    #[test]
    fn tokens_and_plus() {
        assert_eq!(
            toks("@a mass 1 2e+3 x+y"),
            ["@a", "mass", "1", "2e+3", "x", "y"]
        );
        assert_eq!(
            toks("a1e+3 .5e+2 [1 + 2] 'q r' # c"),
            ["a1e", "3", ".5e+2", "[1 + 2]", "'q r'"]
        );
        assert_eq!(toks("x[y]z"), ["x", "[y]", "z"]);
    }

    #[test]
    fn items_split_outside_parens() {
        let t: Vec<char> = "@s (a + b)  c".chars().collect();
        assert_eq!(split_items(&t), vec![(0, 2), (3, 10), (12, 13)]);
    }
}
