//! Text reports of `ressort check`: compile errors and stability warnings in the
//! `FILE:LINE:COL: severity: message` form, and the model summary.

use ressort_engine::{
    CompileError, Engine, InputUse, ModelSpec, OutputUse, ParamKind, PointKind, Span,
    StabilityReport, StabilityWarning,
};
use std::fmt::Write;
use std::path::Path;

/// How many per-mass violations are listed before the rest is summarised.
const MAX_MASS_WARNINGS: usize = 20;

fn location(path: &Path, span: Span) -> String {
    if span.is_known() {
        format!("{}:{}:{}", path.display(), span.line, span.col)
    } else {
        path.display().to_string()
    }
}

/// `FILE:LINE:COL: error: @label: message`.
pub fn print_compile_error(path: &Path, e: &CompileError) {
    let label = if e.label.is_empty() {
        String::new()
    } else {
        format!("@{}: ", e.label)
    };
    eprintln!("{}: error: {label}{}", location(path, e.span), e.kind);
}

/// The span of the element that owns a label (`s` for `s[12]`; a 3-D structure's own label).
fn span_of(spec: &ModelSpec, label: &str) -> Span {
    let owner = label.split('[').next().unwrap_or(label);
    match &spec.space {
        Some(space) => space.element(owner).map(|e| e.span).unwrap_or_default(),
        None => spec.element(owner).map(|e| e.span).unwrap_or_default(),
    }
}

/// The label and span of element `i` (an index into the 3-D elements of a 3-D model).
fn element_at(spec: &ModelSpec, i: usize) -> Option<(String, Span)> {
    match &spec.space {
        Some(space) => space.elements.get(i).map(|e| (e.label.to_string(), e.span)),
        None => spec.elements.get(i).map(|e| (e.label.to_string(), e.span)),
    }
}

/// Stability warnings on stderr, at the line of the element involved.
pub fn print_stability_warnings(
    path: &Path,
    spec: &ModelSpec,
    engine: &Engine,
    report: &StabilityReport,
) {
    let mut masses = 0;
    for w in &report.warnings {
        let span = match w {
            StabilityWarning::MassRule(m) => {
                masses += 1;
                if masses > MAX_MASS_WARNINGS {
                    continue;
                }
                let owner = engine.info().points[m.point as usize].owner;
                span_of(spec, &engine.info().owners[owner as usize].label)
            }
            StabilityWarning::StructureLimit { label, .. } => span_of(spec, label),
            StabilityWarning::Unbounded { .. }
            | StabilityWarning::NegativeCubic { .. }
            | StabilityWarning::WeakBound { .. } => {
                // A link: at the interaction's own line, named by its label.
                if let Some((label, span)) = w.element().and_then(|i| element_at(spec, i)) {
                    eprintln!("{}: warning: @{label}: {w}", location(path, span));
                    continue;
                }
                Span::default()
            }
        };
        eprintln!("{}: warning: {w}", location(path, span));
    }
    if masses > MAX_MASS_WARNINGS {
        eprintln!(
            "{}: warning: … and {} more masses break 4M > K_eq + 2·Z_eq",
            path.display(),
            masses - MAX_MASS_WARNINGS
        );
    }
}

/// The summary printed on success.
pub fn summary(path: &Path, spec: &ModelSpec, engine: &Engine, report: &StabilityReport) -> String {
    let info = engine.info();
    let mut s = String::new();
    let _ = writeln!(s, "{}: ok", path.display());
    let count = |f: &dyn Fn(&PointKind) -> bool| info.points.iter().filter(|p| f(&p.kind)).count();
    let nodes = count(&|k| matches!(k, PointKind::MacroNode { .. }));
    let avatars = count(&|k| matches!(k, PointKind::Avatar));
    let grounds = count(&|k| matches!(k, PointKind::Ground))
        + count(&|k| matches!(k, PointKind::MacroNode { fixed: true }));
    let (space, nodes_word) = match engine.is_3d() {
        true => ("in 3-D: x, y and z; ", "structure nodes"),
        false => ("", "macro nodes"),
    };
    let _ = writeln!(
        s,
        "points        {} ({space}{} single, {} {nodes_word}, {} avatars; {} fixed)",
        info.num_points,
        info.num_points - nodes - avatars,
        nodes,
        avatars,
        grounds
    );
    let _ = writeln!(
        s,
        "interactions  {} ({} connection points)",
        info.num_interactions, info.num_connection_points
    );
    let params: Vec<String> = spec
        .params
        .iter()
        .map(|p| match p.kind {
            ParamKind::Control { value } => format!("{} = {value}", p.name),
            ParamKind::Audio {
                input,
                default: 0.0,
            } => format!("{} ← in{input}", p.name),
            ParamKind::Audio { input, default } => format!("{} ← {default} + in{input}", p.name),
        })
        .collect();
    let _ = writeln!(s, "params        {} {}", params.len(), list(&params));
    let inputs: Vec<String> = info
        .inputs
        .iter()
        .enumerate()
        .map(|(c, uses)| {
            let what: Vec<String> = uses
                .iter()
                .map(|u| match u {
                    InputUse::Position(l) => format!("position of @{l}"),
                    InputUse::Force(t) => format!("force on {t}"),
                    InputUse::Param(p) => format!("audio param {p}"),
                })
                .collect();
            if what.is_empty() {
                format!("in{}: unused", c + 1)
            } else {
                format!("in{}: {}", c + 1, what.join(" + "))
            }
        })
        .collect();
    let _ = writeln!(s, "inputs        {} {}", inputs.len(), list(&inputs));
    let outputs: Vec<String> = info
        .outputs
        .iter()
        .enumerate()
        .map(|(c, u)| match u {
            OutputUse::Position(t) => format!("out{}: position of {t}", c + 1),
            OutputUse::Force(t) => format!("out{}: force at {t}", c + 1),
            OutputUse::Unused => format!("out{}: unused (0)", c + 1),
        })
        .collect();
    let _ = writeln!(s, "outputs       {} {}", outputs.len(), list(&outputs));
    let buffers: Vec<String> = info
        .motion
        .named
        .iter()
        .map(|b| format!("{} ({} points)", b.name, b.members.len()))
        .collect();
    let _ = writeln!(
        s,
        "buffers       generic ({} points){}",
        info.num_points,
        if buffers.is_empty() {
            String::new()
        } else {
            format!(", {}", buffers.join(", "))
        }
    );
    let _ = match engine.native_code_bytes() {
        Some(bytes) => writeln!(
            s,
            "sample loop   native code, {bytes} bytes (a small model, compiled when it loads)"
        ),
        None => writeln!(s, "sample loop   interpreter"),
    };
    let violations = report.violations().count();
    let verdict = if violations == 0 {
        "stable: every mass satisfies 4M > K_eq + 2·Z_eq".to_string()
    } else {
        format!("UNSTABLE: {violations} mass(es) break 4M > K_eq + 2·Z_eq")
    };
    let _ = writeln!(
        s,
        "stability     {verdict} (at {} Hz; {} warning(s))",
        info.sample_rate_hz,
        report.warnings.len()
    );
    if let Some(w) = report.worst() {
        let _ = writeln!(
            s,
            "              closest to the limit: @{} with M = {:.6}, K_eq = {:.6}, Z_eq = {:.6}, \
             margin {:.6} ({:.1} % of 4M used)",
            w.label,
            w.m,
            w.k_eq,
            w.z_eq,
            w.margin(),
            w.load() * 100.0
        );
    }
    s
}

fn list(items: &[String]) -> String {
    const SHOWN: usize = 8;
    if items.is_empty() {
        return String::new();
    }
    let mut text = items
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join("; ");
    if items.len() > SHOWN {
        let _ = write!(text, "; … {} more", items.len() - SHOWN);
    }
    format!("({text})")
}
