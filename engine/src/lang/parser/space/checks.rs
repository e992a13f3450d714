//! What a 3-D script is checked for once it is read: the input channels its XYZ elements take
//! (3-D spec §3.1, §3.2), the buffer scopes its microphones name (§3.4), and the warnings of
//! §5.6 on constant values (a 1-D `spring` line pasted into a 3-D script, a string or
//! membrane without tension, a contact that cannot engage, a negative rest length).

use super::super::Builder;
use crate::lang::diagnostics::{Diagnostic, DiagnosticCode};
use crate::laws::space::SpaceLawKind;
use crate::spec::expr::Expr;
use crate::spec::space::structures::Fix;
use crate::spec::space::{SpaceKind, StructureKind};
use crate::spec::{Endpoint, ParamKind, Vector};
use std::collections::HashMap;

impl Builder<'_> {
    /// The checks of a whole 3-D script (nothing in a 1-D one).
    pub(in crate::lang::parser) fn finish_space(&mut self) {
        let Some(state) = self.space.take() else {
            return;
        };
        let mut diags = Vec::new();
        // Channels taken by posInputXYZ and frcInputXYZ.
        for e in &state.spec.elements {
            let channel = match &e.kind {
                SpaceKind::PosInput { channel, .. }
                | SpaceKind::PosInputXyz { channel, .. }
                | SpaceKind::FrcInput { channel, .. }
                | SpaceKind::FrcInputXyz { channel, .. } => *channel,
                _ => continue,
            };
            if let Some((_, line, by)) = state.taken_inputs.iter().find(|(c, _, _)| *c == channel) {
                diags.push(
                    Diagnostic::new(
                        DiagnosticCode::DuplicateLabel,
                        e.span.line,
                        e.span.col,
                        format!(
                            "input channel {channel} is taken by `@{by}` at line {line}, an XYZ \
                             element that reads channels N, N+1 and N+2"
                        ),
                    )
                    .with_label(Some(&e.label)),
                );
            }
        }
        // Microphones listening to a buffer scope.
        for e in &state.spec.elements {
            if let SpaceKind::Mic { set, .. } = &e.kind {
                let structure = self.symbols.generator(set).is_some();
                if !structure && !self.spec.buffers.iter().any(|b| b == set.as_str()) {
                    diags.push(
                        Diagnostic::new(
                            DiagnosticCode::UndefinedElement,
                            e.span.line,
                            e.span.col,
                            format!(
                                "the microphone listens to `{set}`, which is neither a structure \
                                 (`@name`) nor a buffer scope of the script (`~begin {set}`)"
                            ),
                        )
                        .with_label(Some(&e.label)),
                    );
                }
            }
        }
        diags.extend(lints(&state.spec.elements, &self.spec.params));
        for d in diags {
            self.diags.push(d);
        }
        self.space = Some(state);
    }
}

/// The constant value of `e` with the declared parameter values and `auto` = `auto`.
fn constant(e: &Expr, values: &HashMap<&str, f64>, auto: Option<f64>) -> Option<f64> {
    let mut known = true;
    e.for_each_name(&mut |n| {
        known &= values.contains_key(n) || (n == "auto" && auto.is_some());
    });
    if !known {
        return None;
    }
    let v = e.eval(&|n| {
        if n == "auto" {
            auto
        } else {
            values.get(n).copied()
        }
    });
    v.is_finite().then_some(v)
}

fn position(v: &Vector, values: &HashMap<&str, f64>) -> Option<[f64; 3]> {
    match v {
        Vector::Scalar(z) => Some([0.0, 0.0, constant(z, values, None)?]),
        Vector::Xyz(c) => Some([
            constant(&c[0], values, None)?,
            constant(&c[1], values, None)?,
            constant(&c[2], values, None)?,
        ]),
    }
}

/// The warnings of 3-D spec §5.6 on constant values.
fn lints(
    elements: &[crate::spec::space::SpaceElement],
    params: &[crate::spec::ParamDecl],
) -> Vec<Diagnostic> {
    let values: HashMap<&str, f64> = params
        .iter()
        .map(|p| {
            let v = match p.kind {
                ParamKind::Control { value } => value,
                ParamKind::Audio { default, .. } => default,
            };
            (p.name.as_str(), v)
        })
        .collect();
    let mut places: HashMap<&str, [f64; 3]> = HashMap::new();
    for e in elements {
        let pos = match &e.kind {
            SpaceKind::Mass { pos, .. }
            | SpaceKind::Osc { pos, .. }
            | SpaceKind::Ground { pos }
            | SpaceKind::PosInput { pos, .. }
            | SpaceKind::PosInputXyz { pos, .. } => pos,
            _ => continue,
        };
        if let Some(p) = position(pos, &values) {
            places.insert(e.label.as_str(), p);
        }
    }
    let at = |ep: &Endpoint| match ep {
        Endpoint::Label(l) => places.get(l.as_str()).copied(),
        _ => None,
    };
    let mut out = Vec::new();
    let mut warn = |e: &crate::spec::space::SpaceElement, message: String| {
        out.push(
            Diagnostic::new(
                DiagnosticCode::SuspiciousValue,
                e.span.line,
                e.span.col,
                message,
            )
            .with_label(Some(&e.label)),
        );
    };
    for e in elements {
        match &e.kind {
            SpaceKind::Interaction { law, args, a, b } => {
                let row = law.row();
                let length = |name: &str| row.slot_of(name).and_then(|s| args.get(s));
                let l0 = match (at(a), b.as_ref().and_then(at)) {
                    (Some(p), Some(q)) => Some(
                        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2))
                            .sqrt(),
                    ),
                    _ => None,
                };
                if *law == SpaceLawKind::Spring {
                    let rest = length("L").and_then(|l| constant(l, &values, None));
                    if let (Some(rest), Some(l0)) = (rest, l0) {
                        if rest != 0.0 && rest.abs() < 0.01 * l0 {
                            warn(
                                e,
                                "this `spring`'s rest length is below 1 % of its initial \
                                 distance: if this line came from a 1-D script, its 4th argument \
                                 was a damping; 3-D `spring` takes K and a rest length"
                                    .to_string(),
                            );
                        }
                    }
                }
                for name in ["L", "R"] {
                    if let Some(v) = length(name).and_then(|l| constant(l, &values, l0)) {
                        if v < 0.0 {
                            warn(
                                e,
                                format!("a negative {name} ({v}): the link is never at rest"),
                            );
                        }
                    }
                }
                if matches!(law, SpaceLawKind::Contact | SpaceLawKind::NlContact) {
                    if let Some(d) = length("D").and_then(|l| constant(l, &values, l0)) {
                        if d <= 0.0 {
                            warn(e, format!("the contact distance D = {d} is not positive: the contact never engages"));
                        }
                    }
                }
            }
            SpaceKind::Structure(s)
                if matches!(s.kind, StructureKind::String3 | StructureKind::Mesh3) =>
            {
                let anchored = match (s.kind, s.fix()) {
                    (StructureKind::String3, Fix::Both) => true,
                    (StructureKind::Mesh3, Fix::Borders | Fix::Corners) => true,
                    _ => false,
                };
                let points: Option<Vec<[f64; 3]>> =
                    s.points.iter().map(|p| position(p, &values)).collect();
                let (Some(points), true) = (points, anchored) else {
                    continue;
                };
                let spacing = |a: [f64; 3], b: [f64; 3], n: u32| {
                    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
                        / (n.max(2) - 1) as f64
                };
                let mut spacings = vec![spacing(points[0], points[1], s.sizes[0])];
                if s.kind == StructureKind::Mesh3 {
                    spacings.push(spacing(points[0], points[2], s.sizes[1]));
                }
                let slack = spacings.iter().all(|&a| {
                    constant(&s.rest, &values, Some(a)).is_some_and(|l| l >= a * (1.0 - 1e-12))
                });
                if slack {
                    warn(
                        e,
                        format!(
                            "the `{}` is anchored but its links are not shorter than their \
                             spacing (L = auto or more): it has no transverse stiffness, so no \
                             small-signal pitch; pre-tension it with L < \
                             spacing, e.g. `[0.9*auto]`",
                            s.kind.keyword()
                        ),
                    );
                }
            }
            _ => {}
        }
    }
    out
}
