//! The model-language front end (spec §3): parser, diagnostics and canonical printer.
//!
//! ```
//! use ressort_engine::lang::{parse, print};
//! let parsed = parse("@K param 0.1\n@o osc 1. K 0.0003 0. 0.  # a comment\n@out1 posOutput @o\n");
//! assert!(parsed.diagnostics.is_empty());
//! let spec = parsed.spec.unwrap();
//! assert_eq!(parse(&print(&spec)).spec, Some(spec));
//! ```
//!
//! * [`parse`] / [`parse_bytes`] read a script into a [`crate::ModelSpec`], collecting every
//!   [`Diagnostic`] in one pass with its line and column (§3.12 f). The spec is produced only
//!   when there is no error; warnings do not block it.
//! * [`print`] writes canonical script text that parses back to the same spec.
//!
//! The language is a superset of MIMS4Max (§3.12 a): `#` comments anywhere, scientific
//! notation, expressions with the functions of §3.5, legacy `massG`, two-parameter `spring` and
//! `nlSpring`, `~samplerate raw|scaled`, nested and overlapping buffer scopes (§3.10), legacy
//! trailing buffer tags (§6.4), the proxy branch's bare connection points and macros without
//! velocity (read as the modern form, with a note; §3.14), and the `~generate` directive, which
//! expands a topology generator of §4 inline into explicit, addressable elements:
//!
//! ```
//! use ressort_engine::lang::parse;
//! let parsed = parse(
//!     "~generate triangle tri size=10 M=1 K=0.3 Z=1e-4 fixed=corners from=0,0,0 to=1,1,0\n\
//!      @out1 posOutput @tri_m3_2\n",
//! );
//! let spec = parsed.spec.unwrap();
//! assert!(spec.param("tri_K").is_some());
//! assert!(spec.element("tri_m3_2").is_some());
//! ```
//!
//! See `docs/LANGUAGE.md` for the whole language.

mod diagnostics;
mod expr_parser;
mod generate;
mod legacy;
mod lexer;
mod numbers;
mod parser;
mod printer;
mod space_printer;
mod symbols;

pub use diagnostics::{Diagnostic, DiagnosticCode, Severity, MAX_DIAGNOSTICS};
pub use expr_parser::MAX_NESTING;
pub use generate::MAX_GENERATED_ELEMENTS;
pub use parser::{
    parse, parse_bytes, parse_bytes_with_files, parse_with_files, Files, MAX_EXCITERS,
    MAX_MACRO_NODES, MAX_OPEN_SCOPES,
};
pub use printer::print;

use crate::spec::ModelSpec;

/// The files beside a script read from `folder`, for [`parse_with_files`]: `objMesh
/// 'bell.obj'` reads `folder/bell.obj` (3-D spec §4.6: paths are relative to the script's
/// folder). An error is the reason, which the diagnostic shows at the path.
pub fn folder_files(folder: &std::path::Path) -> impl Fn(&str) -> Result<String, String> + '_ {
    move |path: &str| {
        std::fs::read_to_string(folder.join(path)).map_err(|e| format!("cannot read {path}: {e}"))
    }
}

/// The result of parsing a script.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Parsed {
    /// The model, when the script has no error (warnings and notes do not block it).
    pub spec: Option<ModelSpec>,
    /// Every error, warning and note, sorted by line and column.
    pub diagnostics: Vec<Diagnostic>,
}

impl Parsed {
    /// True when the script has no error.
    pub fn is_ok(&self) -> bool {
        self.spec.is_some()
    }

    /// The errors.
    pub fn errors(&self) -> impl Iterator<Item = &Diagnostic> {
        self.diagnostics.iter().filter(|d| d.is_error())
    }

    /// The warnings.
    pub fn warnings(&self) -> impl Iterator<Item = &Diagnostic> {
        self.diagnostics
            .iter()
            .filter(|d| d.severity == Severity::Warning)
    }

    /// The notes: forms accepted as written, with the modern way to write them (legacy syntax).
    pub fn notes(&self) -> impl Iterator<Item = &Diagnostic> {
        self.diagnostics
            .iter()
            .filter(|d| d.severity == Severity::Note)
    }

    /// The spec, or every diagnostic when there is an error.
    pub fn into_result(self) -> Result<ModelSpec, Vec<Diagnostic>> {
        match self.spec {
            Some(spec) => Ok(spec),
            None => Err(self.diagnostics),
        }
    }
}
