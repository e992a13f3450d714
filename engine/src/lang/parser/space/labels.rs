//! Pass 1 of a 3-D script: what each label names, the structures and adders with the labels
//! they create (3-D spec §4.0, §4.7), and the check that no label is declared twice, written
//! or generated.

use super::structure;
use super::{shape_of, sym_kind, Shape3};
use crate::lang::diagnostics::{Diagnostic, DiagnosticCode, Diags};
use crate::lang::lexer::Token;
use crate::lang::symbols::{Generated, SymKind, Symbols};
use crate::spec::space::structures;
use crate::spec::space::{MeshData, StructureKind};
use std::sync::Arc;

/// Reads the files a script names (`objMesh`), by the path as written: the script's folder
/// for the command line, the preset's files for the plugin. An error is the reason, shown at
/// the path.
pub type Files<'f> = &'f dyn Fn(&str) -> Result<String, String>;

/// What a 3-D pass 1 keeps beside the symbols.
pub(in crate::lang::parser) struct Pass1<'f> {
    files: Files<'f>,
    /// Why an `objMesh`'s file could not be read, by its label.
    pub mesh_errors: Vec<(String, String)>,
    /// Adders, resolved once every structure is known: (label, target, what it adds, line,
    /// column).
    adders: Vec<(String, String, Shape3, u32, u32)>,
}

impl<'f> Pass1<'f> {
    pub fn new(files: Files<'f>) -> Pass1<'f> {
        Pass1 {
            files,
            mesh_errors: Vec::new(),
            adders: Vec::new(),
        }
    }

    /// What a 3-D command's label names, from its keyword (unknown keywords and 1-D-only ones
    /// name [`SymKind::Unknown`], reported in pass 2).
    pub fn kind_of(keyword: &str) -> SymKind {
        shape_of(keyword).map_or(SymKind::Unknown, sym_kind)
    }

    /// A command `label` declared at `line:col` with `args` after its keyword: a structure is
    /// recorded with its topology (an OBJ file read here, once), an adder for [`Pass1::finish`].
    pub fn declared(
        &mut self,
        symbols: &mut Symbols,
        label: &str,
        keyword: &str,
        args: &[Token],
        (line, col): (u32, u32),
    ) {
        match shape_of(keyword) {
            Some(Shape3::Structure(kind)) => {
                let Some(t) = structure::topology(kind, args) else {
                    return;
                };
                let mut mesh = None;
                if kind == StructureKind::ObjMesh {
                    let path = t.path.clone().unwrap_or_default();
                    match (self.files)(&path).and_then(|text| {
                        MeshData::parse(&path, &text).map_err(|e| format!("{e} of the file"))
                    }) {
                        Ok(m) => mesh = Some(Arc::new(m)),
                        Err(e) => {
                            self.mesh_errors.push((label.to_string(), e));
                            return;
                        }
                    }
                }
                let counts = structures::counts(
                    kind,
                    &t.sizes,
                    t.diag,
                    t.span,
                    t.second,
                    t.hinge,
                    mesh.as_deref(),
                );
                symbols.insert_generator(
                    label,
                    Generated {
                        structure: Some((kind, t.sizes)),
                        counts,
                        adds: 0,
                        line,
                        col,
                        mesh,
                    },
                );
            }
            Some(shape @ (Shape3::ContactSet | Shape3::Vdampers)) => {
                let slot = usize::from(shape == Shape3::ContactSet);
                if let Some(t) = args.get(slot) {
                    let target = t.label().to_string();
                    self.adders
                        .push((label.to_string(), target, shape, line, col));
                }
            }
            _ => {}
        }
    }

    /// Records the adders (their counts come from their structures) and reports every
    /// declared label that a structure or adder also creates.
    pub fn finish(mut self, symbols: &mut Symbols, diags: &mut Diags) -> Vec<(String, String)> {
        for (label, target, shape, line, col) in std::mem::take(&mut self.adders) {
            let Some(g) = symbols.generator(&target) else {
                continue;
            };
            let adds = match shape {
                Shape3::ContactSet => g.counts.nodes,
                _ => g.counts.total_links(),
            };
            symbols.insert_generator(
                &label,
                Generated {
                    structure: None,
                    counts: Default::default(),
                    adds,
                    line,
                    col,
                    mesh: None,
                },
            );
        }
        let clashes: Vec<Diagnostic> = symbols
            .declared_labels()
            .filter(|(_, s)| !s.generated)
            .filter_map(|(name, s)| {
                let (owner, g) = symbols.generated(name)?;
                Some(
                    Diagnostic::new(
                        DiagnosticCode::DuplicateLabel,
                        s.line,
                        s.col,
                        format!(
                            "duplicate label `@{name}`: the structure `@{owner}` at line {} \
                             column {} creates it",
                            g.line, g.col
                        ),
                    )
                    .with_label(Some(name)),
                )
            })
            .collect();
        let mut clashes = clashes;
        clashes.sort_by_key(|d| (d.line, d.col));
        for d in clashes {
            diags.push(d);
        }
        self.mesh_errors
    }
}
