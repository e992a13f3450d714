//! Diagnostics of the model-language front end (spec §3.12 f).
//!
//! Every problem carries a 1-based line and column (the column counts Unicode scalar values, a
//! tab counting as one), a typed [`DiagnosticCode`] naming its category, and a message. All
//! diagnostics of a script are collected in one pass; a model is built only when none of them is
//! an error.

use std::fmt;

/// How serious a diagnostic is. Errors block the model; warnings and notes do not (spec
/// §3.12 f). A note marks something accepted as written, such as a legacy form, with the
/// modern way to write it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Severity {
    Error,
    Warning,
    Note,
}

impl fmt::Display for Severity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Note => "note",
        })
    }
}

/// The category of a diagnostic: one variant per error or warning category of spec §3.12 f.
/// The severity is a property of the category ([`DiagnosticCode::severity`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum DiagnosticCode {
    // ---- lexical errors -------------------------------------------------------------------
    /// The input bytes are not valid UTF-8 (spec §3.12 f: "invalid UTF-8").
    InvalidUtf8,
    /// A `[` without its `]` on the same line (spec §3.3, §3.12 a).
    UnterminatedBracket,
    /// A `[` inside a bracket group: groups do not nest (spec §3.3).
    NestedBracket,
    /// A `]` without an opening `[` (spec §3.3).
    StrayBracket,
    /// A `'` without its closing `'` (spec §3.3).
    UnterminatedQuote,
    /// Text that is not a valid number literal where one is required (spec §3.5).
    InvalidNumber,
    /// A number literal that overflows to infinity, e.g. `1e999` (spec §3.12 f).
    NonFiniteNumber,

    // ---- syntactic errors -----------------------------------------------------------------
    /// The wrong number of arguments for the type keyword (spec §2.9, §3.4), including extra
    /// tokens before a ground's position (§3.12 a) and a missing keyword.
    WrongArgumentCount,
    /// A malformed label: empty, or a `param`/`audioParam` name that is not an identifier or is
    /// a function name (spec §3.4).
    BadLabel,
    /// An input or output label that is not `@inN`/`@outN` with a positive decimal N, e.g.
    /// `@in3x` (spec §3.4, §3.12 a).
    BadChannelLabel,
    /// A macro or generator size that is not an integer literal, e.g. `40.5`, `40abc` or a
    /// parameter name (spec §2.7, §3.12 a, §4).
    NonIntegerSize,
    /// A macro size below 2 (spec §2.7), or a generator size below the shape's minimum (§4).
    InvalidSize,
    /// A macro with more than 1 048 576 nodes, a size that overflows, too many open scopes, or
    /// generators beyond their node, link or per-script element limits.
    TooLarge,
    /// An expression that does not follow the grammar of spec §3.5.
    ExpressionSyntax,
    /// An expression nested deeper than the front end accepts (guard against absurd input).
    ExpressionTooDeep,
    /// A function called with the wrong number of arguments (spec §3.5).
    WrongArity,
    /// A function name used without a call, e.g. `sqrt` alone (spec §3.5).
    FunctionWithoutCall,
    /// A position or velocity vector that does not have 3 coordinates `[x y z]` (spec §3.7).
    VectorSize,
    /// Something other than `@label` or `[@macro …]` in an endpoint or target slot (spec §3.4).
    ExpectedEndpoint,
    /// A directive with a missing, extra or invalid argument (spec §3.11), including a
    /// `~generate` name that is not an identifier, an argument that is not `key=value`, and a
    /// key given twice.
    InvalidDirectiveArgument,
    /// `~generate` of a generator kind that does not exist (spec §4).
    UnknownGenerator,
    /// A `~generate` key that the generator does not take, e.g. `span=` on a mesh.
    UnknownGeneratorKey,
    /// A `~generate` directive without one of its generator's required keys.
    MissingGeneratorKey,
    /// A `~generate` value of the wrong form (`fixed=sides`, `size=4` for a mesh), or a value
    /// that cannot be evaluated when the script is read (an audio-rate parameter, a parameter
    /// declared later, NaN, M ≤ 0).
    InvalidGeneratorValue,

    // ---- semantic errors ------------------------------------------------------------------
    /// A label used twice; parameters and elements share one namespace (spec §3.4). Labels
    /// created by `~generate` count too.
    DuplicateLabel,
    /// An expression names no declared parameter, or calls an unknown function such as `floor`
    /// (spec §3.5, §3.12 c).
    UndefinedName,
    /// An expression names an element, not a parameter (spec §3.4).
    NotAParameter,
    /// An endpoint or target names no element (spec §3.4).
    UndefinedElement,
    /// An endpoint or target that is not a point: an output, a parameter, an interaction or a
    /// force input (spec §3.4).
    NotAPoint,
    /// Connection-point brackets on something that is not a macro (spec §2.8).
    NotAMacro,
    /// The wrong number of connection coordinates for the macro (spec §2.8, §3.12 a).
    WrongCoordinateCount,
    /// A macro referred to without connection-point brackets (spec §2.7).
    BareMacroReference,
    /// An unknown type keyword (spec §3.12 a).
    UnknownKeyword,
    /// Two conflicting `~samplerate` directives (spec §3.11), or two `~dim`, `~gravity` or
    /// `~friction` lines (3-D spec §1.1, §1.10).
    ConflictingDirective,
    /// An element or directive of the other dimension: a 1-D element (`massG`, `string`,
    /// `mesh`, `~generate`…) in a `~dim 3` script, or a 3-D one (`vdamper`, `string3`,
    /// `~gravity`…) in a 1-D script (3-D spec §1.1, §1.8).
    DimensionMismatch,
    /// A mesh file that cannot be read, or an error inside it (3-D spec §4.6): the message
    /// gives the file's line.
    MeshFile,
    /// A structure option that is unknown, given twice, or of the wrong form (3-D spec §4.0).
    InvalidOption,
    /// A constant direction that is the zero vector (3-D spec §1.7).
    ZeroDirection,

    // ---- warnings -------------------------------------------------------------------------
    /// A separator `+` directly between two non-blank characters, e.g. `a+b` (spec §3.3).
    PlusSeparator,
    /// An ignored line that looks like a command with a forgotten `@` (spec §3.2).
    IgnoredCommandLike,
    /// An unknown `~` directive, which is ignored (spec §3.11).
    UnknownDirective,
    /// `~end NAME` of a scope that is not open (spec §3.10).
    ScopeNotOpen,
    /// `~begin NAME` of a scope that is already open (spec §3.10).
    ScopeAlreadyOpen,
    /// More diagnostics than the front end records; the rest are counted but not listed.
    TooManyDiagnostics,
    /// A legal 3-D value that is probably a mistake (3-D spec §5.6, §4.6): a 1-D line's
    /// damping read as a rest length, a string without tension, a contact that cannot engage,
    /// a mesh vertex no face uses.
    SuspiciousValue,

    // ---- notes ----------------------------------------------------------------------------
    /// A connection point in the legacy proxy syntax of the MIMS proxy branch, a bare macro
    /// label whose coordinates follow it or end the line (`@in1 frcInput @s 0.3`, `@c contact
    /// @me @m K Z 0. u:w`); it is read as the bracket form (spec §2.8, §3.14).
    LegacyProxySyntax,
    /// A macro without its trailing velocity (legacy MIMS, `@s string 50 1. 0.6 0.01 0.`); the
    /// velocity is 0 (spec §2.7, §3.14).
    LegacyMacroVelocity,
}

impl DiagnosticCode {
    /// Every category, in declaration order (errors first, then warnings, then notes).
    pub const ALL: [DiagnosticCode; 47] = [
        DiagnosticCode::InvalidUtf8,
        DiagnosticCode::UnterminatedBracket,
        DiagnosticCode::NestedBracket,
        DiagnosticCode::StrayBracket,
        DiagnosticCode::UnterminatedQuote,
        DiagnosticCode::InvalidNumber,
        DiagnosticCode::NonFiniteNumber,
        DiagnosticCode::WrongArgumentCount,
        DiagnosticCode::BadLabel,
        DiagnosticCode::BadChannelLabel,
        DiagnosticCode::NonIntegerSize,
        DiagnosticCode::InvalidSize,
        DiagnosticCode::TooLarge,
        DiagnosticCode::ExpressionSyntax,
        DiagnosticCode::ExpressionTooDeep,
        DiagnosticCode::WrongArity,
        DiagnosticCode::FunctionWithoutCall,
        DiagnosticCode::VectorSize,
        DiagnosticCode::ExpectedEndpoint,
        DiagnosticCode::InvalidDirectiveArgument,
        DiagnosticCode::UnknownGenerator,
        DiagnosticCode::UnknownGeneratorKey,
        DiagnosticCode::MissingGeneratorKey,
        DiagnosticCode::InvalidGeneratorValue,
        DiagnosticCode::DuplicateLabel,
        DiagnosticCode::UndefinedName,
        DiagnosticCode::NotAParameter,
        DiagnosticCode::UndefinedElement,
        DiagnosticCode::NotAPoint,
        DiagnosticCode::NotAMacro,
        DiagnosticCode::WrongCoordinateCount,
        DiagnosticCode::BareMacroReference,
        DiagnosticCode::UnknownKeyword,
        DiagnosticCode::ConflictingDirective,
        DiagnosticCode::DimensionMismatch,
        DiagnosticCode::MeshFile,
        DiagnosticCode::InvalidOption,
        DiagnosticCode::ZeroDirection,
        DiagnosticCode::PlusSeparator,
        DiagnosticCode::IgnoredCommandLike,
        DiagnosticCode::UnknownDirective,
        DiagnosticCode::ScopeNotOpen,
        DiagnosticCode::ScopeAlreadyOpen,
        DiagnosticCode::TooManyDiagnostics,
        DiagnosticCode::SuspiciousValue,
        DiagnosticCode::LegacyProxySyntax,
        DiagnosticCode::LegacyMacroVelocity,
    ];

    /// Whether this category is an error, a warning or a note (spec §3.12 f).
    pub fn severity(self) -> Severity {
        use DiagnosticCode::*;
        match self {
            LegacyProxySyntax | LegacyMacroVelocity => Severity::Note,
            PlusSeparator | IgnoredCommandLike | UnknownDirective | ScopeNotOpen
            | ScopeAlreadyOpen | TooManyDiagnostics | SuspiciousValue => Severity::Warning,
            _ => Severity::Error,
        }
    }

    /// A short kebab-case name for the category, stable for tools.
    pub fn name(self) -> &'static str {
        use DiagnosticCode::*;
        match self {
            InvalidUtf8 => "invalid-utf8",
            UnterminatedBracket => "unterminated-bracket",
            NestedBracket => "nested-bracket",
            StrayBracket => "stray-bracket",
            UnterminatedQuote => "unterminated-quote",
            InvalidNumber => "invalid-number",
            NonFiniteNumber => "non-finite-number",
            WrongArgumentCount => "wrong-argument-count",
            BadLabel => "bad-label",
            BadChannelLabel => "bad-channel-label",
            NonIntegerSize => "non-integer-size",
            InvalidSize => "invalid-size",
            TooLarge => "too-large",
            ExpressionSyntax => "expression-syntax",
            ExpressionTooDeep => "expression-too-deep",
            WrongArity => "wrong-arity",
            FunctionWithoutCall => "function-without-call",
            VectorSize => "vector-size",
            ExpectedEndpoint => "expected-endpoint",
            InvalidDirectiveArgument => "invalid-directive-argument",
            UnknownGenerator => "unknown-generator",
            UnknownGeneratorKey => "unknown-generator-key",
            MissingGeneratorKey => "missing-generator-key",
            InvalidGeneratorValue => "invalid-generator-value",
            DuplicateLabel => "duplicate-label",
            UndefinedName => "undefined-name",
            NotAParameter => "not-a-parameter",
            UndefinedElement => "undefined-element",
            NotAPoint => "not-a-point",
            NotAMacro => "not-a-macro",
            WrongCoordinateCount => "wrong-coordinate-count",
            BareMacroReference => "bare-macro-reference",
            UnknownKeyword => "unknown-keyword",
            ConflictingDirective => "conflicting-directive",
            DimensionMismatch => "dimension-mismatch",
            MeshFile => "mesh-file",
            InvalidOption => "invalid-option",
            ZeroDirection => "zero-direction",
            PlusSeparator => "plus-separator",
            IgnoredCommandLike => "ignored-command-like-line",
            UnknownDirective => "unknown-directive",
            ScopeNotOpen => "scope-not-open",
            ScopeAlreadyOpen => "scope-already-open",
            TooManyDiagnostics => "too-many-diagnostics",
            SuspiciousValue => "suspicious-value",
            LegacyProxySyntax => "legacy-proxy-syntax",
            LegacyMacroVelocity => "legacy-macro-velocity",
        }
    }
}

impl fmt::Display for DiagnosticCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One problem found in a script (spec §3.12 f).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Diagnostic {
    pub severity: Severity,
    pub code: DiagnosticCode,
    /// 1-based line.
    pub line: u32,
    /// 1-based column in Unicode scalar values; a tab counts as one.
    pub col: u32,
    /// The label (without `@`) of the command the problem is in, when there is one.
    pub label: Option<String>,
    pub message: String,
    /// What the language expected there, when that is useful.
    pub expected: Option<String>,
    /// What the script had there, when that is useful.
    pub found: Option<String>,
}

impl Diagnostic {
    /// A diagnostic of category `code` (its severity follows the category).
    pub fn new(code: DiagnosticCode, line: u32, col: u32, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: code.severity(),
            code,
            line,
            col,
            label: None,
            message: message.into(),
            expected: None,
            found: None,
        }
    }

    /// True for errors.
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    pub(crate) fn with_label(mut self, label: Option<&str>) -> Self {
        self.label = label.map(str::to_string);
        self
    }

    pub(crate) fn with_expected(mut self, expected: impl Into<String>) -> Self {
        self.expected = Some(expected.into());
        self
    }

    pub(crate) fn with_found(mut self, found: impl Into<String>) -> Self {
        self.found = Some(found.into());
        self
    }
}

impl fmt::Display for Diagnostic {
    /// `LINE:COL: error|warning|note: message` (spec §3.12 f).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}: {}: {}",
            self.line, self.col, self.severity, self.message
        )
    }
}

/// The most diagnostics recorded for one script. Beyond it, diagnostics are counted (so errors
/// still block the model) but not stored, which bounds memory on megabytes of garbage. When
/// only warnings fit, the first error beyond the limit is listed too, so a blocked model always
/// shows an error.
pub const MAX_DIAGNOSTICS: usize = 10_000;

/// Collects diagnostics in one pass.
#[derive(Debug, Default)]
pub(crate) struct Diags {
    list: Vec<Diagnostic>,
    errors: usize,
    dropped: usize,
    /// The first error that did not fit, kept so that a blocked model always lists an error.
    first_dropped_error: Option<Diagnostic>,
    /// Lines with invalid UTF-8, in order: their report stands for the line, and what the
    /// U+FFFD in place of the bytes makes fail later (a bad keyword or expression character)
    /// is not reported again.
    utf8_lines: Vec<u32>,
}

impl Diags {
    /// Reports invalid UTF-8 on `d.line` (see `utf8_lines`).
    pub(crate) fn push_invalid_utf8(&mut self, d: Diagnostic) {
        if self.utf8_lines.last() != Some(&d.line) {
            self.utf8_lines.push(d.line);
        }
        self.push(d);
    }

    pub(crate) fn push(&mut self, d: Diagnostic) {
        if d.code != DiagnosticCode::InvalidUtf8 && self.utf8_lines.binary_search(&d.line).is_ok() {
            return;
        }
        if d.is_error() {
            self.errors += 1;
        }
        if self.list.len() < MAX_DIAGNOSTICS {
            self.list.push(d);
        } else {
            self.dropped += 1;
            if d.is_error() && self.first_dropped_error.is_none() {
                self.first_dropped_error = Some(d);
            }
        }
    }

    pub(crate) fn error_count(&self) -> usize {
        self.errors
    }

    /// The diagnostics sorted by position (stable, so same-position ones keep their order).
    pub(crate) fn finish(mut self) -> Vec<Diagnostic> {
        if !self.list.iter().any(Diagnostic::is_error) {
            if let Some(d) = self.first_dropped_error.take() {
                self.list.push(d);
                self.dropped -= 1;
            }
        }
        self.list.sort_by_key(|d| (d.line, d.col));
        if self.dropped > 0 {
            let (line, col) = self.list.last().map(|d| (d.line, d.col)).unwrap_or((1, 1));
            self.list.push(Diagnostic::new(
                DiagnosticCode::TooManyDiagnostics,
                line,
                col,
                format!(
                    "{} more diagnostics were not listed ({} shown)",
                    self.dropped, MAX_DIAGNOSTICS
                ),
            ));
        }
        self.list
    }
}
