//! The legacy syntax of MIMS's experimental proxy branch, which mi-gen's `_unsorted` proxy and
//! Macro_Objects examples are written in (spec §3.14). Both forms are read as their modern
//! equivalent, so they build exactly the same model, and each use gets a note that names the
//! modern form.
//!
//! * **Bare connection points.** A macro may only be referred to through a connection point
//!   (spec §2.7, "References"; §2.8): `[@s α]` on a string, chain or stiff string, `[@me u w]` on
//!   a mesh. The proxy branch wrote the macro's label bare in the endpoint or target slot and
//!   put the coordinates at the **end of the line**, one per bare macro, endpoint 1's before
//!   endpoint 2's (MIMS branch `ProxyConnections`, `physicsGenerator/physicsGen.py`: `l[-2]` for
//!   m1, `l[-1]` for m2); a mesh point was one token `u:w`. So `@in1 frcInput @s 0.3` is `@in1
//! frcInput [@s 0.3]`, `@c contact @s @in2 K Z 0.
//!   α` is `@c contact [@s α] @in2 K Z 0.`, and `@out1 posOutput @me u:w` is `@out1 posOutput
//!   [@me u w]`. A mesh point may also be written as two tokens `u w`.
//! * **Macros without velocity.** The proxy branch's macros ended at the position
//!   (`@s string 50 1. 0.6 0.01 0.`); spec §2.7's shape ends with `pos vel`. One argument
//!   fewer than the shortest accepted form is read with velocity 0.
//!
//! The bare form is recognised only where a point is expected (an interaction's two endpoints,
//! an input's or output's target), only when the label is declared as a macro, and only when the
//! arguments left once the coordinates are taken off the end fit the keyword's argument count.
//! Anything else is parsed as before: a bare mass label followed by a number is still too many
//! arguments, and a bare macro label without coordinates is still an error.

use super::diagnostics::{Diagnostic, DiagnosticCode, Diags};
use super::lexer::{col_plus, width, TokKind, Token};
use super::symbols::{SymKind, Symbols};

/// A bare macro label in an endpoint slot, with the coordinate tokens that go with it.
#[derive(Debug)]
pub(super) struct Point<'a> {
    /// The endpoint slot (0 or 1 for interactions; 0 for inputs and outputs).
    pub slot: usize,
    /// The macro's label, without `@`.
    pub target: String,
    /// One coordinate (string-like macro) or two (mesh), as tokens at their own columns.
    pub coords: Vec<Token<'a>>,
    /// The coordinates as written (`0.3`, `u:w`, `u w`), for the note.
    written: String,
}

/// Arguments in a legacy form, read as the modern form: the arguments without the coordinate
/// tokens (or with the velocity added), and the connection points the coordinates make.
#[derive(Debug)]
pub(super) struct Read<'a> {
    pub args: Vec<Token<'a>>,
    pub points: Vec<Point<'a>>,
}

/// Which legacy form a command's keyword may take.
#[derive(Clone, Copy, Debug)]
pub(super) enum Form {
    /// Bare connection points in this many endpoint slots: 2 for an interaction, 1 for
    /// `frcInput`, `posOutput` and `frcOutput`.
    Endpoints(usize),
    /// A macro without its velocity.
    Macro,
    /// No legacy form.
    Other,
}

/// Where a command stands, for the notes.
pub(super) struct Place<'a> {
    pub line: u32,
    pub label: &'a str,
}

/// Recognises a legacy form in the arguments of a command whose keyword takes `form` and
/// `min..=max` arguments. Returns `None`, having reported nothing, when the arguments are not
/// in a legacy form; otherwise notes each legacy use.
///
/// A bare macro label in an endpoint slot is an error in the modern syntax (spec §2.7), and so
/// is a macro one argument short, so reading them as legacy forms changes the meaning of no
/// valid script.
pub(super) fn read<'a>(
    form: Form,
    counts: (usize, usize),
    args: &[Token<'a>],
    symbols: &Symbols,
    at: Place<'_>,
    diags: &mut Diags,
) -> Option<Read<'a>> {
    match form {
        // Without a macro there is no bare connection point to find.
        Form::Endpoints(_) if !symbols.has_macros() => None,
        Form::Endpoints(slots) => proxy_form(slots, counts, args, symbols, at, diags),
        Form::Macro => macro_velocity(args, counts.0, at, diags),
        Form::Other => None,
    }
}

/// The legacy proxy form in the arguments of a command with `slots` endpoint slots.
fn proxy_form<'a>(
    slots: usize,
    (min, max): (usize, usize),
    args: &[Token<'a>],
    symbols: &Symbols,
    at: Place<'_>,
    diags: &mut Diags,
) -> Option<Read<'a>> {
    let macros: Vec<(usize, String, usize)> = (0..slots)
        .filter_map(|slot| {
            let t = args.get(slot)?;
            let name = bare_label(t)?;
            match symbols.declared(&name)?.kind {
                SymKind::Macro { dims } => Some((slot, name, usize::from(dims))),
                _ => None,
            }
        })
        .collect();
    if macros.is_empty() {
        return None;
    }
    // Coordinates are taken off the end of the line, the last endpoint's last.
    let mut end = args.len();
    let mut points = Vec::with_capacity(macros.len());
    for (slot, target, dims) in macros.into_iter().rev() {
        let last = args.get(end.checked_sub(1)?)?;
        if end - 1 < slots || !is_coordinate(last) {
            return None;
        }
        let colon = top_level_colons(last);
        let written = last.source();
        let (coords, written) = match (dims, colon.as_slice()) {
            (1, []) => {
                end -= 1;
                (vec![*last], written)
            }
            (2, [c]) => {
                end -= 1;
                let (u, w) = split_at_colon(last, *c)?;
                (vec![u, w], written)
            }
            (2, []) => {
                let before = args.get(end.checked_sub(2)?)?;
                if end - 2 < slots || !is_coordinate(before) || !top_level_colons(before).is_empty()
                {
                    return None;
                }
                end -= 2;
                let written = format!("{} {written}", before.source());
                (vec![*before, *last], written)
            }
            _ => return None,
        };
        points.push(Point {
            slot,
            target,
            coords,
            written,
        });
    }
    if !(min..=max).contains(&end) {
        return None;
    }
    points.reverse();
    for p in &points {
        diags.push(note(p, args.get(p.slot)?, end, &at));
    }
    Some(Read {
        args: args.get(..end)?.to_vec(),
        points,
    })
}

/// The note for one legacy connection point: the bracket form, at the bare label.
fn note(p: &Point, label_tok: &Token, end: usize, at: &Place<'_>) -> Diagnostic {
    let coords: Vec<String> = p
        .coords
        .iter()
        .map(|t| match t.kind {
            TokKind::Bracket => format!("({})", t.string()),
            _ => t.string(),
        })
        .collect();
    let bracket = format!("[@{} {}]", p.target, coords.join(" "));
    let adjacent = p.slot + 1 == end;
    let message = if adjacent {
        format!(
            "legacy proxy syntax: write `{bracket}` for `@{} {}`",
            p.target, p.written
        )
    } else {
        format!(
            "legacy proxy syntax: write `{bracket}` for `@{}` and drop the trailing `{}`",
            p.target, p.written
        )
    };
    Diagnostic::new(
        DiagnosticCode::LegacyProxySyntax,
        at.line,
        label_tok.col,
        message,
    )
    .with_label(Some(at.label))
    .with_expected(bracket)
    .with_found(format!("@{}", p.target))
}

/// A macro without its velocity (spec §2.7, §3.14): `min - 1` arguments, `min` being the
/// shortest accepted count. Returns the arguments with a velocity `0` appended, and notes it at
/// the position; `None` for any other count.
fn macro_velocity<'a>(
    args: &[Token<'a>],
    min: usize,
    at: Place<'_>,
    diags: &mut Diags,
) -> Option<Read<'a>> {
    if args.len().checked_add(1)? != min {
        return None;
    }
    let pos = args.last()?;
    let message = format!(
        "legacy macro syntax: the velocity is missing and defaults to 0; write `{} 0`",
        pos.source()
    );
    diags.push(
        Diagnostic::new(
            DiagnosticCode::LegacyMacroVelocity,
            at.line,
            pos.col,
            message,
        )
        .with_label(Some(at.label))
        .with_expected(format!("{} 0", pos.source()))
        .with_found(pos.source()),
    );
    let mut out = args.to_vec();
    out.push(Token {
        kind: TokKind::Bare,
        text: "0",
        col: pos.col,
    });
    Some(Read {
        args: out,
        points: Vec::new(),
    })
}

/// `@label` as a bare token: the label without `@`.
fn bare_label(t: &Token) -> Option<String> {
    if t.kind != TokKind::Bare || !t.starts_with_at() || t.text.len() < 2 {
        return None;
    }
    Some(t.label().to_string())
}

/// A token that can be a coordinate: a bare value (not a label) or a bracketed expression (not
/// a connection point).
fn is_coordinate(t: &Token) -> bool {
    let first = t.first_non_blank();
    match t.kind {
        TokKind::Bare => first.is_some_and(|c| c != '@'),
        TokKind::Bracket => first.is_some_and(|c| c != '@'),
        TokKind::Quoted => false,
    }
}

/// The byte offsets of the `:` of a bare token outside parentheses (the legacy mesh point
/// `u:w`).
fn top_level_colons(t: &Token) -> Vec<usize> {
    if t.kind != TokKind::Bare {
        return Vec::new();
    }
    let mut depth = 0usize;
    let mut out = Vec::new();
    for (i, c) in t.text.bytes().enumerate() {
        match c {
            b'(' => depth += 1,
            b')' => depth = depth.saturating_sub(1),
            b':' if depth == 0 => out.push(i),
            _ => {}
        }
    }
    out
}

/// Splits `u:w` at the colon into two bare tokens at their own columns; `None` when a side is
/// empty.
fn split_at_colon<'a>(t: &Token<'a>, at: usize) -> Option<(Token<'a>, Token<'a>)> {
    let (u, w) = (t.text.get(..at)?, t.text.get(at + 1..)?);
    if u.is_empty() || w.is_empty() {
        return None;
    }
    let part = |text: &'a str, by: u32| Token {
        kind: TokKind::Bare,
        text,
        col: col_plus(t.col, by),
    };
    Some((part(u, 0), part(w, width(u).saturating_add(1))))
}
