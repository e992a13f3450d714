//! Canonical script text for a [`ModelSpec`] (spec §3), such that
//! `parse(&print(&spec)).spec == Some(spec)` for every spec the parser can produce.
//!
//! Layout: `~samplerate raw` when raw (§3.11); the parameters; the host directives (`~pitch`,
//! `~key`, `~note`, `~route`, `~macro`); then the elements in script
//! order, with `~begin`/`~end` scopes reconstructed so that every element's buffer membership
//! (and the order of [`ModelSpec::buffers`]) is preserved (§3.10). Legacy forms print
//! canonically: a two-parameter `spring` prints as `springDamper`, `nlSpring` as `nlSpring2`;
//! optional arguments equal to 0 are left out. Expressions that contain spaces or `+` go inside
//! `[ ]` (§3.3); inside vectors and connection points they are parenthesised (§3.7, §2.8).

use super::expr_parser::is_identifier;
use crate::spec::expr::{format_number, BinOp, Expr};
use crate::spec::{
    Element, ElementKind, Endpoint, Law, LawForm, MacroSpec, ModelSpec, ParamKind, SampleRateMode,
    Vector,
};
use std::fmt::Write;

fn precedence(e: &Expr) -> u8 {
    match e {
        Expr::Binary(BinOp::Add | BinOp::Sub, ..) => 1,
        Expr::Binary(BinOp::Mul | BinOp::Div, ..) => 2,
        Expr::Neg(_) => 3,
        Expr::Num(v) if v.is_sign_negative() => 3,
        _ => 4,
    }
}

/// Infix text of `e`, as [`Expr`]'s `Display` writes it, except that the negation of a number
/// literal prints as `-(2)`: the parser reads `-2` as the literal −2 (spec §3.5).
pub(crate) fn expr_text(e: &Expr) -> String {
    let mut s = String::new();
    write_expr(&mut s, e);
    s
}

fn write_expr(s: &mut String, e: &Expr) {
    match e {
        Expr::Num(v) => s.push_str(&format_number(*v)),
        Expr::Name(n) => s.push_str(n),
        Expr::Neg(inner) => {
            s.push('-');
            if precedence(inner) < 3 || matches!(**inner, Expr::Num(v) if !v.is_sign_negative()) {
                s.push('(');
                write_expr(s, inner);
                s.push(')');
            } else {
                write_expr(s, inner);
            }
        }
        Expr::Binary(op, a, b) => {
            let p = match op {
                BinOp::Add | BinOp::Sub => 1,
                BinOp::Mul | BinOp::Div => 2,
            };
            if precedence(a) < p {
                s.push('(');
                write_expr(s, a);
                s.push(')');
            } else {
                write_expr(s, a);
            }
            match op {
                BinOp::Add | BinOp::Sub => {
                    s.push(' ');
                    s.push(op.symbol());
                    s.push(' ');
                }
                _ => s.push(op.symbol()),
            }
            if precedence(b) <= p {
                s.push('(');
                write_expr(s, b);
                s.push(')');
            } else {
                write_expr(s, b);
            }
        }
        Expr::Call(func, args) => {
            s.push_str(func.name());
            s.push('(');
            for (i, a) in args.iter().enumerate() {
                if i > 0 {
                    s.push_str(", ");
                }
                write_expr(s, a);
            }
            s.push(')');
        }
    }
}

fn needs_brackets(text: &str) -> bool {
    text.contains([' ', '+'])
}

/// An expression in an argument slot: bare when it has no space or `+`, else `[ … ]`.
pub(super) fn arg(e: &Expr) -> String {
    let t = expr_text(e);
    if needs_brackets(&t) {
        format!("[{t}]")
    } else {
        t
    }
}

/// An item of a vector or connection bracket: parenthesised when it has spaces (§3.3).
pub(super) fn item(e: &Expr) -> String {
    let t = expr_text(e);
    if t.contains(' ') {
        format!("({t})")
    } else {
        t
    }
}

pub(super) fn vector(v: &Vector) -> String {
    match v {
        Vector::Scalar(e) => {
            let t = expr_text(e);
            if needs_brackets(&t) {
                format!("[({t})]")
            } else {
                t
            }
        }
        Vector::Xyz(v) => {
            let [x, y, z] = &**v;
            format!("[{} {} {}]", item(x), item(y), item(z))
        }
    }
}

pub(super) fn endpoint(e: &Endpoint) -> String {
    match e {
        Endpoint::Label(l) => format!("@{l}"),
        Endpoint::Line { target, alpha } => format!("[@{target} {}]", item(alpha)),
        Endpoint::Surface { target, u, w } => format!("[@{target} {} {}]", item(u), item(w)),
        Endpoint::Volume { target, coords } => {
            let [u, v, w] = &**coords;
            format!("[@{target} {} {} {}]", item(u), item(v), item(w))
        }
    }
}

pub(super) fn is_zero(e: &Expr) -> bool {
    *e == Expr::Num(0.0)
}

fn law_args(law: &Law) -> (&'static str, Vec<&Expr>) {
    // The written columns; a law's trailing optional ones equal to 0 are left out (they
    // default to 0, §2.9).
    let mut args: Vec<&Expr> = law.args().iter().collect();
    if let LawForm::Full(kind) = law.form() {
        while args.len() > kind.row().required && args.last().is_some_and(|e| is_zero(e)) {
            args.pop();
        }
    }
    (law.keyword(), args)
}

fn macro_args(m: &MacroSpec) -> Vec<String> {
    let mut a = vec![m.length.to_string()];
    if m.kind.is_2d() {
        a.push(m.width.to_string());
    }
    a.push(arg(&m.m));
    a.push(arg(&m.k));
    if m.kind == crate::spec::MacroKind::StiffString {
        a.push(arg(m.k2.as_ref().unwrap_or(&Expr::Num(0.0))));
    }
    a.push(arg(&m.z));
    if !is_zero(&m.zo) {
        a.push(arg(&m.zo));
    }
    a.push(vector(&m.pos));
    a.push(vector(&m.vel));
    a
}

/// The command line of one element (without scopes), and the tag buffer it names, if any.
fn element_line(e: &Element, spec: &ModelSpec) -> (String, Option<u32>) {
    let label = match &e.kind {
        ElementKind::PosInput { channel, .. } | ElementKind::FrcInput { channel, .. } => {
            format!("in{channel}")
        }
        ElementKind::PosOutput { channel, .. } | ElementKind::FrcOutput { channel, .. } => {
            format!("out{channel}")
        }
        _ => e.label.to_string(),
    };
    let mut args: Vec<String> = Vec::new();
    let keyword = match &e.kind {
        ElementKind::Mass {
            m,
            gravity,
            pos,
            vel,
        } => {
            args.push(arg(m));
            if !is_zero(gravity) {
                args.push(arg(gravity));
            }
            args.push(vector(pos));
            args.push(vector(vel));
            "mass"
        }
        ElementKind::Osc {
            m,
            k,
            z,
            gravity,
            pos,
            vel,
        } => {
            args.extend([arg(m), arg(k), arg(z)]);
            if !is_zero(gravity) {
                args.push(arg(gravity));
            }
            args.push(vector(pos));
            args.push(vector(vel));
            "osc"
        }
        ElementKind::Ground { pos } => {
            args.push(vector(pos));
            "ground"
        }
        ElementKind::MassG {
            m,
            gravity,
            pos,
            delayed,
        } => {
            args.extend([arg(m), arg(gravity), vector(pos), vector(delayed)]);
            "massG"
        }
        ElementKind::Macro(m) => {
            args = macro_args(m);
            m.kind.keyword()
        }
        ElementKind::Interaction { law, a, b } => {
            let (kw, params) = law_args(law);
            args.push(endpoint(a));
            args.push(endpoint(b));
            args.extend(params.into_iter().map(arg));
            kw
        }
        ElementKind::PosInput { pos, .. } => {
            args.push(vector(pos));
            "posInput"
        }
        ElementKind::FrcInput { target, .. } => {
            args.push(endpoint(target));
            "frcInput"
        }
        ElementKind::PosOutput { target, .. } => {
            args.push(endpoint(target));
            "posOutput"
        }
        ElementKind::FrcOutput { target, .. } => {
            args.push(endpoint(target));
            "frcOutput"
        }
    };
    // A legacy tag (§6.4) is the last buffer of a mass-type element with `tag_xy`.
    let mut tag = None;
    if let (true, Some((x, y)), Some(&last)) = (e.kind.is_single_mass(), e.tag_xy, e.buffers.last())
    {
        if let Some(name) = spec.buffers.get(last as usize) {
            let usable =
                is_identifier(name) && spec.param(name).is_none() && x.is_finite() && y.is_finite();
            if usable {
                args.extend([name.clone(), format_number(x), format_number(y)]);
                tag = Some(last);
            }
        }
    }
    let mut line = format!("@{label} {keyword}");
    for a in args {
        line.push(' ');
        line.push_str(&a);
    }
    (line, tag)
}

/// Prints `spec` as canonical script text (spec §3). Parsing the result gives back `spec`
/// (spans aside) for every spec the parser produces.
pub fn print(spec: &ModelSpec) -> String {
    let mut body = String::new();
    // Scopes currently open in the printed text, in opening order (as the parser keeps them).
    let mut open: Vec<u32> = Vec::new();
    // The order in which the printed text first opens each buffer.
    let mut first_opened: Vec<u32> = Vec::new();
    let mut seen = vec![false; spec.buffers.len()];
    let mut note = |b: u32, first_opened: &mut Vec<u32>| {
        if let Some(s) = seen.get_mut(b as usize) {
            if !*s {
                *s = true;
                first_opened.push(b);
            }
        }
    };
    let name = |i: u32| spec.buffers.get(i as usize).map_or("", String::as_str);
    // Each element's line and buffers (a 3-D model's elements are in its space).
    let lines: Vec<(String, Option<u32>, &[u32])> = match &spec.space {
        Some(space) => space
            .elements
            .iter()
            .map(|e| {
                (
                    super::space_printer::element_line(e, space),
                    None,
                    e.buffers.as_slice(),
                )
            })
            .collect(),
        None => spec
            .elements
            .iter()
            .map(|e| {
                let (line, tag) = element_line(e, spec);
                (line, tag, e.buffers.as_slice())
            })
            .collect(),
    };
    for (line, tag, buffers) in lines {
        let wanted: Vec<u32> = match tag {
            Some(_) => buffers.get(..buffers.len() - 1).unwrap_or(&[]).to_vec(),
            None => buffers.to_vec(),
        };
        let common = open.iter().zip(&wanted).take_while(|(a, b)| a == b).count();
        for &b in open.get(common..).unwrap_or(&[]).iter().rev() {
            let _ = writeln!(body, "~end {}", name(b));
        }
        open.truncate(common);
        for &b in wanted.get(common..).unwrap_or(&[]) {
            let _ = writeln!(body, "~begin {}", name(b));
            open.push(b);
            note(b, &mut first_opened);
        }
        if let Some(t) = tag {
            note(t, &mut first_opened);
        }
        body.push_str(&line);
        body.push('\n');
    }
    for &b in open.iter().rev() {
        let _ = writeln!(body, "~end {}", name(b));
    }

    let mut out = String::new();
    if let Some(space) = &spec.space {
        out.push_str(&super::space_printer::medium(space));
    }
    if spec.sample_rate_mode == SampleRateMode::Raw {
        out.push_str("~samplerate raw\n");
    }
    // Declare the buffers up front when first use does not give their order (§3.10).
    let in_order = first_opened.len() == spec.buffers.len()
        && first_opened
            .iter()
            .enumerate()
            .all(|(i, &b)| b as usize == i);
    if !in_order {
        for b in &spec.buffers {
            let _ = writeln!(out, "~begin {b}\n~end {b}");
        }
    }
    for p in &spec.params {
        match p.kind {
            ParamKind::Control { value } => {
                let _ = writeln!(out, "@{} param {}", p.name, format_number(value));
            }
            // A zero default is left out: the MIMS4Max form, which means the same.
            ParamKind::Audio {
                input,
                default: 0.0,
            } => {
                let _ = writeln!(out, "@{} audioParam @in{input}", p.name);
            }
            ParamKind::Audio { input, default } => {
                let _ = writeln!(
                    out,
                    "@{} audioParam @in{input} {}",
                    p.name,
                    format_number(default)
                );
            }
        }
    }
    let h = &spec.host;
    if let Some(v) = h.pitch_hz {
        let _ = writeln!(out, "~pitch {}", format_number(v));
    }
    if let Some(v) = h.voices {
        let _ = writeln!(out, "~voices {v}");
    }
    if let Some(k) = h.pressure_input {
        match h.pressure_scale {
            Some(a) => {
                let _ = writeln!(out, "~pressure in{k} {}", format_number(a));
            }
            None => {
                let _ = writeln!(out, "~pressure in{k}");
            }
        }
    }
    if let Some(v) = h.key {
        let _ = writeln!(out, "~key {}", format_number(v));
    }
    if let Some(k) = h.note_input {
        match h.note_force {
            Some(f) => {
                let _ = writeln!(out, "~note in{k} {}", format_number(f));
            }
            None => {
                let _ = writeln!(out, "~note in{k}");
            }
        }
    }
    if h.unpitched {
        out.push_str("~unpitched\n");
    }
    for e in &h.exciters {
        let _ = write!(out, "~exciter in{} {}", e.input, e.kind.name());
        if let Some(a) = e.amount {
            let _ = write!(out, " {}", format_number(a));
            if let Some(t) = e.time_ms {
                let _ = write!(out, " {}", format_number(t));
            }
        }
        out.push('\n');
    }
    for r in &h.routes {
        let _ = writeln!(out, "~route in{} {}", r.input, r.source.name());
    }
    for m in &h.macro_ranges {
        let _ = writeln!(
            out,
            "~macro {} {} {}",
            m.name,
            format_number(m.min),
            format_number(m.max)
        );
    }
    out.push_str(&body);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negated_literal_keeps_its_tree() {
        let e = -Expr::Num(2.0) * Expr::param("a");
        assert_eq!(expr_text(&e), "-(2)*a");
        assert_eq!(expr_text(&Expr::Num(-2.0)), "-2");
        assert_eq!(expr_text(&-Expr::Num(-2.0)), "--2");
        assert_eq!(arg(&(Expr::param("a") + Expr::Num(1.0))), "[a + 1]");
    }
}
