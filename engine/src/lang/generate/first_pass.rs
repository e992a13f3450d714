//! The first pass over a `~generate` line (spec §4, §3.4): kind, name, sizes and geometry are
//! literals, read and checked here so that the parser knows every generated label before any
//! line is resolved. The physical values stay text until [`super::expand`].

use super::*;

/// Splits `text` at `sep`, returning each piece with its column.
fn split(text: &str, col: u32, sep: char) -> Vec<(&str, u32)> {
    let mut out = Vec::new();
    let mut piece_col = col;
    for piece in text.split(sep) {
        out.push((piece, piece_col));
        piece_col = col_plus(piece_col, width(piece).saturating_add(1));
    }
    out
}

/// Reads the generator's name and kind from the first tokens of a line, for a line that failed
/// to tokenise: its labels are then unknown, not undefined.
pub(crate) fn broken_name(words: &[&str]) -> Option<String> {
    match words {
        ["~generate", _, name, ..] if is_identifier(name) => Some((*name).to_string()),
        _ => None,
    }
}

/// The first pass over a `~generate` line (`tokens[0]` is `~generate`). Reports every problem
/// of its form; `budget` is what is left of [`MAX_GENERATED_ELEMENTS`] and is reduced by the
/// elements this directive creates.
pub(crate) fn read(tokens: &[Token], line: u32, diags: &mut Diags, budget: &mut usize) -> Read {
    let Some(directive) = tokens.first() else {
        return Read::Broken { name: None };
    };
    let synopsis = "~generate KIND NAME key=value …";
    let (Some(kind_tok), Some(name_tok)) = (tokens.get(1), tokens.get(2)) else {
        let col = tokens.get(1).map_or(directive.col, |t| t.col);
        diags.push(
            diag(
                DiagnosticCode::InvalidDirectiveArgument,
                line,
                col,
                "`~generate` needs a generator kind, a name and key=value arguments",
            )
            .with_expected(synopsis),
        );
        return Read::Broken { name: None };
    };

    // The name first, so that an unknown kind still silences references to its labels.
    let name = name_tok.string();
    let name_ok = name_tok.kind == TokKind::Bare && is_identifier(&name);
    if !name_ok {
        let hint = if name.contains('=') {
            " (the name comes before the key=value arguments)"
        } else {
            ""
        };
        diags.push(
            diag(
                DiagnosticCode::InvalidDirectiveArgument,
                line,
                name_tok.col,
                format!(
                    "generator name `{}` is not an identifier{hint}: it prefixes the labels \
                     and parameters it creates",
                    name_tok.source()
                ),
            )
            .with_expected("an identifier ([A-Za-z_][A-Za-z0-9_]*)")
            .with_found(name_tok.source()),
        );
    }
    let broken = || Read::Broken {
        name: name_ok.then(|| name.clone()),
    };

    let keyword = kind_tok.string();
    let kind = if kind_tok.kind == TokKind::Bare {
        KINDS.iter().find(|(k, _)| *k == keyword).map(|(_, g)| *g)
    } else {
        None
    };
    let Some(kind) = kind else {
        let mut d = diag(
            DiagnosticCode::UnknownGenerator,
            line,
            kind_tok.col,
            format!("unknown generator `{}`", kind_tok.source()),
        );
        if let Some((k, _)) = KINDS.iter().find(|(k, _)| k.eq_ignore_ascii_case(&keyword)) {
            d.message.push_str(&format!(" (did you mean `{k}`?)"));
        }
        diags.push(
            d.with_expected(format!("one of {KIND_LIST}"))
                .with_found(kind_tok.source()),
        );
        return broken();
    };
    let (required, optional) = keys_of(kind);
    let label = name_ok.then_some(name.as_str());
    let push = |diags: &mut Diags, d: Diagnostic| diags.push(d.with_label(label));

    // key=value arguments.
    let mut values: Vec<(Key, Val)> = Vec::new();
    // Keys written, including those whose value was rejected (so they are not also "missing").
    let mut given: Vec<(Key, u32)> = Vec::new();
    let mut ok = name_ok;
    let rest = tokens.get(3..).unwrap_or(&[]);
    let mut i = 0;
    while let Some(t) = rest.get(i) {
        i += 1;
        let text = t.string();
        let eq = t.text.find('=');
        let (Some(eq), TokKind::Bare) = (eq, t.kind) else {
            push(
                diags,
                diag(
                    DiagnosticCode::InvalidDirectiveArgument,
                    line,
                    t.col,
                    format!("expected key=value, found `{}`", t.source()),
                )
                .with_expected(usage(kind, &keyword))
                .with_found(t.source()),
            );
            ok = false;
            continue;
        };
        let key_text = t.text.get(..eq).unwrap_or("").to_string();
        let mut value = Val {
            value: t.text.get(eq + 1..).unwrap_or("").to_string(),
            col: col_plus(t.col, width(&key_text).saturating_add(1)),
            bracket: false,
        };
        if value.value.is_empty() {
            // `key=[ … ]` or `key='…'`: the group written right after the `=`.
            let end_col = col_plus(t.col, width(t.text));
            if let Some(g) = rest
                .get(i)
                .filter(|g| g.kind != TokKind::Bare && g.col == end_col)
            {
                value = Val {
                    value: g.string(),
                    col: g.inner_col(),
                    bracket: g.kind == TokKind::Bracket,
                };
                i += 1;
            }
        }
        if key_text.is_empty() {
            push(
                diags,
                diag(
                    DiagnosticCode::InvalidDirectiveArgument,
                    line,
                    t.col,
                    format!("missing key before `=` in `{text}`"),
                )
                .with_expected(usage(kind, &keyword))
                .with_found(text),
            );
            ok = false;
            continue;
        }
        let key = Key::from_name(&key_text);
        let Some(key) = key.filter(|k| required.contains(k) || optional.contains(k)) else {
            let mut message = format!("unknown key `{key_text}` for a `{keyword}` generator");
            if let Some(k) = key {
                let owners: Vec<&str> = KINDS
                    .iter()
                    .filter(|(_, g)| {
                        let (r, o) = keys_of(*g);
                        r.contains(&k) || o.contains(&k)
                    })
                    .map(|(n, _)| *n)
                    .collect();
                message.push_str(&format!(
                    " (`{key_text}` is a key of {})",
                    owners.join(", ")
                ));
            } else if let Some(k) = required
                .iter()
                .chain(optional)
                .find(|k| k.name().eq_ignore_ascii_case(&key_text))
            {
                message.push_str(&format!(" (did you mean `{}`?)", k.name()));
            }
            let keys: Vec<&str> = required.iter().chain(optional).map(|k| k.name()).collect();
            push(
                diags,
                diag(DiagnosticCode::UnknownGeneratorKey, line, t.col, message)
                    .with_expected(format!("one of {}", keys.join(", ")))
                    .with_found(key_text),
            );
            ok = false;
            continue;
        };
        if let Some((_, col)) = given.iter().find(|(k, _)| *k == key) {
            push(
                diags,
                diag(
                    DiagnosticCode::InvalidDirectiveArgument,
                    line,
                    t.col,
                    format!(
                        "key `{key_text}` given twice (first at column {col}); each key is \
                         given once"
                    ),
                )
                .with_found(key_text),
            );
            ok = false;
            continue;
        }
        given.push((key, t.col));
        if value.value.chars().all(is_blank) {
            push(
                diags,
                diag(
                    DiagnosticCode::InvalidGeneratorValue,
                    line,
                    t.col,
                    format!("missing value after `{key_text}=`"),
                )
                .with_expected(key.form(kind)),
            );
            ok = false;
            continue;
        }
        values.push((key, value));
    }
    let missing: Vec<&Key> = required
        .iter()
        .filter(|k| !given.iter().any(|(g, _)| g == *k))
        .collect();
    // Without a valid name the keys were probably shifted by one: do not pile up "missing".
    if !missing.is_empty() && name_ok {
        let list: Vec<String> = missing
            .iter()
            .map(|k| format!("`{}={}`", k.name(), placeholder(**k, kind)))
            .collect();
        push(
            diags,
            diag(
                DiagnosticCode::MissingGeneratorKey,
                line,
                kind_tok.col,
                format!(
                    "the `{keyword}` generator needs {}",
                    list.join(if list.len() == 2 { " and " } else { ", " })
                ),
            )
            .with_expected(usage(kind, &keyword)),
        );
        ok = false;
    }
    let get = |key: Key| values.iter().find(|(k, _)| *k == key).map(|(_, v)| v);

    // Structure: sizes, fixed nodes, geometry (literals only, so labels are known now).
    let mut r = Reader {
        diags,
        line,
        label,
        kind,
        ok: true,
    };
    let int_list = |r: &mut Reader<'_>, key: Key, n: usize| -> Option<Vec<usize>> {
        let v = get(key)?;
        r.integers(key, v, n)
    };
    let default_box = ([0.0, 0.0, 0.0], [1.0, 1.0, 0.0]);
    let mut first = get(Key::From).map_or(Some(default_box.0), |v| r.triple(Key::From, v));
    let last = get(Key::To).map_or(Some(default_box.1), |v| r.triple(Key::To, v));
    if kind == GenKind::Ring {
        first = get(Key::Centre).map_or(Some(default_box.0), |v| r.triple(Key::Centre, v));
    }
    let fixed = get(Key::Fixed).map(|v| r.fixed(v));
    let plain_fixed = |f: &Option<Option<LatticeFixed>>| match f {
        None => Some(Fixed::None),
        Some(None) => None,
        Some(Some(LatticeFixed::None)) => Some(Fixed::None),
        Some(Some(LatticeFixed::Corners)) => Some(Fixed::Corners),
        Some(Some(LatticeFixed::Borders)) => Some(Fixed::Borders),
        Some(Some(_)) => None, // rejected by `fixed` for these kinds
    };
    let topology = match kind {
        GenKind::String | GenKind::StiffString | GenKind::Chain => int_list(&mut r, Key::Nodes, 1)
            .map(|n| match kind {
                GenKind::String => Topology::String { nodes: n[0] },
                GenKind::StiffString => Topology::StiffString { nodes: n[0] },
                _ => Topology::Chain { nodes: n[0] },
            }),
        GenKind::Mesh => {
            let size = int_list(&mut r, Key::Size, 2);
            match (size, plain_fixed(&fixed)) {
                (Some(s), Some(fixed)) => Some(Topology::Mesh {
                    length: s[0],
                    width: s[1],
                    fixed,
                }),
                _ => None,
            }
        }
        GenKind::Triangle | GenKind::Hexagon => {
            let size = int_list(&mut r, Key::Size, 1);
            match (size, plain_fixed(&fixed)) {
                (Some(s), Some(fixed)) if kind == GenKind::Triangle => {
                    Some(Topology::Triangle { size: s[0], fixed })
                }
                (Some(s), Some(fixed)) => Some(Topology::Hexagon { rings: s[0], fixed }),
                _ => None,
            }
        }
        GenKind::Ring => {
            let nodes = int_list(&mut r, Key::Nodes, 1);
            let radius = get(Key::Radius).map_or(Some(1.0), |v| r.number(Key::Radius, v));
            match (nodes, radius) {
                (Some(n), Some(radius)) => Some(Topology::Ring {
                    nodes: n[0],
                    radius,
                }),
                _ => None,
            }
        }
        GenKind::Lattice => {
            let size = int_list(&mut r, Key::Size, 3);
            let span = get(Key::Span).map_or(Some(vec![1]), |v| r.integers(Key::Span, v, 1));
            let diagonals = get(Key::Diagonals).map_or(Some(false), |v| r.switch(v));
            match (size, span, diagonals, fixed) {
                (Some(s), Some(span), Some(diagonals), f) => f
                    .unwrap_or(Some(LatticeFixed::None))
                    .map(|fixed| Topology::Lattice {
                        size: [s[0], s[1], s[2]],
                        span: span[0],
                        diagonals,
                        fixed,
                    }),
                _ => None,
            }
        }
        GenKind::Polyline => {
            let points = get(Key::Points).and_then(|v| r.points(v));
            let closed = get(Key::Closed).map_or(Some(true), |v| r.switch(v));
            match (points, closed) {
                (Some(points), Some(closed)) => Some(Topology::Polyline { points, closed }),
                _ => None,
            }
        }
    };
    let structure_ok = r.ok;
    let (Some(topology), Some(first), Some(last), true, true) =
        (topology, first, last, ok, structure_ok)
    else {
        return broken();
    };

    // Sizes: each generator within its own limits, all of them within the script's budget.
    let size_key = match kind {
        GenKind::String | GenKind::StiffString | GenKind::Chain | GenKind::Ring => Key::Nodes,
        GenKind::Polyline => Key::Points,
        _ => Key::Size,
    };
    let size_col = get(size_key).map_or(kind_tok.col, |v| v.col);
    let too_large = |found: String, expected: String| {
        diag(
            DiagnosticCode::TooLarge,
            line,
            size_col,
            format!(
                "the `{keyword}` generator `{name}` would create {found}, more than {expected}"
            ),
        )
        .with_label(label)
        .with_expected(expected)
        .with_found(found)
    };
    match topology.counts() {
        Ok((nodes, links)) => {
            let total = nodes.saturating_add(links);
            if total > *budget {
                let used = MAX_GENERATED_ELEMENTS - *budget;
                let expected = if used == 0 {
                    format!("the limit of {MAX_GENERATED_ELEMENTS} generated elements per script")
                } else {
                    format!(
                        "the {} generated elements left of the script's limit of \
                         {MAX_GENERATED_ELEMENTS}",
                        *budget
                    )
                };
                diags.push(too_large(
                    format!("{total} elements ({nodes} nodes and {links} links)"),
                    expected,
                ));
                return broken();
            }
            *budget -= total;
        }
        Err(GeneratorError::TooManyLinks { links }) => {
            diags.push(too_large(
                format!("{links} links"),
                format!("the limit of {MAX_GENERATED_LINKS} links"),
            ));
            return broken();
        }
        Err(GeneratorError::TooLarge { nodes }) => {
            diags.push(too_large(
                format!("{nodes} nodes"),
                format!("the limit of {MAX_GENERATED_NODES} nodes"),
            ));
            return broken();
        }
        Err(e) => {
            // Minimums are checked per value above; anything else is reported as is.
            diags.push(
                diag(
                    DiagnosticCode::InvalidGeneratorValue,
                    line,
                    size_col,
                    e.to_string(),
                )
                .with_label(label),
            );
            return broken();
        }
    }

    let value = |key: Key| get(key).cloned();
    let (Some(m), Some(k), Some(z)) = (value(Key::M), value(Key::K), value(Key::Z)) else {
        return broken();
    };
    Read::Ready(Box::new(GenRequest {
        line,
        keyword,
        kind_col: kind_tok.col,
        name,
        name_col: name_tok.col,
        topology,
        first,
        last,
        m,
        k,
        z,
        zo: value(Key::Zo),
        ks: value(Key::Ks),
    }))
}

/// Reads literal values of the first pass, reporting problems at the offending value.
struct Reader<'d> {
    diags: &'d mut Diags,
    line: u32,
    label: Option<&'d str>,
    kind: GenKind,
    ok: bool,
}

impl Reader<'_> {
    fn bad(&mut self, code: DiagnosticCode, col: u32, message: String, key: Key, found: String) {
        self.ok = false;
        self.diags.push(
            diag(code, self.line, col, message)
                .with_label(self.label)
                .with_expected(key.form(self.kind))
                .with_found(found),
        );
    }

    /// `n` comma-separated integer literals (`40` or `40.`), each at least the kind's minimum.
    fn integers(&mut self, key: Key, v: &Val, n: usize) -> Option<Vec<usize>> {
        let parts = split(&v.value, v.col, ',');
        if parts.len() != n || v.bracket {
            let found = if v.bracket {
                format!("[{}]", v.text())
            } else {
                v.text()
            };
            self.bad(
                DiagnosticCode::InvalidGeneratorValue,
                v.col,
                format!(
                    "`{}` takes {}, found `{found}`",
                    key.name(),
                    key.form(self.kind)
                ),
                key,
                found,
            );
            return None;
        }
        let min = minimum(self.kind);
        let mut out = Vec::with_capacity(n);
        for (text, col) in parts {
            let text = text.to_string();
            let (int_part, frac) = text.split_once('.').unwrap_or((text.as_str(), ""));
            let is_integer = !int_part.is_empty()
                && int_part.chars().all(|c| c.is_ascii_digit())
                && frac.chars().all(|c| c == '0');
            if !is_integer {
                self.bad(
                    DiagnosticCode::NonIntegerSize,
                    col,
                    format!(
                        "`{}` is not an integer literal (generator sizes are literals)",
                        text
                    ),
                    key,
                    text,
                );
                return None;
            }
            let Ok(value) = int_part.parse::<usize>() else {
                self.bad(
                    DiagnosticCode::TooLarge,
                    col,
                    format!("generator size `{text}` is too large"),
                    key,
                    text,
                );
                return None;
            };
            if value < min {
                let what = if key == Key::Span {
                    "neighbour span".to_string()
                } else {
                    format!("`{}` of a {} generator", key.name(), kind_name(self.kind))
                };
                self.bad(
                    DiagnosticCode::InvalidSize,
                    col,
                    format!("the {what} is {value}, below its minimum of {min}"),
                    key,
                    text,
                );
                return None;
            }
            out.push(value);
        }
        Some(out)
    }

    /// A finite numeric literal.
    fn literal(&mut self, key: Key, text: &str, col: u32) -> Option<f64> {
        match parse_number_literal(text.trim()) {
            Ok(v) => Some(v),
            Err(e) => {
                let (code, message) = match e {
                    NumberError::Invalid => (
                        DiagnosticCode::InvalidNumber,
                        format!(
                            "`{}` is not a number (generator geometry takes numeric literals)",
                            text.trim()
                        ),
                    ),
                    NumberError::NonFinite => (
                        DiagnosticCode::NonFiniteNumber,
                        format!("non-finite number `{}`", text.trim()),
                    ),
                };
                self.bad(code, col, message, key, text.trim().to_string());
                None
            }
        }
    }

    fn number(&mut self, key: Key, v: &Val) -> Option<f64> {
        self.literal(key, &v.value, v.col)
    }

    /// `x,y,z`, or `[x y z]` as positions are written elsewhere (spec §3.7).
    fn triple(&mut self, key: Key, v: &Val) -> Option<[f64; 3]> {
        let parts: Vec<(&str, u32)> = if v.bracket {
            split_items(&v.value)
                .into_iter()
                .map(|(item, offset)| (item, col_plus(v.col, offset)))
                .collect()
        } else {
            split(&v.value, v.col, ',')
        };
        if parts.len() != 3 {
            let found = v.text();
            self.bad(
                DiagnosticCode::InvalidGeneratorValue,
                v.col,
                format!(
                    "`{}` takes three coordinates x,y,z, found {}",
                    key.name(),
                    parts.len()
                ),
                key,
                found,
            );
            return None;
        }
        let mut out = [0.0; 3];
        let mut good = true;
        for (slot, (text, col)) in out.iter_mut().zip(parts) {
            match self.literal(key, text, col) {
                Some(x) => *slot = x,
                None => good = false,
            }
        }
        good.then_some(out)
    }

    fn switch(&mut self, v: &Val) -> Option<bool> {
        match v.text().as_str() {
            "on" => Some(true),
            "off" => Some(false),
            other => {
                let key = if self.kind == GenKind::Polyline {
                    Key::Closed
                } else {
                    Key::Diagonals
                };
                self.bad(
                    DiagnosticCode::InvalidGeneratorValue,
                    v.col,
                    format!("`{}` is `on` or `off`, found `{other}`", key.name()),
                    key,
                    other.to_string(),
                );
                None
            }
        }
    }

    fn fixed(&mut self, v: &Val) -> Option<LatticeFixed> {
        let text = v.text();
        let face = |axis: u8, high: bool| Some(LatticeFixed::Face { axis, high });
        let f = match text.as_str() {
            "none" => Some(LatticeFixed::None),
            "corners" => Some(LatticeFixed::Corners),
            "borders" => Some(LatticeFixed::Borders),
            _ if self.kind != GenKind::Lattice => None,
            "centre" => Some(LatticeFixed::Centre),
            "xmin" => face(0, false),
            "xmax" => face(0, true),
            "ymin" => face(1, false),
            "ymax" => face(1, true),
            "zmin" => face(2, false),
            "zmax" => face(2, true),
            _ => None,
        };
        if f.is_none() {
            self.bad(
                DiagnosticCode::InvalidGeneratorValue,
                v.col,
                format!(
                    "`fixed` of a {} generator is {}, found `{text}`",
                    kind_name(self.kind),
                    Key::Fixed.form(self.kind)
                ),
                Key::Fixed,
                text,
            );
        }
        f
    }

    /// `x,y;x,y;…`: at least two points.
    fn points(&mut self, v: &Val) -> Option<Vec<(f64, f64)>> {
        let mut out = Vec::new();
        let mut good = true;
        for (point, col) in split(&v.value, v.col, ';') {
            let pair = split(point, col, ',');
            let [(x, xc), (y, yc)] = pair.as_slice() else {
                let found = point.to_string();
                self.bad(
                    DiagnosticCode::InvalidGeneratorValue,
                    col,
                    format!("a polyline point is x,y, found `{found}`"),
                    Key::Points,
                    found,
                );
                good = false;
                continue;
            };
            match (
                self.literal(Key::Points, x, *xc),
                self.literal(Key::Points, y, *yc),
            ) {
                (Some(x), Some(y)) => out.push((x, y)),
                _ => good = false,
            }
        }
        if good && out.len() < 2 {
            self.bad(
                DiagnosticCode::InvalidSize,
                v.col,
                format!("a polyline needs at least 2 points, found {}", out.len()),
                Key::Points,
                v.text(),
            );
            good = false;
        }
        good.then_some(out)
    }
}
