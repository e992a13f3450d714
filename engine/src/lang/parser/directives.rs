//! Directives (spec §3.10, §3.11): `~begin`, `~end`, `~samplerate`, and the host directives
//! `~pitch`, `~key`, `~note`, `~route`, `~macro`, `~voices`, `~pressure`, `~exciter`,
//! `~unpitched`.

use super::lines::Item;
use super::{At, Builder, MAX_OPEN_SCOPES};
use crate::lang::diagnostics::{DiagnosticCode, Diags};
use crate::lang::expr_parser::is_identifier;
use crate::lang::lexer::{TokKind, Token};
use crate::lang::symbols::SymKind;
use crate::spec::{ExciterDecl, ExciterKind, MacroRange, Route, RouteSource, SampleRateMode, Span};

/// The highest model input a host directive may name.
const MAX_HOST_INPUT: u32 = 64;

/// The most `~exciter` lines a script may have (a voice keeps their state in place).
pub const MAX_EXCITERS: usize = 8;

/// The longest exciter ramp or sweep, in milliseconds.
const MAX_EXCITER_MS: f64 = 2000.0;

fn plural_args(count: &[usize]) -> String {
    match count {
        [1] => "one argument".into(),
        [n] => format!("{n} arguments"),
        [a, b] => format!("{a} or {b} arguments"),
        _ => "arguments".into(),
    }
}

impl Builder<'_> {
    /// `~begin`, `~end`, `~samplerate` (spec §3.10, §3.11).
    pub(super) fn directive(&mut self, item: &Item) {
        let tokens = item.tokens(self.tokens);
        let Some(first) = tokens.first() else {
            return;
        };
        let name = first.label();
        let args = tokens.get(1..).unwrap_or(&[]);
        let at = At {
            line: item.line,
            label: None,
        };
        if matches!(
            name,
            "pitch"
                | "key"
                | "note"
                | "route"
                | "macro"
                | "voices"
                | "pressure"
                | "exciter"
                | "unpitched"
        ) {
            self.host_directive(item, name, first.col, args);
            return;
        }
        if matches!(name, "dim" | "gravity" | "friction") {
            self.space_directive(name, first, args, at);
            return;
        }
        let expected = match name {
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
                        "~begin, ~end, ~samplerate, ~generate, ~dim, ~pitch, ~key, ~note, \
                         ~route, ~macro, ~voices, ~pressure, ~exciter or ~unpitched (3-D: \
                         ~gravity, ~friction)",
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
            "voices" => ("a number of voices, 1 to 1024", &[1]),
            "pressure" => (
                "an input (`in1`…) and optionally what full pressure adds to it",
                &[1, 2],
            ),
            "note" => (
                "an input (`in1`…) and optionally the force of a full-velocity note",
                &[1, 2],
            ),
            "exciter" => (
                "an input (`in1`…), a kind (strike, bow, pluck or press), then optionally its \
                 amount and its time in ms",
                &[2, 3, 4],
            ),
            "unpitched" => ("no argument", &[0]),
            "route" => (
                "an input (`in1`…) and main_left, main_right, sidechain_left, sidechain_right, \
                 sidechain_3 … sidechain_8 or none",
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
            let s = s.strip_prefix('@').unwrap_or(&s);
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
        // `~note`, `~route`, `~pressure` and `~exciter` start with an input (`@in1` reads as
        // `in1`).
        let k = if matches!(name, "note" | "route" | "pressure" | "exciter") {
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
            "voices" => match number(&args[0])
                .filter(|v| v.fract() == 0.0 && (1.0..=MAX_VOICES as f64).contains(v))
            {
                Some(v) if host.voices.is_none() => host.voices = Some(v as u32),
                Some(_) => conflict(&mut self.diags, "the model"),
                None => bad(
                    &mut self.diags,
                    args[0].col,
                    format!("the voice count must be a whole number from 1 to {MAX_VOICES}"),
                    Some(args[0].source()),
                ),
            },
            "note" | "pressure" => {
                // An input, then an optional number: the note's force or full pressure's amount.
                let amount = match args.get(1) {
                    Some(t) => match number(t) {
                        Some(v) => Some(v),
                        None => {
                            let what = if name == "note" {
                                "the note force"
                            } else {
                                "the pressure amount"
                            };
                            bad(
                                &mut self.diags,
                                t.col,
                                format!("{what} must be a number"),
                                Some(t.source()),
                            );
                            return;
                        }
                    },
                    None => None,
                };
                let (input, value) = if name == "note" {
                    (&mut host.note_input, &mut host.note_force)
                } else {
                    (&mut host.pressure_input, &mut host.pressure_scale)
                };
                if input.is_some() {
                    conflict(&mut self.diags, "the model");
                    return;
                }
                if name == "note" && host.exciters.iter().any(|e| e.kind == ExciterKind::Strike) {
                    self.diags.push(at.diag(
                        DiagnosticCode::ConflictingDirective,
                        col,
                        "`~note` and `~exciter … strike` both choose the input a note strikes: \
                         keep one"
                            .to_string(),
                    ));
                    return;
                }
                *input = Some(k);
                *value = amount;
            }
            "unpitched" => {
                if host.unpitched {
                    conflict(&mut self.diags, "the model");
                    return;
                }
                host.unpitched = true;
            }
            "exciter" => self.exciter(item, col, k, args),
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
}

impl Builder<'_> {
    /// `~exciter inK KIND [AMOUNT [TIME_MS]]` (docs/LANGUAGE.md §12.4): what a key does to
    /// input K. Whether the input can take the kind (a strike needs a force input, a bow or a
    /// pluck a position input) is checked when the model is prepared, where the inputs are
    /// known.
    fn exciter(&mut self, item: &Item, col: u32, k: u32, args: &[Token]) {
        let at = At {
            line: item.line,
            label: None,
        };
        let kinds = "strike, bow, pluck or press";
        let kind_text = args[1].string();
        let Some(kind) = ExciterKind::from_name(&kind_text) else {
            self.diags.push(
                at.diag(
                    DiagnosticCode::InvalidDirectiveArgument,
                    args[1].col,
                    format!("unknown exciter `{kind_text}`"),
                )
                .with_expected(kinds)
                .with_found(kind_text),
            );
            return;
        };
        let number = |t: &Token| t.string().parse::<f64>().ok().filter(|v| v.is_finite());
        let mut values = [None, None];
        for (i, t) in args[2..].iter().enumerate() {
            let what = if i == 0 {
                match kind {
                    ExciterKind::Strike => "the strike's force, a non-zero number",
                    ExciterKind::Bow => "the bow's speed in units per second, a positive number",
                    ExciterKind::Pluck => "the plectrum's travel, a positive number",
                    ExciterKind::Press => "the press's depth, a non-zero number",
                }
            } else {
                match kind {
                    ExciterKind::Strike => "nothing: a strike takes only its force",
                    ExciterKind::Bow | ExciterKind::Press => "the ramp in milliseconds, 0 to 2000",
                    ExciterKind::Pluck => "the sweep in milliseconds, above 0 and up to 2000",
                }
            };
            let ok = number(t).filter(|v| match (i, kind) {
                (0, ExciterKind::Bow | ExciterKind::Pluck) => *v > 0.0,
                (0, _) => *v != 0.0,
                (_, ExciterKind::Strike) => false,
                (_, ExciterKind::Pluck) => *v > 0.0 && *v <= MAX_EXCITER_MS,
                _ => (0.0..=MAX_EXCITER_MS).contains(v),
            });
            match ok {
                Some(v) => values[i] = Some(v),
                None => {
                    self.diags.push(
                        at.diag(
                            DiagnosticCode::InvalidDirectiveArgument,
                            t.col,
                            format!(
                                "`~exciter in{k} {}`: bad value `{}`",
                                kind.name(),
                                t.source()
                            ),
                        )
                        .with_expected(what)
                        .with_found(t.source()),
                    );
                    return;
                }
            }
        }
        let host = &self.spec.host;
        let conflict = if host.exciters.iter().any(|e| e.input == k) {
            Some(format!("a second `~exciter` for in{k}"))
        } else if kind == ExciterKind::Strike
            && (host.note_input.is_some()
                || host.exciters.iter().any(|e| e.kind == ExciterKind::Strike))
        {
            Some(
                "a second strike: `~note` and `~exciter … strike` choose the one input a note \
                 strikes"
                    .to_string(),
            )
        } else {
            None
        };
        if let Some(message) = conflict {
            self.diags
                .push(at.diag(DiagnosticCode::ConflictingDirective, col, message));
            return;
        }
        if host.exciters.len() >= MAX_EXCITERS {
            self.diags.push(at.diag(
                DiagnosticCode::TooLarge,
                col,
                format!("more than {MAX_EXCITERS} exciters"),
            ));
            return;
        }
        self.spec.host.exciters.push(ExciterDecl {
            input: k,
            kind,
            amount: values[0],
            time_ms: values[1],
            span: Span::new(item.line, args[0].col),
        });
    }
}

/// The most voices `~voices` declares.
pub const MAX_VOICES: u32 = 1024;
