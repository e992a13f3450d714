//! A structure statement (3-D spec §4): its size literals, its physical and geometry
//! arguments, its rest length (which may use `auto`) and its options group (§4.0).

use super::super::{At, Builder};
use crate::lang::diagnostics::DiagnosticCode;
use crate::lang::lexer::{col_plus, split_items, TokKind, Token};
use crate::spec::expr::Expr;
use crate::spec::space::structures::{self, Fix, Lock};
use crate::spec::space::{MeshData, StructOption, Structure, StructureKind, MAX_STRUCTURE_NODES};
use std::sync::Arc;

/// The argument count of a structure statement without its options group (§4.1–§4.6).
pub(super) fn required(kind: StructureKind) -> usize {
    match kind {
        StructureKind::String3 | StructureKind::Icosphere | StructureKind::ObjMesh => 7,
        StructureKind::Ring3 => 8,
        StructureKind::Mesh3 | StructureKind::Lattice3 => 9,
    }
}

/// How many geometry vectors follow M K Z, and whether a radius (or scale) stands among them.
fn geometry(kind: StructureKind) -> (usize, bool) {
    match kind {
        StructureKind::String3 => (2, false),
        StructureKind::Mesh3 => (3, false),
        StructureKind::Lattice3 => (2, false),
        StructureKind::Ring3 => (2, true),
        StructureKind::Icosphere => (1, true),
        StructureKind::ObjMesh => (1, true),
    }
}

/// The options a generator takes besides `Zo`, `fix` and `lock`.
fn own_options(kind: StructureKind) -> &'static [&'static str] {
    match kind {
        StructureKind::String3 => &[],
        StructureKind::Mesh3 => &["diag"],
        StructureKind::Lattice3 => &["diag", "span"],
        StructureKind::Ring3 => &["K2"],
        StructureKind::Icosphere | StructureKind::ObjMesh => &["hinge"],
    }
}

/// What pass 1 needs of a structure statement: its topology, read leniently (pass 2 reports
/// every problem).
#[derive(Clone, Debug, Default)]
pub(in crate::lang::parser) struct Topology {
    pub sizes: Vec<u32>,
    pub diag: bool,
    pub span: u32,
    pub second: bool,
    pub hinge: bool,
    /// objMesh: the quoted path.
    pub path: Option<String>,
}

/// A size literal: digits, optionally `.` and zeros (`40` or `40.`).
fn size_literal(t: &Token) -> Option<u64> {
    if t.kind != TokKind::Bare {
        return None;
    }
    let (int_part, frac) = t.text.split_once('.').unwrap_or((t.text, ""));
    let ok = !int_part.is_empty()
        && int_part.chars().all(|c| c.is_ascii_digit())
        && frac.chars().all(|c| c == '0');
    if ok {
        int_part.parse().ok()
    } else {
        None
    }
}

/// Pass 1: the topology of a structure statement, or `None` when its sizes are not literals
/// within the limits (reported in pass 2).
pub(in crate::lang::parser) fn topology(kind: StructureKind, args: &[Token]) -> Option<Topology> {
    let n = kind.num_sizes();
    let mut t = Topology {
        span: 1,
        ..Topology::default()
    };
    for a in args.get(..n)? {
        let v = size_literal(a)?;
        t.sizes
            .push(u32::try_from(v.min(MAX_STRUCTURE_NODES)).ok()?);
    }
    if kind == StructureKind::ObjMesh {
        let p = args.first()?;
        if p.kind != TokKind::Quoted {
            return None;
        }
        t.path = Some(p.text.to_string());
    }
    let req = required(kind);
    if let Some(opts) = args.get(req) {
        for (item, _) in split_items(opts.text) {
            let (key, value) = item.split_once('=').unwrap_or((item, ""));
            match key {
                "diag" => t.diag = true,
                "span" => t.span = value.parse().unwrap_or(1).max(1),
                "K2" => t.second = true,
                "hinge" => t.hinge = true,
                _ => {}
            }
        }
    }
    Some(t)
}

impl Builder<'_> {
    /// Pass 2: a structure statement with an accepted argument count.
    pub(super) fn structure(
        &mut self,
        kind: StructureKind,
        label: &str,
        args: &[Token],
        at: At<'_>,
    ) -> Option<Structure> {
        let nsizes = kind.num_sizes();
        let mut sizes = Vec::with_capacity(nsizes);
        let mut ok = true;
        if kind == StructureKind::Icosphere {
            // S is a subdivision level: 0 is the icosahedron; the node count bounds it.
            ok = self.level(&args[0], at).map(|s| sizes.push(s)).is_some();
        } else {
            for t in args.get(..nsizes)? {
                match self.size(t, at) {
                    Some(v) => sizes.push(u32::try_from(v).ok()?),
                    None => ok = false,
                }
            }
        }
        let mut mesh = None;
        let first_arg = if kind == StructureKind::ObjMesh {
            mesh = self.mesh_file(label, &args[0], at);
            ok &= mesh.is_some();
            1
        } else {
            nsizes
        };
        let rest_args = args.get(first_arg..)?;
        let m = self.expr(rest_args.first()?, at);
        let k = self.expr(rest_args.get(1)?, at);
        let z = self.expr(rest_args.get(2)?, at);
        let (num_points, with_radius) = geometry(kind);
        let mut points = Vec::new();
        let mut radius = None;
        let mut i = 3;
        // The argument order: ring3 C R NRM, icosphere C R, objMesh S T; the others vectors only.
        let order: Vec<bool> = match kind {
            StructureKind::Ring3 => vec![false, true, false],
            StructureKind::Icosphere => vec![false, true],
            StructureKind::ObjMesh => vec![true, false],
            _ => vec![false; num_points],
        };
        debug_assert_eq!(order.len(), num_points + usize::from(with_radius));
        for is_radius in order {
            let t = rest_args.get(i)?;
            if is_radius {
                radius = self.expr(t, at);
                ok &= radius.is_some();
            } else {
                match self.vector(t, at) {
                    Some(v) => points.push(v),
                    None => ok = false,
                }
            }
            i += 1;
        }
        let rest = self.with_auto(true, |b| b.expr(rest_args.get(i)?, at));
        let options = match args.get(required(kind)) {
            Some(t) => self.options(kind, t, at),
            None => Some(Vec::new()),
        };
        let (m, k, z, rest, options) = (m?, k?, z?, rest?, options?);
        if !ok {
            return None;
        }
        let s = Structure {
            kind,
            sizes,
            m,
            k,
            z,
            points,
            radius,
            rest,
            options,
            mesh,
        };
        let counts = structures::counts(
            kind,
            &s.sizes,
            s.diag(),
            s.span(),
            s.k2().is_some(),
            s.hinge().is_some(),
            s.mesh.as_deref(),
        );
        if counts.nodes > MAX_STRUCTURE_NODES {
            self.diags.push(
                at.diag(
                    DiagnosticCode::TooLarge,
                    args.first()?.col,
                    format!(
                        "structure `@{label}` would have {} nodes, more than the limit of \
                         {MAX_STRUCTURE_NODES}",
                        counts.nodes
                    ),
                )
                .with_expected(format!("at most {MAX_STRUCTURE_NODES} nodes")),
            );
            return None;
        }
        Some(s)
    }

    /// The icosphere's subdivision level S: an integer literal from 0 to 8 (655,362 nodes; 9
    /// would pass the node limit).
    fn level(&mut self, t: &Token, at: At<'_>) -> Option<u32> {
        match size_literal(t) {
            Some(v) if v <= 8 => Some(v as u32),
            _ => {
                self.diags.push(
                    at.diag(
                        DiagnosticCode::InvalidSize,
                        t.col,
                        format!(
                            "the icosphere's subdivision level `{}` is not 0 … 8",
                            t.source()
                        ),
                    )
                    .with_expected("an integer literal from 0 to 8")
                    .with_found(t.source()),
                );
                None
            }
        }
    }

    /// objMesh's file: pass 1 read it (the script's folder, the host's files); its errors are
    /// reported here, at the path, with the file's line.
    fn mesh_file(&mut self, label: &str, t: &Token, at: At<'_>) -> Option<Arc<MeshData>> {
        if t.kind != TokKind::Quoted {
            self.diags.push(
                at.diag(
                    DiagnosticCode::MeshFile,
                    t.col,
                    format!(
                        "`objMesh` takes its file as a quoted path, found `{}`",
                        t.source()
                    ),
                )
                .with_expected("'path/to/mesh.obj'")
                .with_found(t.source()),
            );
            return None;
        }
        let read = self.symbols.generator(label).and_then(|g| g.mesh.clone());
        match read {
            Some(mesh) => {
                for w in mesh_warnings(&mesh) {
                    self.diags.push(
                        at.diag(DiagnosticCode::SuspiciousValue, t.col, w)
                            .with_found(t.source()),
                    );
                }
                Some(mesh)
            }
            None => {
                let why = self
                    .mesh_errors
                    .iter()
                    .find(|(l, _)| l == label)
                    .map(|(_, e)| e.clone())
                    .unwrap_or_else(|| "the file could not be read".to_string());
                self.diags.push(
                    at.diag(
                        DiagnosticCode::MeshFile,
                        t.col,
                        format!("'{}': {why}", t.text),
                    )
                    .with_found(t.source()),
                );
                None
            }
        }
    }

    /// The options group (§4.0): space-separated `key=value` items and flags.
    fn options(&mut self, kind: StructureKind, t: &Token, at: At<'_>) -> Option<Vec<StructOption>> {
        let mut out: Vec<StructOption> = Vec::new();
        let mut ok = true;
        let mut seen: Vec<&str> = Vec::new();
        let own = own_options(kind);
        for (item, offset) in split_items(t.text) {
            let col = col_plus(t.inner_col(), offset);
            let (key, value) = match item.split_once('=') {
                Some((k, v)) => (k, Some(v)),
                None => (item, None),
            };
            let known = matches!(key, "Zo" | "fix" | "lock") || own.contains(&key);
            let mut bad = |this: &mut Self, message: String| {
                this.diags.push(
                    at.diag(DiagnosticCode::InvalidOption, col, message)
                        .with_found(item.to_string()),
                );
                ok = false;
            };
            if !known {
                let mut takes = vec!["Zo=", "fix=", "lock="];
                takes.extend(own.iter().map(|o| match *o {
                    "diag" => "diag",
                    "span" => "span=",
                    "K2" => "K2=",
                    _ => "hinge=",
                }));
                bad(
                    self,
                    format!(
                        "unknown option `{key}` for `{}` (it takes {})",
                        kind.keyword(),
                        takes.join(", ")
                    ),
                );
                continue;
            }
            if seen.contains(&key) {
                bad(self, format!("option `{key}` given twice"));
                continue;
            }
            seen.push(key);
            let value_col = col_plus(col, key.chars().count() as u32 + 1);
            let option = match (key, value) {
                ("diag", None) => Some(StructOption::Diag),
                ("diag", Some(_)) => {
                    bad(self, "`diag` is a flag: write it without a value".into());
                    None
                }
                (_, None) => {
                    bad(self, format!("option `{key}` needs a value: `{key}=…`"));
                    None
                }
                ("fix", Some(v)) => match Fix::parse(kind, v) {
                    Ok(f) => Some(StructOption::Fix(f)),
                    Err(e) => {
                        bad(self, e);
                        None
                    }
                },
                ("lock", Some(v)) => match v {
                    "z" => Some(StructOption::Lock(Lock::Z)),
                    "xy" => Some(StructOption::Lock(Lock::Xy)),
                    _ => {
                        bad(self, format!("`lock={v}`: expected `lock=z` or `lock=xy`"));
                        None
                    }
                },
                ("span", Some(v)) => match v.parse::<u32>() {
                    Ok(s) if (1..=16).contains(&s) => Some(StructOption::Span(s)),
                    _ => {
                        bad(
                            self,
                            format!("`span={v}`: expected an integer from 1 to 16"),
                        );
                        None
                    }
                },
                (key, Some(v)) => {
                    let e = self.value_expr(v, value_col, at);
                    ok &= e.is_some();
                    e.map(|e| match key {
                        "Zo" => StructOption::Zo(e),
                        "K2" => StructOption::K2(e),
                        _ => StructOption::Hinge(e),
                    })
                }
            };
            if let Some(o) = option {
                out.push(o);
            }
        }
        ok.then_some(out)
    }

    /// An expression standing in an option's value at column `col`.
    fn value_expr(&mut self, text: &str, col: u32, at: At<'_>) -> Option<Expr> {
        let cx = crate::lang::expr_parser::ExprContext {
            symbols: self.symbols,
            line: at.line,
            label: at.label,
            auto: self.auto,
        };
        crate::lang::expr_parser::parse_expression(text, col, &cx, &mut self.diags)
    }
}

/// The warnings of 3-D spec §4.6 on a mesh file: vertices no face or line uses, zero-length
/// edges.
fn mesh_warnings(mesh: &MeshData) -> Vec<String> {
    let mut w = Vec::new();
    if let Some(first) = mesh.unreferenced.first() {
        w.push(format!(
            "{} vertices of '{}' are on no face or line (vertex {} first): they become free \
             masses with no links",
            mesh.unreferenced.len(),
            mesh.path,
            first + 1
        ));
    }
    if mesh.zero_edges > 0 {
        w.push(format!(
            "'{}' has {} zero-length edges: their rest length is 0 and their direction is \
             undefined at rest",
            mesh.path, mesh.zero_edges
        ));
    }
    w
}
