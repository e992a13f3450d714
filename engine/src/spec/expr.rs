//! Argument expressions (spec §3.5, normative decision §3.12 c).
//!
//! An element argument is an expression over numbers and parameter names:
//!
//! ```text
//! expr    := term  { ("+" | "-") term }
//! term    := unary { ("*" | "/") unary }
//! unary   := ("-" | "+") unary | primary
//! primary := number | name | call | "(" expr ")"
//! func    := sqrt | pow | exp | log | sin | cos | tan | abs | min | max | clamp
//! ```
//!
//! This module holds the tree the parser and the builder produce, its canonical printing, and a
//! small stack program ([`Program`]) that the compiled model evaluates without allocating.
//! Arithmetic is IEEE-754: division by zero or `sqrt(-1)` give `inf`/`NaN`, never a panic.

use std::fmt;

/// A binary operator of the expression grammar.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
}

impl BinOp {
    /// The operator's character.
    pub fn symbol(self) -> char {
        match self {
            BinOp::Add => '+',
            BinOp::Sub => '-',
            BinOp::Mul => '*',
            BinOp::Div => '/',
        }
    }

    fn precedence(self) -> u8 {
        match self {
            BinOp::Add | BinOp::Sub => 1,
            BinOp::Mul | BinOp::Div => 2,
        }
    }

    fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            BinOp::Add => a + b,
            BinOp::Sub => a - b,
            BinOp::Mul => a * b,
            BinOp::Div => a / b,
        }
    }
}

/// The functions of spec §3.5. Anything else (`pi`, `floor`, `SAMPLERATE`, …) is not part of the
/// language.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Func {
    Sqrt,
    Pow,
    Exp,
    Log,
    Sin,
    Cos,
    Tan,
    Abs,
    Min,
    Max,
    Clamp,
}

impl Func {
    /// Every function, in the order of the specification.
    pub const ALL: [Func; 11] = [
        Func::Sqrt,
        Func::Pow,
        Func::Exp,
        Func::Log,
        Func::Sin,
        Func::Cos,
        Func::Tan,
        Func::Abs,
        Func::Min,
        Func::Max,
        Func::Clamp,
    ];

    /// The function's name in scripts.
    pub fn name(self) -> &'static str {
        match self {
            Func::Sqrt => "sqrt",
            Func::Pow => "pow",
            Func::Exp => "exp",
            Func::Log => "log",
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Abs => "abs",
            Func::Min => "min",
            Func::Max => "max",
            Func::Clamp => "clamp",
        }
    }

    /// Looks a function up by its script name.
    pub fn from_name(name: &str) -> Option<Func> {
        Func::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The number of arguments the function takes.
    pub fn arity(self) -> usize {
        match self {
            Func::Pow | Func::Min | Func::Max => 2,
            Func::Clamp => 3,
            _ => 1,
        }
    }

    /// Applies the function. `args` has exactly [`Func::arity`] values.
    fn apply(self, args: &[f64]) -> f64 {
        match self {
            Func::Sqrt => args[0].sqrt(),
            Func::Pow => args[0].powf(args[1]),
            Func::Exp => args[0].exp(),
            Func::Log => args[0].ln(),
            Func::Sin => args[0].sin(),
            Func::Cos => args[0].cos(),
            Func::Tan => args[0].tan(),
            Func::Abs => args[0].abs(),
            Func::Min => args[0].min(args[1]),
            Func::Max => args[0].max(args[1]),
            // `f64::clamp` panics when lo > hi or either is NaN; this never does.
            Func::Clamp => args[0].max(args[1]).min(args[2]),
        }
    }
}

/// An argument expression. Parameter names are stored without the `@`.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A numeric literal.
    Num(f64),
    /// A reference to a `param` or `audioParam`.
    Name(Box<str>),
    /// Unary minus.
    Neg(Box<Expr>),
    /// A binary operation.
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// A function call; the argument count is checked by the parser and the compiler.
    Call(Func, Box<[Expr]>),
}

// A spec holds an expression for every argument of every element: names and call arguments
// are boxed slices, not growable vectors, so that an expression is three words (a script
// written element by element builds and copies thousands of them).
#[cfg(target_pointer_width = "64")]
const _: () = assert!(std::mem::size_of::<Expr>() == 24);

impl Expr {
    /// A reference to the parameter `name`.
    pub fn param(name: &str) -> Expr {
        Expr::Name(name.into())
    }

    /// A call of `func` on `args`.
    pub fn call(func: Func, args: Vec<Expr>) -> Expr {
        Expr::Call(func, args.into_boxed_slice())
    }

    /// The literal value, if this is a plain (possibly negated) number.
    pub fn as_number(&self) -> Option<f64> {
        match self {
            Expr::Num(v) => Some(*v),
            Expr::Neg(inner) => inner.as_number().map(|v| -v),
            _ => None,
        }
    }

    /// Calls `f` on every parameter name the expression refers to.
    pub fn for_each_name<'a>(&'a self, f: &mut impl FnMut(&'a str)) {
        match self {
            Expr::Num(_) => {}
            Expr::Name(n) => f(n),
            Expr::Neg(e) => e.for_each_name(f),
            Expr::Binary(_, a, b) => {
                a.for_each_name(f);
                b.for_each_name(f);
            }
            Expr::Call(_, args) => args.iter().for_each(|a| a.for_each_name(f)),
        }
    }

    /// True when the expression refers to no parameter.
    pub fn is_constant(&self) -> bool {
        let mut constant = true;
        self.for_each_name(&mut |_| constant = false);
        constant
    }

    /// Evaluates the tree directly, looking names up with `lookup`. Unknown names and calls with
    /// the wrong number of arguments evaluate to NaN. Used off the audio thread (analysis,
    /// initial positions); the audio thread runs a compiled [`Program`].
    pub fn eval(&self, lookup: &impl Fn(&str) -> Option<f64>) -> f64 {
        match self {
            Expr::Num(v) => *v,
            Expr::Name(n) => lookup(n).unwrap_or(f64::NAN),
            Expr::Neg(e) => -e.eval(lookup),
            Expr::Binary(op, a, b) => op.apply(a.eval(lookup), b.eval(lookup)),
            Expr::Call(func, args) => {
                if args.len() != func.arity() {
                    return f64::NAN;
                }
                let mut values = [0.0; 3];
                for (slot, arg) in values.iter_mut().zip(args) {
                    *slot = arg.eval(lookup);
                }
                func.apply(&values[..args.len()])
            }
        }
    }

    /// The tree's depth (a number is 1). The compiler bounds it so evaluation stacks stay small.
    pub fn depth(&self) -> usize {
        match self {
            Expr::Num(_) | Expr::Name(_) => 1,
            Expr::Neg(e) => 1 + e.depth(),
            Expr::Binary(_, a, b) => 1 + a.depth().max(b.depth()),
            Expr::Call(_, args) => 1 + args.iter().map(Expr::depth).max().unwrap_or(0),
        }
    }

    fn precedence(&self) -> u8 {
        match self {
            Expr::Binary(op, ..) => op.precedence(),
            Expr::Neg(_) => 3,
            // A negative literal prints with its sign, so it binds like a unary minus.
            Expr::Num(v) if v.is_sign_negative() => 3,
            _ => 4,
        }
    }
}

impl From<f64> for Expr {
    fn from(value: f64) -> Self {
        Expr::Num(value)
    }
}

impl From<&str> for Expr {
    /// A bare string in the builder is a parameter name.
    fn from(name: &str) -> Self {
        Expr::param(name)
    }
}

macro_rules! expr_binop {
    ($trait:ident, $method:ident, $op:expr) => {
        impl std::ops::$trait for Expr {
            type Output = Expr;
            fn $method(self, rhs: Expr) -> Expr {
                Expr::Binary($op, Box::new(self), Box::new(rhs))
            }
        }
    };
}
expr_binop!(Add, add, BinOp::Add);
expr_binop!(Sub, sub, BinOp::Sub);
expr_binop!(Mul, mul, BinOp::Mul);
expr_binop!(Div, div, BinOp::Div);

impl std::ops::Neg for Expr {
    type Output = Expr;
    fn neg(self) -> Expr {
        Expr::Neg(Box::new(self))
    }
}

/// Formats a literal so that it reads back to the same `f64`: plain decimal for ordinary
/// magnitudes, scientific notation for very large or small ones. Non-finite values, which the
/// language cannot express, print as `nan`, `inf` or `-inf`.
pub fn format_number(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}").to_lowercase();
    }
    let abs = v.abs();
    if abs == 0.0 || (1e-4..1e15).contains(&abs) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

impl fmt::Display for Expr {
    /// Canonical infix text with the fewest parentheses that keep the tree. The text contains
    /// spaces around `+` and `-`, so in a script it belongs inside `[ ]` (the printer does that).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Expr::Num(v) => f.write_str(&format_number(*v)),
            Expr::Name(n) => f.write_str(n),
            Expr::Neg(e) => {
                if e.precedence() < 3 {
                    write!(f, "-({e})")
                } else {
                    write!(f, "-{e}")
                }
            }
            Expr::Binary(op, a, b) => {
                let p = op.precedence();
                if a.precedence() < p {
                    write!(f, "({a})")?;
                } else {
                    write!(f, "{a}")?;
                }
                match op {
                    BinOp::Add | BinOp::Sub => write!(f, " {} ", op.symbol())?,
                    _ => write!(f, "{}", op.symbol())?,
                }
                // Left-associative: an equal-precedence right operand needs parentheses.
                if b.precedence() <= p {
                    write!(f, "({b})")
                } else {
                    write!(f, "{b}")
                }
            }
            Expr::Call(func, args) => {
                write!(f, "{}(", func.name())?;
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        f.write_str(", ")?;
                    }
                    write!(f, "{a}")?;
                }
                f.write_str(")")
            }
        }
    }
}

/// One instruction of a compiled expression.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Op {
    Const(f64),
    /// Push the current value of parameter slot `n`.
    Param(u32),
    Neg,
    Bin(BinOp),
    Call(Func),
}

/// Compiled expressions: one flat instruction array shared by all the expressions of a model,
/// evaluated on a stack whose capacity is reserved at compile time (no allocation afterwards).
#[derive(Clone, Debug, Default)]
pub(crate) struct Program {
    ops: Vec<Op>,
    /// The deepest stack any expression needs.
    max_stack: usize,
}

/// A compiled expression: a range of [`Program`] instructions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ExprRef {
    start: u32,
    len: u32,
}

impl Program {
    /// Appends `expr`, resolving names with `resolve`. Returns the unresolved name on failure.
    pub(crate) fn push<'a>(
        &mut self,
        expr: &'a Expr,
        resolve: &impl Fn(&str) -> Option<u32>,
    ) -> Result<ExprRef, &'a str> {
        let start = self.ops.len();
        let mut depth = 0usize;
        let mut max_depth = 0usize;
        self.emit(expr, resolve, &mut depth, &mut max_depth)?;
        self.max_stack = self.max_stack.max(max_depth);
        Ok(ExprRef {
            start: start as u32,
            len: (self.ops.len() - start) as u32,
        })
    }

    fn emit<'a>(
        &mut self,
        expr: &'a Expr,
        resolve: &impl Fn(&str) -> Option<u32>,
        depth: &mut usize,
        max_depth: &mut usize,
    ) -> Result<(), &'a str> {
        let mut push_one = |op: Op, depth: &mut usize| {
            self.ops.push(op);
            *depth += 1;
            *max_depth = (*max_depth).max(*depth);
        };
        match expr {
            Expr::Num(v) => push_one(Op::Const(*v), depth),
            Expr::Name(n) => push_one(Op::Param(resolve(n).ok_or(&**n)?), depth),
            Expr::Neg(e) => {
                self.emit(e, resolve, depth, max_depth)?;
                self.ops.push(Op::Neg);
            }
            Expr::Binary(op, a, b) => {
                self.emit(a, resolve, depth, max_depth)?;
                self.emit(b, resolve, depth, max_depth)?;
                self.ops.push(Op::Bin(*op));
                *depth -= 1;
            }
            Expr::Call(func, args) => {
                // The compiler checks arity before it gets here; a mismatch would unbalance
                // the stack, so it is treated as a NaN constant.
                if args.len() != func.arity() {
                    push_one(Op::Const(f64::NAN), depth);
                    return Ok(());
                }
                for a in args {
                    self.emit(a, resolve, depth, max_depth)?;
                }
                self.ops.push(Op::Call(*func));
                *depth -= args.len() - 1;
            }
        }
        Ok(())
    }

    /// Appends the constant `v`, as [`Program::push`] appends `Expr::Num(v)`: the commonest
    /// argument, without the tree walk.
    pub(crate) fn push_const(&mut self, v: f64) -> ExprRef {
        let start = self.ops.len() as u32;
        self.ops.push(Op::Const(v));
        self.max_stack = self.max_stack.max(1);
        ExprRef { start, len: 1 }
    }

    /// Room for `ops` more instructions.
    pub(crate) fn reserve(&mut self, ops: usize) {
        self.ops.reserve(ops);
    }

    /// The parameter slots `e` reads (repeated if it reads one twice).
    pub(crate) fn params_read(&self, e: ExprRef) -> impl Iterator<Item = u32> + '_ {
        self.ops[e.start as usize..(e.start + e.len) as usize]
            .iter()
            .filter_map(|op| match op {
                Op::Param(i) => Some(*i),
                _ => None,
            })
    }

    /// A stack with enough capacity for every expression of this program.
    pub(crate) fn new_stack(&self) -> EvalStack {
        EvalStack(Vec::with_capacity(self.max_stack.max(1)))
    }

    /// Evaluates `e` against the parameter values. `stack` comes from [`Program::new_stack`]
    /// and never grows past its capacity, so this does not allocate.
    #[inline]
    pub(crate) fn eval(&self, e: ExprRef, params: &[f64], stack: &mut Vec<f64>) -> f64 {
        let ops = &self.ops[e.start as usize..(e.start + e.len) as usize];
        // Most arguments are one literal or one parameter: no stack needed.
        match ops {
            [Op::Const(v)] => return *v,
            [Op::Param(i)] => return params.get(*i as usize).copied().unwrap_or(f64::NAN),
            _ => {}
        }
        stack.clear();
        for op in ops {
            match *op {
                Op::Const(v) => stack.push(v),
                Op::Param(i) => stack.push(params.get(i as usize).copied().unwrap_or(f64::NAN)),
                Op::Neg => {
                    if let Some(top) = stack.last_mut() {
                        *top = -*top;
                    }
                }
                Op::Bin(op) => {
                    let b = stack.pop().unwrap_or(f64::NAN);
                    let a = stack.pop().unwrap_or(f64::NAN);
                    stack.push(op.apply(a, b));
                }
                Op::Call(func) => {
                    let n = func.arity();
                    let mut args = [0.0; 3];
                    for slot in args[..n].iter_mut().rev() {
                        *slot = stack.pop().unwrap_or(f64::NAN);
                    }
                    stack.push(func.apply(&args[..n]));
                }
            }
        }
        stack.pop().unwrap_or(f64::NAN)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Expr {
        // stiffness + sqrt(kScale/3) * -2
        Expr::param("stiffness")
            + Expr::call(Func::Sqrt, vec![Expr::param("kScale") / Expr::Num(3.0)]) * -Expr::Num(2.0)
    }

    #[test]
    fn tree_and_program_agree() {
        let e = sample();
        let lookup = |n: &str| match n {
            "stiffness" => Some(0.5),
            "kScale" => Some(0.12),
            _ => None,
        };
        let direct = e.eval(&lookup);
        assert!((direct - (0.5 - 2.0 * 0.2)).abs() < 1e-15);

        let mut p = Program::default();
        let r = p
            .push(&e, &|n| match n {
                "stiffness" => Some(0),
                "kScale" => Some(1),
                _ => None,
            })
            .unwrap();
        let mut stack = p.new_stack();
        let cap = stack.capacity();
        assert_eq!(p.eval(r, &[0.5, 0.12], &mut stack), direct);
        assert_eq!(stack.capacity(), cap, "evaluation must not grow the stack");
    }

    #[test]
    fn unresolved_name_is_reported() {
        let e = Expr::param("a") + Expr::param("kScale3");
        let mut p = Program::default();
        let err = p.push(&e, &|n| (n == "a").then_some(0)).unwrap_err();
        assert_eq!(err, "kScale3");
    }

    #[test]
    fn display_keeps_structure() {
        assert_eq!(sample().to_string(), "stiffness + sqrt(kScale/3)*-2");
        let e = Expr::Num(1.0) - (Expr::Num(2.0) - Expr::Num(3.0));
        assert_eq!(e.to_string(), "1 - (2 - 3)");
        let e = (Expr::Num(1.0) + Expr::Num(2.0)) * Expr::param("a");
        assert_eq!(e.to_string(), "(1 + 2)*a");
        assert_eq!(Expr::Num(1e-5).to_string(), "1e-5");
        assert_eq!(Expr::Num(0.0004).to_string(), "0.0004");
    }

    #[test]
    fn ieee_arithmetic_never_panics() {
        let lookup = |_: &str| None;
        assert!(Expr::call(Func::Sqrt, vec![Expr::Num(-1.0)])
            .eval(&lookup)
            .is_nan());
        assert_eq!(
            (Expr::Num(1.0) / Expr::Num(0.0)).eval(&lookup),
            f64::INFINITY
        );
        let c = Expr::call(
            Func::Clamp,
            vec![Expr::Num(5.0), Expr::Num(3.0), Expr::Num(1.0)],
        );
        assert_eq!(c.eval(&lookup), 1.0);
    }
}

/// The evaluation stack of an engine, reserved once at its full depth
/// ([`Program::new_stack`]). A clone reserves the same capacity (a derived `Vec` clone would
/// reserve only its length, 0), so a cloned engine — a voice — never allocates when it first
/// evaluates an argument on the audio thread.
#[derive(Debug, Default)]
pub(crate) struct EvalStack(pub(crate) Vec<f64>);

impl Clone for EvalStack {
    fn clone(&self) -> Self {
        EvalStack(Vec::with_capacity(self.0.capacity()))
    }
}

impl std::ops::Deref for EvalStack {
    type Target = Vec<f64>;
    fn deref(&self) -> &Vec<f64> {
        &self.0
    }
}

impl std::ops::DerefMut for EvalStack {
    fn deref_mut(&mut self) -> &mut Vec<f64> {
        &mut self.0
    }
}
