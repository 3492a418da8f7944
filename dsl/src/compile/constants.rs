//! Constants and expressions: the table of `let` constants, and the folding of every numeric
//! expression to one number, with diagnostics that point inside the expression.
//!
//! Architecture Invariant: the compiled grammar holds numbers only; expressions live in the
//! syntax tree and end here. A failed expression yields `None` once, with one diagnostic; a
//! constant whose `let` failed is *poisoned*: its uses stay silent, as rustc stays silent
//! about uses of a `{type error}`.

use std::collections::{HashMap, HashSet};

use super::{Compiler, codes};
use crate::diagnostic::Diagnostic;
use crate::suggest::closest;
use crate::syntax::{BinaryOp, Expr, ExprKind, Ident, Item, LetDecl, Span, UnaryOp};

/// The built-in constants.
const BUILTIN_CONSTANTS: [(&str, f64); 1] = [("pi", std::f64::consts::PI)];

/// The built-in functions, with how many arguments each takes (`None`: one or more).
/// Angles are degrees, the language's angle unit.
const FUNCTIONS: [(&str, Option<usize>, &str); 11] = [
    ("sqrt", Some(1), "sqrt(x)"),
    ("abs", Some(1), "abs(x)"),
    ("sin", Some(1), "sin(degrees)"),
    ("cos", Some(1), "cos(degrees)"),
    ("tan", Some(1), "tan(degrees)"),
    ("asin", Some(1), "asin(x)"),
    ("acos", Some(1), "acos(x)"),
    ("atan", Some(1), "atan(x)"),
    ("atan2", Some(2), "atan2(y, x)"),
    ("min", None, "min(a, b, ...)"),
    ("max", None, "max(a, b, ...)"),
];

/// One `let`.
#[derive(Clone, Debug)]
struct Constant {
    /// `None` when its expression failed (reported there): the constant is poisoned.
    value: Option<f64>,
    /// The name in its `let`.
    span: Span,
    /// Uses at or after this byte see it (the end of its `let`).
    visible_from: usize,
    used: bool,
}

/// The `let` constants of a file, and which expressions were already reported.
#[derive(Debug, Default)]
pub(crate) struct Constants {
    table: HashMap<String, Constant>,
    /// Every `let` name with its span, known before any is evaluated, so that a use before
    /// the declaration is told apart from an unknown name.
    declared: HashMap<String, Span>,
    /// Spans of expressions already evaluated with an error: a pass that reads an expression
    /// again stays silent.
    failed: HashSet<(usize, usize)>,
    /// Constants already reported as used before their `let`.
    early: HashSet<String>,
}

/// Why evaluation stopped; the diagnostic (if any) is already pushed.
struct Stop;

impl Compiler {
    /// Evaluates every `let` in file order (a constant may use the constants above it).
    pub(crate) fn constants(&mut self, items: &[Item]) {
        let lets: Vec<&LetDecl> = items
            .iter()
            .filter_map(|i| match i {
                Item::Let(l) => Some(l),
                _ => None,
            })
            .collect();
        for l in &lets {
            self.consts
                .declared
                .entry(l.name.name.clone())
                .or_insert(l.name.span);
        }
        for l in lets {
            self.let_decl(l);
        }
    }

    fn let_decl(&mut self, l: &LetDecl) {
        let name = &l.name.name;
        if let Some(first) = self.consts.table.get(name) {
            let first = first.span;
            self.duplicate("constant", &l.name, first);
            return;
        }
        let builtin = BUILTIN_CONSTANTS.iter().any(|(n, _)| n == name)
            || FUNCTIONS.iter().any(|(n, _, _)| n == name);
        if builtin {
            self.error(
                Diagnostic::error(
                    codes::DUPLICATE,
                    format!("`{name}` is built in"),
                    l.name.span,
                    "a built-in name",
                )
                .with_hint("choose another name for the constant"),
            );
            return;
        }
        let value = self.eval(&l.value);
        self.consts.table.insert(
            name.clone(),
            Constant {
                value,
                span: l.name.span,
                visible_from: l.span.end,
                used: false,
            },
        );
    }

    /// Warns about constants nothing uses.
    pub(crate) fn unused_constants(&mut self) {
        let mut unused: Vec<(String, Span)> = self
            .consts
            .table
            .iter()
            .filter(|(_, c)| !c.used)
            .map(|(n, c)| (n.clone(), c.span))
            .collect();
        unused.sort_by_key(|(_, s)| s.start);
        for (name, span) in unused {
            self.error(
                Diagnostic::warning(
                    codes::UNUSED_CONSTANT,
                    format!("constant `{name}` is never used"),
                    span,
                    "declared here",
                )
                .with_hint("remove the `let`, or use the constant where its number belongs"),
            );
        }
    }

    /// The value of an expression, or `None` after reporting why it has none (or silently,
    /// when it uses a poisoned constant or was reported before).
    pub fn eval(&mut self, e: &Expr) -> Option<f64> {
        if let ExprKind::Number(v) = e.kind {
            return Some(v);
        }
        if self.consts.failed.contains(&(e.span.start, e.span.end)) {
            return None;
        }
        match self.fold(e) {
            Ok(v) => Some(v),
            Err(Stop) => {
                self.consts.failed.insert((e.span.start, e.span.end));
                None
            }
        }
    }

    /// Folds one node. Recursion is bounded: the parser rejects trees deeper than
    /// `MAX_EXPR_DEPTH`.
    fn fold(&mut self, e: &Expr) -> Result<f64, Stop> {
        let v = match &e.kind {
            ExprKind::Number(v) => return Ok(*v),
            ExprKind::Paren(inner) => return self.fold(inner),
            ExprKind::Name(id) => return self.constant(id),
            ExprKind::Unary(UnaryOp::Neg, x) => -self.fold(x)?,
            ExprKind::Unary(UnaryOp::Plus, x) => self.fold(x)?,
            ExprKind::Binary(op, a, b) => {
                let (x, y) = (self.fold(a)?, self.fold(b)?);
                match op {
                    BinaryOp::Add => x + y,
                    BinaryOp::Sub => x - y,
                    BinaryOp::Mul => x * y,
                    BinaryOp::Div if y == 0.0 => return Err(self.division_by_zero(e, b)),
                    BinaryOp::Div => x / y,
                }
            }
            ExprKind::Call(call) => self.call(e, &call.func, &call.args)?,
        };
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.not_finite(e, v))
        }
    }

    fn constant(&mut self, id: &Ident) -> Result<f64, Stop> {
        let name = id.name.as_str();
        if let Some((_, v)) = BUILTIN_CONSTANTS.iter().find(|(n, _)| *n == name) {
            return Ok(*v);
        }
        match self.consts.table.get_mut(name) {
            Some(c) if c.visible_from <= id.span.start => {
                c.used = true;
                return c.value.ok_or(Stop);
            }
            _ => {}
        }
        if let Some(&declared) = self.consts.declared.get(name) {
            // One mistake (the `let` is too low), one error: later uses stay silent.
            if !self.consts.early.insert(name.to_string()) {
                return Err(Stop);
            }
            self.error(
                Diagnostic::error(
                    codes::USED_BEFORE_LET,
                    format!("constant `{name}` is used before its `let`"),
                    id.span,
                    "used here",
                )
                .with_secondary(declared, "declared later here")
                .with_hint(format!(
                    "a constant is visible after its `let`: move `let {name}` above this use"
                )),
            );
            return Err(Stop);
        }
        let mut d = Diagnostic::error(
            codes::UNKNOWN,
            format!("unknown constant `{name}`"),
            id.span,
            "no constant of this name",
        );
        if let Some((_, _, usage)) = FUNCTIONS.iter().find(|(n, _, _)| *n == name) {
            d = d.with_hint(format!("`{name}` is a function: call it as `{usage}`"));
        } else {
            let visible: Vec<&str> = self
                .consts
                .table
                .iter()
                .filter(|(_, c)| c.visible_from <= id.span.start)
                .map(|(n, _)| n.as_str())
                .chain(BUILTIN_CONSTANTS.iter().map(|(n, _)| *n))
                .collect();
            match closest(name, visible.iter().copied()) {
                Some(c) => d = d.with_hint(format!("did you mean `{c}`?")),
                None => {
                    d = d.with_hint(format!("declare it first: `let {name} = ...`"));
                }
            }
        }
        self.error(d);
        Err(Stop)
    }

    fn call(&mut self, e: &Expr, func: &Ident, args: &[Expr]) -> Result<f64, Stop> {
        let name = func.name.as_str();
        let Some(&(_, arity, usage)) = FUNCTIONS.iter().find(|(n, _, _)| *n == name) else {
            let mut d = Diagnostic::error(
                codes::UNKNOWN,
                format!("unknown function `{name}`"),
                func.span,
                "no function of this name",
            );
            d = match closest(name, FUNCTIONS.iter().map(|(n, _, _)| *n)) {
                Some(c) => d.with_hint(format!("did you mean `{c}`?")),
                None => {
                    let all: Vec<String> =
                        FUNCTIONS.iter().map(|(n, _, _)| format!("`{n}`")).collect();
                    d.with_hint(format!("the functions are {}", all.join(", ")))
                }
            };
            self.error(d);
            return Err(Stop);
        };
        let fits = match arity {
            Some(n) => args.len() == n,
            None => !args.is_empty(),
        };
        if !fits {
            let wanted = match arity {
                Some(1) => "1 argument".to_string(),
                Some(n) => format!("{n} arguments"),
                None => "at least 1 argument".to_string(),
            };
            self.error(
                Diagnostic::error(
                    codes::BAD_CALL,
                    match args.len() {
                        1 => format!("`{name}` takes {wanted}, but 1 was given"),
                        n => format!("`{name}` takes {wanted}, but {n} were given"),
                    },
                    e.span,
                    format!("expected {wanted}"),
                )
                .with_hint(format!("write `{usage}`")),
            );
            return Err(Stop);
        }
        let mut x = Vec::with_capacity(args.len());
        for a in args {
            x.push(self.fold(a)?);
        }
        Ok(match name {
            "sqrt" => x[0].sqrt(),
            "abs" => x[0].abs(),
            "sin" => sin_degrees(x[0]),
            "cos" => sin_degrees(x[0] + 90.0),
            "tan" => tan_degrees(x[0]),
            "asin" => x[0].asin().to_degrees(),
            "acos" => x[0].acos().to_degrees(),
            "atan" => x[0].atan().to_degrees(),
            "atan2" => x[0].atan2(x[1]).to_degrees(),
            "min" => x.iter().copied().fold(f64::INFINITY, f64::min),
            _ => x.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        })
    }

    fn division_by_zero(&mut self, e: &Expr, divisor: &Expr) -> Stop {
        let mut d = Diagnostic::error(
            codes::DIVISION_BY_ZERO,
            "division by zero",
            divisor.span,
            "this is 0",
        );
        if !matches!(divisor.kind, ExprKind::Number(_)) {
            d = d.with_secondary(e.span, "in this division");
        }
        self.error(d.with_hint("the divisor must not be zero"));
        Stop
    }

    fn not_finite(&mut self, e: &Expr, v: f64) -> Stop {
        let what = if v.is_nan() {
            "is not a number"
        } else {
            "is infinite"
        };
        let hint = match &e.kind {
            ExprKind::Call(c) if c.func.name == "sqrt" => "`sqrt` takes a number of at least 0",
            ExprKind::Call(c) if c.func.name == "tan" => {
                "`tan` is infinite at 90 degrees (and 270, ...)"
            }
            ExprKind::Call(c) if c.func.name == "asin" || c.func.name == "acos" => {
                "`asin` and `acos` take a number from -1 to 1"
            }
            _ => "numbers must be finite; the largest is about 1.8e308",
        };
        self.error(
            Diagnostic::error(
                codes::NON_FINITE,
                format!("this expression {what}"),
                e.span,
                format!("{what} here"),
            )
            .with_hint(hint),
        );
        Stop
    }
}

/// `sin` of an angle in degrees, exact at multiples of 90 degrees (so `cos(90)` is 0, not
/// 6e-17, and coordinates meant to lie on an axis do).
fn sin_degrees(deg: f64) -> f64 {
    let r = deg.rem_euclid(360.0);
    let exact = [(0.0, 0.0), (90.0, 1.0), (180.0, 0.0), (270.0, -1.0)];
    exact
        .iter()
        .find(|(at, _)| *at == r)
        .map_or_else(|| r.to_radians().sin(), |(_, v)| *v)
}

/// `tan` in degrees: exact at multiples of 45, infinite (reported) at odd multiples of 90.
fn tan_degrees(deg: f64) -> f64 {
    let r = deg.rem_euclid(180.0);
    let exact = [
        (0.0, 0.0),
        (45.0, 1.0),
        (90.0, f64::INFINITY),
        (135.0, -1.0),
    ];
    exact
        .iter()
        .find(|(at, _)| *at == r)
        .map_or_else(|| r.to_radians().tan(), |(_, v)| *v)
}

/// The folded values of a tree's constants (those that fold), for editors' hovers.
pub(crate) fn constant_values(file: &crate::syntax::File) -> HashMap<String, f64> {
    let mut c = Compiler::new("");
    c.constants(&file.items);
    c.consts
        .table
        .iter()
        .filter_map(|(n, k)| k.value.map(|v| (n.clone(), v)))
        .collect()
}

/// Whether `name` is a built-in function.
pub(crate) fn is_function(name: &str) -> bool {
    FUNCTIONS.iter().any(|(n, _, _)| *n == name)
}

/// The built-in functions' names and how to call them, for completion.
pub(crate) fn functions() -> impl Iterator<Item = (&'static str, &'static str)> {
    FUNCTIONS.iter().map(|(n, _, usage)| (*n, *usage))
}
