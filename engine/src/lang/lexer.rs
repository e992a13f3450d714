//! Lines, comments and tokens of the model language (spec §3.2, §3.3).

use super::diagnostics::{Diagnostic, DiagnosticCode, Diags};

/// Blank characters: Unicode whitespace, plus a byte-order mark (so a BOM before the first
/// command does not hide it).
pub(crate) fn is_blank(c: char) -> bool {
    c.is_whitespace() || c == '\u{feff}'
}

/// The length of the line that starts `rest`: the offset of its break (CR or LF, spec §3.2) at
/// or after byte `from`, or the length of `rest` when it is the last line.
pub(crate) fn line_len(rest: &str, from: usize) -> usize {
    let bytes = rest.as_bytes();
    bytes
        .get(from..)
        .and_then(|b| memchr::memchr2(b'\n', b'\r', b))
        .map_or(bytes.len(), |k| from + k)
}

/// A script read line by line (spec §3.2: a line ends at CR LF, CR or LF). The lexer reads a
/// command line from its start and stops at its break, so that the script's bytes are scanned
/// once; other lines find their break with [`line_len`].
pub(crate) struct Lines<'a> {
    text: &'a str,
    /// The byte offset of the current line's start.
    pos: usize,
    /// The current line's 1-based number.
    line: u32,
}

impl<'a> Lines<'a> {
    pub(crate) fn new(text: &'a str) -> Lines<'a> {
        Lines {
            text,
            pos: 0,
            line: 1,
        }
    }

    /// The current line and the rest of the script after it (`None` after the last line).
    pub(crate) fn rest(&self) -> Option<&'a str> {
        self.text.get(self.pos..).filter(|r| !r.is_empty())
    }

    /// The current line's number.
    pub(crate) fn number(&self) -> u32 {
        self.line
    }

    /// Moves to the next line, the current one being `len` bytes long (up to its break).
    pub(crate) fn advance(&mut self, len: usize) {
        let bytes = self.text.as_bytes();
        let end = self.pos + len;
        self.pos = match (bytes.get(end), bytes.get(end + 1)) {
            (Some(b'\r'), Some(b'\n')) => end + 2,
            (Some(_), _) => end + 1,
            (None, _) => end,
        };
        self.line = self.line.saturating_add(1);
    }
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

/// A token of a command or directive line. Its text borrows the script, so reading a line
/// allocates nothing but room in the script's token vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Token<'a> {
    pub kind: TokKind,
    /// The content (without brackets or quotes).
    pub text: &'a str,
    /// Column of the token's first character (the `[` or `'` for groups).
    pub col: u32,
}

impl<'a> Token<'a> {
    /// Column of the content's first character: after the `[` or `'` of a group.
    pub(crate) fn inner_col(&self) -> u32 {
        match self.kind {
            TokKind::Bare => self.col,
            TokKind::Bracket | TokKind::Quoted => col_plus(self.col, 1),
        }
    }

    pub(crate) fn string(&self) -> String {
        self.text.to_string()
    }

    /// The text after the first character: a label token's label, without its `@`.
    pub(crate) fn label(&self) -> &'a str {
        after_first(self.text)
    }

    /// The token as written in the script, for messages.
    pub(crate) fn source(&self) -> String {
        match self.kind {
            TokKind::Bare => self.string(),
            TokKind::Bracket => format!("[{}]", self.text),
            TokKind::Quoted => format!("'{}'", self.text),
        }
    }

    /// The first non-blank character of the content.
    pub(crate) fn first_non_blank(&self) -> Option<char> {
        self.text.chars().find(|c| !is_blank(*c))
    }

    /// True when the content starts with `@` (a label, not a value).
    pub(crate) fn starts_with_at(&self) -> bool {
        self.text.as_bytes().first() == Some(&b'@')
    }
}

/// `s` without its first character.
pub(crate) fn after_first(s: &str) -> &str {
    let mut chars = s.chars();
    chars.next();
    chars.as_str()
}

/// The number of columns `s` spans: its Unicode scalar values (spec §3.12 f: columns count
/// characters, a tab as one).
pub(crate) fn width(s: &str) -> u32 {
    u32::try_from(s.chars().count()).unwrap_or(u32::MAX)
}

/// `col` moved right by `by` columns.
pub(crate) fn col_plus(col: u32, by: u32) -> u32 {
    col.saturating_add(by)
}

/// The character at byte `i` of `s` and its length in bytes; ASCII without decoding.
#[inline]
fn char_at(s: &str, i: usize) -> Option<(char, usize)> {
    let b = *s.as_bytes().get(i)?;
    if b.is_ascii() {
        return Some((char::from(b), 1));
    }
    let c = s.get(i..)?.chars().next()?;
    Some((c, c.len_utf8()))
}

fn is_bare_char(c: char) -> bool {
    !is_blank(c) && !matches!(c, '+' | '[' | ']' | '\'' | '#')
}

/// The ASCII bytes [`is_bare_char`] accepts (non-ASCII bytes are `false`: the lexer decodes
/// their character).
const BARE_ASCII: [bool; 256] = {
    let mut table = [false; 256];
    let mut b = 0;
    while b < 128 {
        table[b] = !matches!(
            b as u8,
            b'\t'..=b'\r' | b' ' | b'+' | b'[' | b']' | b'\'' | b'#'
        );
        b += 1;
    }
    table
};

/// The length of the run of bare ASCII bytes at the start of `bytes`.
#[inline]
fn bare_ascii_run(bytes: &[u8]) -> usize {
    bytes
        .iter()
        .position(|&b| !BARE_ASCII[usize::from(b)])
        .unwrap_or(bytes.len())
}

/// True when `tok` (the bare token scanned so far) ends with the mantissa of a number followed
/// by `e`/`E`, i.e. a following `+digits` is the exponent of a numeric literal (spec §3.3).
fn ends_with_exponent_marker(tok: &str) -> bool {
    let Some(rest) = tok.strip_suffix(['e', 'E']) else {
        return false;
    };
    let mantissa_len = rest
        .bytes()
        .rev()
        .take_while(|b| b.is_ascii_digit() || *b == b'.')
        .count();
    let (before, mantissa) = rest.split_at(rest.len() - mantissa_len);
    if !mantissa.bytes().any(|b| b.is_ascii_digit())
        || mantissa.bytes().filter(|b| *b == b'.').count() > 1
    {
        return false;
    }
    match before.chars().next_back() {
        Some(c) => !(c.is_alphanumeric() || c == '_'),
        None => true,
    }
}

/// Tokenises the command or directive line that starts `rest` (spec §3.3) onto the end of
/// `tokens`, the tokens of the whole script in one vector. Returns the line's range in it and
/// the line's length in bytes (up to its break, which ends the lexing; `rest` goes on with the
/// following lines). A `#` outside a quoted group starts a comment (spec §3.2). Reports the
/// first lexical error of the line and returns no range then, with `tokens` as it was; warns
/// about `+` separators between two non-blank characters.
pub(crate) fn tokenize<'a>(
    rest: &'a str,
    line: u32,
    diags: &mut Diags,
    tokens: &mut Vec<Token<'a>>,
) -> (Option<std::ops::Range<usize>>, usize) {
    let start = tokens.len();
    match lex_line(rest, line, diags, tokens) {
        Ok(len) => (Some(start..tokens.len()), len),
        Err(at) => {
            tokens.truncate(start);
            (None, line_len(rest, at))
        }
    }
}

/// The lexer's loop: `i` is a byte offset into the line and `col` its column, moved together
/// (every character the lexer dispatches on is ASCII; other characters are stepped over whole).
/// Returns the line's length, or the offset of its lexical error (reported).
fn lex_line<'a>(
    text: &'a str,
    line: u32,
    diags: &mut Diags,
    tokens: &mut Vec<Token<'a>>,
) -> Result<usize, usize> {
    let bytes = text.as_bytes();
    let mut i = 0;
    let mut col: u32 = 1;
    while let Some(&b) = bytes.get(i) {
        match b {
            b' ' | b'\t' | 0x0b | 0x0c => {
                i += 1;
                col = col_plus(col, 1);
            }
            b'\n' | b'\r' => return Ok(i),
            b'#' => return Ok(line_len(text, i)),
            b'+' => {
                let prev = text.get(..i).and_then(|s| s.chars().next_back());
                let next = text.get(i + 1..).and_then(|s| s.chars().next());
                if let (Some(p), Some(n)) = (prev, next) {
                    if !is_blank(p) && !is_blank(n) && n != '#' {
                        diags.push(
                            Diagnostic::new(
                                DiagnosticCode::PlusSeparator,
                                line,
                                col,
                                "`+` outside brackets separates tokens (as in MIMS4Max); \
                                 write the expression inside [ ]",
                            )
                            .with_found("+"),
                        );
                    }
                }
                i += 1;
                col = col_plus(col, 1);
            }
            b'[' => {
                let after = bytes.get(i + 1..).unwrap_or(&[]);
                let stop = after
                    .iter()
                    .position(|b| matches!(b, b'#' | b'[' | b']' | b'\n' | b'\r'))
                    .map(|k| (i + 1 + k, bytes.get(i + 1 + k).copied()));
                let inner = |j: usize| text.get(i + 1..j).unwrap_or("");
                match stop {
                    Some((j, Some(b']'))) => {
                        col = push_group(tokens, TokKind::Bracket, inner(j), col);
                        i = j + 1;
                    }
                    Some((j, Some(b'['))) => {
                        diags.push(Diagnostic::new(
                            DiagnosticCode::NestedBracket,
                            line,
                            col_plus(col, width(inner(j)).saturating_add(1)),
                            "`[` inside a bracket group: bracket groups do not nest; use \
                             parentheses inside brackets",
                        ));
                        return Err(i);
                    }
                    _ => {
                        diags.push(Diagnostic::new(
                            DiagnosticCode::UnterminatedBracket,
                            line,
                            col,
                            "unterminated `[`: no matching `]` on this line",
                        ));
                        return Err(i);
                    }
                }
            }
            b']' => {
                diags.push(Diagnostic::new(
                    DiagnosticCode::StrayBracket,
                    line,
                    col,
                    "stray `]` without a matching `[`",
                ));
                return Err(i);
            }
            b'\'' => {
                let after = bytes.get(i + 1..).unwrap_or(&[]);
                let end = after
                    .iter()
                    .position(|&b| matches!(b, b'\'' | b'\n' | b'\r'))
                    .filter(|&k| after.get(k) == Some(&b'\''));
                let Some(len) = end else {
                    diags.push(Diagnostic::new(
                        DiagnosticCode::UnterminatedQuote,
                        line,
                        col,
                        "unterminated quote: no closing `'` on this line",
                    ));
                    return Err(i);
                };
                let j = i + 1 + len;
                col = push_group(
                    tokens,
                    TokKind::Quoted,
                    text.get(i + 1..j).unwrap_or(""),
                    col,
                );
                i = j + 1;
            }
            _ => {
                if let Some((_, len)) = char_at(text, i).filter(|&(c, _)| is_blank(c)) {
                    // A non-ASCII blank (the ASCII ones are matched above).
                    i += len;
                    col = col_plus(col, 1);
                    continue;
                }
                let (start, start_col) = (i, col);
                loop {
                    let run = bare_ascii_run(bytes.get(i..).unwrap_or(&[]));
                    i += run;
                    col = col_plus(col, u32::try_from(run).unwrap_or(u32::MAX));
                    let Some((c, len)) = char_at(text, i) else {
                        break;
                    };
                    if (!c.is_ascii() && is_bare_char(c))
                        || (c == '+'
                            && bytes.get(i + 1).is_some_and(u8::is_ascii_digit)
                            && ends_with_exponent_marker(text.get(start..i).unwrap_or("")))
                    {
                        // `2.5e+3`: the `+` belongs to the number (spec §3.3).
                        i += len;
                        col = col_plus(col, 1);
                    } else {
                        break;
                    }
                }
                tokens.push(Token {
                    kind: TokKind::Bare,
                    text: text.get(start..i).unwrap_or(""),
                    col: start_col,
                });
            }
        }
    }
    Ok(bytes.len())
}

/// Pushes a bracket or quoted group whose opening character stands at `col`; returns the column
/// after its closing character.
fn push_group<'a>(tokens: &mut Vec<Token<'a>>, kind: TokKind, content: &'a str, col: u32) -> u32 {
    tokens.push(Token {
        kind,
        text: content,
        col,
    });
    col_plus(col, width(content).saturating_add(2))
}

/// An item of a bracket's content: its text and its offset in columns from the content's
/// first character.
pub(crate) type BracketItem<'a> = (&'a str, u32);

/// Splits the content of a vector or connection-point bracket into items separated by blanks
/// outside parentheses (spec §3.3).
pub(crate) fn split_items(text: &str) -> Vec<BracketItem<'_>> {
    let mut items = Vec::new();
    let mut depth: usize = 0;
    // The item being read: its start (byte, column offset).
    let mut start: Option<(usize, u32)> = None;
    for (k, (i, c)) in text.char_indices().enumerate() {
        let at = u32::try_from(k).unwrap_or(u32::MAX);
        if is_blank(c) && depth == 0 {
            if let Some((s, sc)) = start.take() {
                items.push((text.get(s..i).unwrap_or(""), sc));
            }
            continue;
        }
        if start.is_none() {
            start = Some((i, at));
        }
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    if let Some((s, sc)) = start {
        items.push((text.get(s..).unwrap_or(""), sc));
    }
    items
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(s: &str) -> Vec<String> {
        let mut d = Diags::default();
        let mut tokens = Vec::new();
        let (range, len) = tokenize(s, 1, &mut d, &mut tokens);
        range.unwrap();
        assert_eq!(len, line_len(s, 0));
        tokens.iter().map(Token::source).collect()
    }

    /// Every line of `text`: (number, content).
    fn split_lines(text: &str) -> Vec<(u32, &str)> {
        let mut lines = Lines::new(text);
        let mut out = Vec::new();
        while let Some(rest) = lines.rest() {
            let len = line_len(rest, 0);
            out.push((lines.number(), &rest[..len]));
            lines.advance(len);
        }
        out
    }

    #[test]
    fn lines_split_at_crlf_cr_lf() {
        let l = split_lines("a\r\nb\rc\nd");
        assert_eq!(l, vec![(1, "a"), (2, "b"), (3, "c"), (4, "d")]);
        assert_eq!(split_lines("a\n"), vec![(1, "a")]);
        assert_eq!(split_lines("\n\n"), vec![(1, ""), (2, "")]);
        assert_eq!(split_lines("\r\n\r\r\n"), vec![(1, ""), (2, ""), (3, "")]);
    }

    #[test]
    fn the_lexer_stops_at_the_line_break() {
        for (text, want, len) in [
            ("@a mass 1 # c\n@b", vec!["@a", "mass", "1"], 13),
            ("@a [x y]\r\n@b", vec!["@a", "[x y]"], 8),
            ("@a 'q'\r@b", vec!["@a", "'q'"], 6),
            ("@a 1e+\n3", vec!["@a", "1e"], 6),
        ] {
            let mut d = Diags::default();
            let mut tokens = Vec::new();
            let (range, l) = tokenize(text, 1, &mut d, &mut tokens);
            assert!(range.is_some(), "{text:?}");
            let got: Vec<String> = tokens.iter().map(Token::source).collect();
            assert_eq!(
                (got, l),
                (want.iter().map(|s| s.to_string()).collect(), len)
            );
        }
        // A group is not closed by the next line.
        for text in ["@a [x\ny]", "@a 'q\nq'"] {
            let mut d = Diags::default();
            let mut tokens = Vec::new();
            let (range, l) = tokenize(text, 1, &mut d, &mut tokens);
            assert_eq!((range, l, tokens.len()), (None, 5, 0), "{text:?}");
        }
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
        assert_eq!(
            split_items("@s (a + b)  c"),
            vec![("@s", 0), ("(a + b)", 3), ("c", 12)]
        );
        assert_eq!(
            split_items("é\t(ü b) c"),
            vec![("é", 0), ("(ü b)", 2), ("c", 8)]
        );
    }
}
