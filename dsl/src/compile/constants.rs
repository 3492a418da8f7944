//! Constants and expressions: the table of `let` constants and `param` parameters, the
//! parameters' overrides, and the folding of every numeric expression to one number, with
//! diagnostics that point inside the expression.
//!
//! Architecture Invariant: the compiled grammar holds numbers only; expressions live in the
//! syntax tree and end here. A failed expression yields `None` once, with one diagnostic; a
//! constant whose `let` failed is *poisoned*: its uses stay silent, as rustc stays silent
//! about uses of a `{type error}`. A parameter is a constant whose value an override may
//! replace; one whose declaration or override failed is poisoned the same way.

use std::collections::{HashMap, HashSet};

use super::codes;
use super::state::{Compiler, Constant, Kind, Touch};
use crate::diagnostic::Diagnostic;
use crate::format::format_number;
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

impl Kind {
    fn word(self) -> &'static str {
        match self {
            Kind::Let => "constant",
            Kind::Param => "parameter",
        }
    }

    fn keyword(self) -> &'static str {
        match self {
            Kind::Let => "let",
            Kind::Param => "param",
        }
    }
}

/// Why evaluation stopped; the diagnostic (if any) is already pushed.
struct Stop;

impl Compiler {
    /// Evaluates every `let` and `param` in file order (a constant may use the constants above
    /// it), applying the overrides to the parameters; then reports overrides that name no
    /// parameter.
    pub(crate) fn constants(&mut self, items: &[Item]) {
        for item in items {
            let (name, kind) = match item {
                Item::Let(l) => (&l.name, Kind::Let),
                Item::Param(p) => (&p.name, Kind::Param),
                _ => continue,
            };
            self.consts
                .declared
                .entry(name.name.clone())
                .or_insert((name.span, kind));
        }
        for item in items {
            match item {
                Item::Let(l) => self.let_decl(l),
                Item::Param(p) => self.param_decl(p),
                _ => {}
            }
        }
        self.unknown_overrides();
    }

    /// Whether `name` may be declared as a new constant of `kind`; reports why not.
    pub(super) fn declare(&mut self, name: &Ident, kind: Kind) -> bool {
        if let Some(first) = self.consts.table.get(&name.name) {
            let (first_span, first_kind) = (first.span, first.kind);
            if first_kind == kind {
                self.duplicate(kind.word(), name, first_span);
            } else {
                let keep = match kind {
                    Kind::Param => "remove the `let` if the number is meant to be set",
                    Kind::Let => "remove the `let` and keep the `param`",
                };
                self.error(
                    Diagnostic::error(
                        codes::DUPLICATE,
                        format!(
                            "`{}` is defined twice, as a {} and as a {}",
                            name.name,
                            first_kind.word(),
                            kind.word()
                        ),
                        name.span,
                        format!("defined again here, as a {}", kind.word()),
                    )
                    .with_secondary(
                        first_span,
                        format!("first defined here, with `{}`", first_kind.keyword()),
                    )
                    .with_hint(format!(
                        "a parameter is a constant a user may set: rename one of them, or {keep}"
                    )),
                );
            }
            return false;
        }
        let builtin = BUILTIN_CONSTANTS.iter().any(|(n, _)| *n == name.name)
            || FUNCTIONS.iter().any(|(n, _, _)| *n == name.name);
        if builtin {
            self.error(
                Diagnostic::error(
                    codes::DUPLICATE,
                    format!("`{}` is built in", name.name),
                    name.span,
                    "a built-in name",
                )
                .with_hint(format!("choose another name for the {}", kind.word())),
            );
            return false;
        }
        true
    }

    fn let_decl(&mut self, l: &LetDecl) {
        if !self.declare(&l.name, Kind::Let) {
            return;
        }
        self.consts.touched = None;
        let value = self.eval(&l.value);
        let depends = self.consts.touched.take().map(|t| t.dep);
        self.consts.table.insert(
            l.name.name.clone(),
            Constant {
                value,
                span: l.name.span,
                visible_from: l.span.end,
                used: false,
                kind: Kind::Let,
                ty: None,
                depends,
            },
        );
    }

    /// E070 for each override whose name is no parameter of the grammar (once per name).
    fn unknown_overrides(&mut self) {
        let mut params: Vec<(&str, Span)> = self
            .consts
            .declared
            .iter()
            .filter(|(_, (_, k))| *k == Kind::Param)
            .map(|(n, (s, _))| (n.as_str(), *s))
            .collect();
        params.sort_by_key(|(_, s)| s.start);
        let mut seen = HashSet::new();
        let mut diags = Vec::new();
        for (name, _) in &self.consts.overrides {
            if !seen.insert(name.as_str()) {
                continue;
            }
            match self.consts.declared.get(name) {
                Some((_, Kind::Param)) => {}
                Some((span, Kind::Let)) => diags.push(
                    Diagnostic::error(
                        codes::UNKNOWN_PARAM,
                        format!("`{name}` is a constant, not a parameter: it cannot be set"),
                        *span,
                        "declared with `let`",
                    )
                    .with_hint(format!(
                        "declare it with `param {name} = ...` to let it be set"
                    )),
                ),
                None => {
                    let mut d = Diagnostic::error(
                        codes::UNKNOWN_PARAM,
                        format!("unknown parameter `{name}`"),
                        Span::new(0, 0),
                        format!("the grammar has no parameter `{name}`"),
                    );
                    if let Some(c) = closest(name, params.iter().map(|(n, _)| *n)) {
                        let at = params.iter().find(|(n, _)| *n == c).map(|(_, s)| *s);
                        if let Some(at) = at {
                            d = d.with_secondary(at, format!("`{c}` is declared here"));
                        }
                        d = d.with_hint(format!("did you mean `{c}`?"));
                    }
                    d = d.with_hint(if params.is_empty() {
                        "the grammar declares no parameters (`param NAME = VALUE`)".to_string()
                    } else {
                        let list: Vec<String> =
                            params.iter().map(|(n, _)| format!("`{n}`")).collect();
                        format!("the parameters are {}", list.join(", "))
                    });
                    diags.push(d);
                }
            }
        }
        for d in diags {
            self.error(d);
        }
    }

    /// Warns about constants nothing uses.
    pub(crate) fn unused_constants(&mut self) {
        let mut unused: Vec<(String, Span, Kind)> = self
            .consts
            .table
            .iter()
            .filter(|(_, c)| !c.used)
            .map(|(n, c)| (n.clone(), c.span, c.kind))
            .collect();
        unused.sort_by_key(|(_, s, _)| s.start);
        for (name, span, kind) in unused {
            let word = kind.word();
            self.error(
                Diagnostic::warning(
                    codes::UNUSED_CONSTANT,
                    format!("{word} `{name}` is never used"),
                    span,
                    "declared here",
                )
                .with_hint(format!(
                    "remove the `{}`, or use the {word} where its number belongs",
                    kind.keyword()
                )),
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
                if let Some(k) = c.ty.as_ref().filter(|k| !k.is_numeric()) {
                    let (word, a_word, span) = (k.word(), k.with_article(), c.span);
                    let hint = if word == "bool" {
                        format!("switch model statements with `if {name} {{ ... }}`")
                    } else {
                        format!("write `{name}` where a piece's name goes in the model")
                    };
                    self.error(
                        Diagnostic::error(
                            codes::PARAM_TYPE,
                            format!("parameter `{name}` is {a_word}, not a number"),
                            id.span,
                            "used as a number",
                        )
                        .with_secondary(span, format!("declared {a_word} here"))
                        .with_hint(hint),
                    );
                    return Err(Stop);
                }
                if let (Some(dep), None) = (&c.depends, &self.consts.touched) {
                    self.consts.touched = Some(Touch {
                        dep: dep.clone(),
                        used: id.clone(),
                    });
                }
                return c.value.ok_or(Stop);
            }
            _ => {}
        }
        if let Some(&(declared, kind)) = self.consts.declared.get(name) {
            // One mistake (the `let` is too low), one error: later uses stay silent.
            if !self.consts.early.insert(name.to_string()) {
                return Err(Stop);
            }
            let (word, keyword) = (kind.word(), kind.keyword());
            self.error(
                Diagnostic::error(
                    codes::USED_BEFORE_LET,
                    format!("{word} `{name}` is used before its `{keyword}`"),
                    id.span,
                    "used here",
                )
                .with_secondary(declared, "declared later here")
                .with_hint(format!(
                    "a {word} is visible after its `{keyword}`: move `{keyword} {name}` above this use"
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

/// A value as messages show it: the shortest text that reads back, or `inf`, `-inf`, `NaN`.
pub(super) fn shown(v: f64) -> String {
    if v.is_finite() {
        format_number(v)
    } else {
        format!("{v}")
    }
}

/// `LO..HI` as messages show a range.
pub(super) fn range_text(low: f64, high: f64) -> String {
    format!("{}..{}", format_number(low), format_number(high))
}

/// Whether `name` is a built-in function.
pub(crate) fn is_function(name: &str) -> bool {
    FUNCTIONS.iter().any(|(n, _, _)| *n == name)
}

/// The built-in functions' names and how to call them, for completion.
pub(crate) fn functions() -> impl Iterator<Item = (&'static str, &'static str)> {
    FUNCTIONS.iter().map(|(n, _, usage)| (*n, *usage))
}
