//! What can go wrong compiling a model: one [`CompileError`] per problem, each on its element
//! (or the whole model), all of them collected in [`CompileErrors`].

use super::{MAX_EXPR_DEPTH, MAX_POINTS, SAMPLE_RATE_RANGE_HZ};
use crate::spec::Span;
use std::fmt;

/// What went wrong compiling one element (or the whole model).
#[derive(Clone, Debug, PartialEq)]
pub enum CompileErrorKind {
    /// The sample rate is not a finite number in [`SAMPLE_RATE_RANGE_HZ`].
    InvalidSampleRate(f64),
    /// The motion interval is 0.
    InvalidMotionInterval,
    /// The label is already used by the element or parameter at `first`.
    DuplicateLabel { first: Span },
    /// A parameter name that is not an identifier, or is a function name.
    InvalidParamName,
    /// An expression names something that is not declared.
    UndefinedName(String),
    /// An expression names an element, not a parameter.
    NotAParameter(String),
    /// A function called with the wrong number of arguments.
    WrongArity {
        func: &'static str,
        expected: usize,
        found: usize,
    },
    /// An expression nested deeper than [`MAX_EXPR_DEPTH`].
    ExpressionTooDeep,
    /// An endpoint or target names no element.
    UndefinedElement(String),
    /// An endpoint or target names something that is not a point (`found` says what).
    NotAPoint { target: String, found: &'static str },
    /// A macro referred to without connection-point brackets.
    BareMacroReference(String),
    /// Connection-point brackets on something that is not a macro.
    NotAMacro(String),
    /// The wrong number of connection coordinates for the macro.
    WrongCoordinateCount {
        target: String,
        expected: usize,
        found: usize,
    },
    /// A macro size below 2.
    InvalidSize(u32),
    /// The model would have more than [`MAX_POINTS`] points.
    TooLarge { points: usize },
    /// An input or output channel numbered 0.
    InvalidChannel,
    /// A constant argument outside its domain (e.g. a mass that is not > 0).
    InvalidValue { what: &'static str, value: f64 },
    /// A 3-D structure that cannot be generated (3-D spec §4), or an element a 3-D model
    /// cannot build, with why.
    Structure(String),
}

/// A compile error: what, on which element, and where in the script.
#[derive(Clone, Debug, PartialEq)]
pub struct CompileError {
    pub kind: CompileErrorKind,
    /// The label of the element or parameter involved (empty for model-wide errors).
    pub label: String,
    pub span: Span,
}

impl fmt::Display for CompileErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use CompileErrorKind::*;
        match self {
            InvalidSampleRate(v) => write!(
                f,
                "sample rate {v} Hz is outside {}..={} Hz",
                SAMPLE_RATE_RANGE_HZ.start(),
                SAMPLE_RATE_RANGE_HZ.end()
            ),
            InvalidMotionInterval => write!(f, "motion interval must be at least 1 sample"),
            DuplicateLabel { first } if first.is_known() => write!(
                f,
                "duplicate label, first used at line {} column {}",
                first.line, first.col
            ),
            DuplicateLabel { .. } => write!(f, "duplicate label"),
            InvalidParamName => write!(
                f,
                "a parameter name must be an identifier that is not a function name"
            ),
            UndefinedName(n) => write!(f, "undefined name `{n}` in expression"),
            NotAParameter(n) => write!(f, "`{n}` is an element, not a parameter"),
            WrongArity {
                func,
                expected,
                found,
            } => write!(f, "`{func}` takes {expected} argument(s), found {found}"),
            ExpressionTooDeep => write!(f, "expression nested deeper than {MAX_EXPR_DEPTH}"),
            UndefinedElement(t) => write!(f, "undefined element `@{t}`"),
            NotAPoint { target, found } => {
                write!(f, "`@{target}` is {found}, not a point")
            }
            BareMacroReference(t) => write!(
                f,
                "macro `@{t}` must be addressed through a connection point such as `[@{t} 0.5]`"
            ),
            NotAMacro(t) => write!(f, "connection point on `@{t}`, which is not a macro"),
            WrongCoordinateCount {
                target,
                expected,
                found,
            } => write!(
                f,
                "connection point on `@{target}` needs {expected} coordinate(s), found {found}"
            ),
            InvalidSize(v) => write!(f, "macro size {v} is below 2"),
            TooLarge { points } => write!(
                f,
                "model has {points} points, more than the limit of {MAX_POINTS}"
            ),
            InvalidChannel => write!(f, "channel numbers start at 1"),
            InvalidValue { what, value } => write!(f, "{what}, found {value}"),
            Structure(why) => write!(f, "{why}"),
        }
    }
}

impl fmt::Display for CompileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if !self.label.is_empty() {
            write!(f, "@{}: ", self.label)?;
        }
        write!(f, "{}", self.kind)?;
        if self.span.is_known() {
            write!(f, " at line {} column {}", self.span.line, self.span.col)?;
        }
        Ok(())
    }
}

impl std::error::Error for CompileError {}

/// Every error of one compilation.
#[derive(Clone, Debug, PartialEq)]
pub struct CompileErrors(pub Vec<CompileError>);

impl fmt::Display for CompileErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for CompileErrors {}
