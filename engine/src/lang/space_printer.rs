//! Canonical text of a 3-D model's elements and medium (3-D spec §1.1, §2–§4), for
//! [`super::print`]: `~dim 3`, `~gravity`, `~friction`, then the elements as
//! `parse(print(spec))` reads them back. Optional trailing arguments equal to 0 are left out,
//! a direction prints as a vector, an options group as a quoted group.

use super::printer::{arg, endpoint, expr_text, is_zero, vector};
use crate::laws::space::ColShape;
use crate::spec::expr::Expr;
use crate::spec::space::{SpaceElement, SpaceKind, SpaceSpec, StructOption, Structure};
use crate::spec::Vector;

/// `~dim 3` and the medium's directives.
pub(super) fn medium(space: &SpaceSpec) -> String {
    let mut out = String::from("~dim 3\n");
    if let Some(g) = &space.gravity {
        out.push_str(&format!("~gravity {}\n", vector(g)));
    }
    if let Some(z) = &space.friction {
        out.push_str(&format!("~friction {}\n", arg(z)));
    }
    out
}

/// A vector as a direction's three slots were read.
fn direction(slots: &[Expr]) -> String {
    vector(&Vector::Xyz(Box::new([
        slots[0].clone(),
        slots[1].clone(),
        slots[2].clone(),
    ])))
}

fn is_zero_vector(v: &Vector) -> bool {
    match v {
        Vector::Scalar(s) => is_zero(s),
        Vector::Xyz(c) => c.iter().all(is_zero),
    }
}

/// A law's written columns (the slots regrouped: a direction from three), trailing optional
/// zeros left out.
fn columns(law: crate::laws::space::SpaceLawKind, args: &[Expr]) -> Vec<String> {
    let row = law.row();
    let mut out: Vec<(String, bool)> = Vec::new();
    let mut slot = 0;
    for c in row.columns {
        let n = c.slots();
        let values = &args[slot..slot + n];
        let zero = values.iter().all(is_zero);
        let text = match c.shape {
            ColShape::Direction => direction(values),
            ColShape::Scalar | ColShape::Length => arg(&values[0]),
        };
        out.push((text, zero));
        slot += n;
    }
    while out.len() > row.required && out.last().is_some_and(|(_, zero)| *zero) {
        out.pop();
    }
    out.into_iter().map(|(t, _)| t).collect()
}

/// An option's value: space-free text, parenthesised when the expression has blanks.
fn option_value(e: &Expr) -> String {
    let t = expr_text(e);
    if t.contains(' ') {
        format!("({t})")
    } else {
        t
    }
}

fn options(s: &Structure) -> Option<String> {
    if s.options.is_empty() {
        return None;
    }
    let items: Vec<String> = s
        .options
        .iter()
        .map(|o| match o {
            StructOption::Zo(e) => format!("Zo={}", option_value(e)),
            StructOption::Fix(f) => format!("fix={}", f.text()),
            StructOption::Lock(l) => format!("lock={}", l.word()),
            StructOption::Diag => "diag".to_string(),
            StructOption::Span(n) => format!("span={n}"),
            StructOption::K2(e) => format!("K2={}", option_value(e)),
            StructOption::Hinge(e) => format!("hinge={}", option_value(e)),
        })
        .collect();
    Some(format!("'{}'", items.join(" ")))
}

fn structure(s: &Structure) -> Vec<String> {
    use crate::spec::space::StructureKind as K;
    let mut a: Vec<String> = Vec::new();
    match s.kind {
        K::ObjMesh => a.push(format!(
            "'{}'",
            s.mesh.as_ref().map_or("", |m| m.path.as_str())
        )),
        _ => a.extend(s.sizes.iter().map(|n| n.to_string())),
    }
    a.extend([arg(&s.m), arg(&s.k), arg(&s.z)]);
    let radius = s.radius.as_ref().map(arg).unwrap_or_default();
    match s.kind {
        K::Ring3 => {
            a.push(vector(&s.points[0]));
            a.push(radius);
            a.push(vector(&s.points[1]));
        }
        K::Icosphere => {
            a.push(vector(&s.points[0]));
            a.push(radius);
        }
        K::ObjMesh => {
            a.push(radius);
            a.push(vector(&s.points[0]));
        }
        _ => a.extend(s.points.iter().map(vector)),
    }
    a.push(arg(&s.rest));
    a.extend(options(s));
    a
}

/// The line of one 3-D element.
pub(super) fn element_line(e: &SpaceElement, space: &SpaceSpec) -> String {
    let label = match &e.kind {
        SpaceKind::PosInput { channel, .. }
        | SpaceKind::PosInputXyz { channel, .. }
        | SpaceKind::FrcInput { channel, .. }
        | SpaceKind::FrcInputXyz { channel, .. } => format!("in{channel}"),
        SpaceKind::Output { channel, .. }
        | SpaceKind::DistOutput { channel, .. }
        | SpaceKind::Mic { channel, .. } => format!("out{channel}"),
        _ => e.label.to_string(),
    };
    let mut args: Vec<String> = Vec::new();
    let optional_dir = |d: &Option<Vector>| d.as_ref().map(vector);
    match &e.kind {
        SpaceKind::Mass {
            m,
            gravity,
            pos,
            vel,
            ..
        } => {
            args.push(arg(m));
            if !is_zero_vector(gravity) {
                args.push(vector(gravity));
            }
            args.extend([vector(pos), vector(vel)]);
        }
        SpaceKind::Osc {
            m,
            k,
            z,
            gravity,
            pos,
            vel,
        } => {
            args.extend([arg(m), arg(k), arg(z)]);
            if !is_zero_vector(gravity) {
                args.push(vector(gravity));
            }
            args.extend([vector(pos), vector(vel)]);
        }
        SpaceKind::Ground { pos } => args.push(vector(pos)),
        SpaceKind::Interaction {
            law,
            args: a,
            a: e1,
            b,
        } => {
            args.push(endpoint(e1));
            if let Some(b) = b {
                args.push(endpoint(b));
            }
            args.extend(columns(*law, a));
        }
        SpaceKind::Structure(s) => args = structure(s),
        SpaceKind::ContactSet { a, set, args: a2 } => {
            args.push(endpoint(a));
            args.push(format!("@{set}"));
            args.extend(columns(crate::laws::space::SpaceLawKind::Contact, a2));
        }
        SpaceKind::Vdampers { set, z } => {
            args.push(format!("@{set}"));
            args.push(arg(z));
        }
        SpaceKind::PosInput { pos, dir, .. } => {
            args.push(vector(pos));
            args.extend(optional_dir(dir));
        }
        SpaceKind::PosInputXyz { pos, .. } => args.push(vector(pos)),
        SpaceKind::FrcInput { target, dir, .. } | SpaceKind::Output { target, dir, .. } => {
            args.push(endpoint(target));
            args.extend(optional_dir(dir));
        }
        SpaceKind::FrcInputXyz { target, .. } => args.push(endpoint(target)),
        SpaceKind::DistOutput { a, b, .. } => {
            args.push(endpoint(a));
            args.push(endpoint(b));
        }
        SpaceKind::Mic {
            set,
            at,
            dir,
            q,
            r0,
            ..
        } => {
            let structure = space
                .element(set)
                .is_some_and(|e| matches!(e.kind, SpaceKind::Structure(_)));
            args.push(if structure {
                format!("@{set}")
            } else {
                set.to_string()
            });
            args.push(vector(at));
            args.push(dir.as_ref().map_or_else(|| "radial".to_string(), vector));
            args.extend([arg(q), arg(r0)]);
        }
    }
    let mut line = format!("@{label} {}", e.kind.keyword());
    for a in args {
        line.push(' ');
        line.push_str(&a);
    }
    line
}
