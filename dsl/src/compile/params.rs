//! Parameters: each `param`'s type, default and range, and the value a user set for it
//! (checked against its type and range), for the constants table and the compiled grammar.
//!
//! A number, `int` or `seed` parameter is a constant expressions may use; a `bool` switches
//! `if` blocks of the model and a `choice` names a piece there ([`Compiler::switch`],
//! [`Compiler::chosen_piece`]), and neither is a number (E073 where one is used as such).

use super::codes;
use super::constants::{range_text, shown};
use super::state::{Compiler, Constant, Dependency, Kind};
use crate::compiled::{Param, ParamKind, ParamValue};
use crate::diagnostic::Diagnostic;
use crate::format::format_number;
use crate::suggest::closest;
use crate::syntax::{Expr, ExprKind, Ident, ParamDecl, ParamDefault, ParamTypeKind, Span};

/// The type names a parameter may have, as written after its colon.
const TYPE_NAMES: [&str; 4] = ["number", "int", "bool", "seed"];

/// The largest seed: seeds are whole numbers that an `f64` holds exactly.
const MAX_SEED: f64 = 9_007_199_254_740_991.0;

impl Compiler {
    pub(super) fn param_decl(&mut self, p: &ParamDecl) {
        if !self.declare(&p.name, Kind::Param) {
            return;
        }
        let kind = self.param_kind(p);
        let value = kind.as_ref().and_then(|k| self.param_value(p, k));
        let number = value.as_ref().and_then(ParamValue::number);
        self.consts.table.insert(
            p.name.name.clone(),
            Constant {
                value: number,
                span: p.name.span,
                visible_from: p.span.end,
                used: false,
                kind: Kind::Param,
                ty: kind.or(Some(ParamKind::Number)),
                depends: Some(Dependency {
                    param: p.name.name.clone(),
                    decl: p.name.span,
                }),
            },
        );
    }

    /// The type written after the colon (a number without one); `None` after reporting an
    /// unknown type name or a repeated choice.
    fn param_kind(&mut self, p: &ParamDecl) -> Option<ParamKind> {
        let Some(ty) = &p.ty else {
            return Some(ParamKind::Number);
        };
        match &ty.kind {
            ParamTypeKind::Named(id) => match id.name.as_str() {
                "number" => Some(ParamKind::Number),
                "int" => Some(ParamKind::Int),
                "bool" => Some(ParamKind::Bool),
                "seed" => Some(ParamKind::Seed),
                _ => {
                    let mut d = Diagnostic::error(
                        codes::PARAM_TYPE,
                        format!("unknown parameter type `{}`", id.name),
                        id.span,
                        "no type of this name",
                    );
                    // Other languages' words for the same types.
                    let synonym = match id.name.as_str() {
                        "integer" | "i32" | "i64" | "usize" | "whole" => Some("int"),
                        "boolean" | "switch" | "flag" => Some("bool"),
                        "float" | "real" | "double" | "f64" => Some("number"),
                        "string" | "str" | "enum" | "piece" => Some("choice(\"a\", \"b\")"),
                        _ => None,
                    };
                    if let Some(c) = synonym.or_else(|| closest(&id.name, TYPE_NAMES)) {
                        d = d.with_hint(format!("did you mean `{c}`?"));
                    }
                    self.error(d.with_hint(
                        "the types are `number`, `int`, `bool`, `seed` and `choice(\"a\", \"b\", ...)`",
                    ));
                    None
                }
            },
            ParamTypeKind::Choice(strings) => {
                let mut choices: Vec<String> = Vec::new();
                for (i, s) in strings.iter().enumerate() {
                    if let Some(first) = strings[..i].iter().find(|f| f.value == s.value) {
                        self.error(
                            Diagnostic::error(
                                codes::DUPLICATE,
                                format!("choice \"{}\" is listed twice", s.value),
                                s.span,
                                "listed again here",
                            )
                            .with_secondary(first.span, "first listed here")
                            .with_hint("remove one of them"),
                        );
                        return None;
                    }
                    choices.push(s.value.clone());
                }
                self.consts
                    .choices
                    .push((p.name.name.clone(), strings.clone()));
                Some(ParamKind::Choice { choices })
            }
        }
    }

    /// A parameter's value: its override, or else its default. `None` (poisoned) after an
    /// error in its declaration, reported once.
    fn param_value(&mut self, p: &ParamDecl, kind: &ParamKind) -> Option<ParamValue> {
        let (default, range) = match kind {
            ParamKind::Bool | ParamKind::Choice { .. } => {
                if let Some(r) = &p.range {
                    self.error(
                        Diagnostic::error(
                            codes::PARAM_TYPE,
                            format!(
                                "parameter `{}` is {}: it has no range",
                                p.name.name,
                                kind.with_article()
                            ),
                            r.span,
                            "a range of numbers",
                        )
                        .with_hint("remove the range: only a number, `int` or `seed` has one"),
                    );
                    return None;
                }
                (self.switch_default(p, kind)?, None)
            }
            _ => self.number_default(p, kind)?,
        };
        let given = (self.consts.overrides.iter().rev())
            .find(|(n, _)| *n == p.name.name)
            .map(|(_, v)| v.clone());
        // A rejected override is reported once; the rest of the grammar compiles with the
        // default, so that nothing else is said about it.
        let value = match given {
            None => default.clone(),
            Some(v) => self
                .checked_override(p, kind, v, range)
                .unwrap_or_else(|| default.clone()),
        };
        self.consts.params.push(Param {
            name: p.name.name.clone(),
            kind: kind.clone(),
            value: value.clone(),
            default,
            range,
        });
        Some(value)
    }

    /// The default of a `bool` (`true` or `false`) or a `choice` (one of its strings).
    fn switch_default(&mut self, p: &ParamDecl, kind: &ParamKind) -> Option<ParamValue> {
        let name = &p.name.name;
        match (kind, &p.value) {
            (ParamKind::Bool, ParamDefault::Expr(e)) => match &e.kind {
                ExprKind::Name(id) if id.name == "true" => Some(ParamValue::Bool(true)),
                ExprKind::Name(id) if id.name == "false" => Some(ParamValue::Bool(false)),
                _ => self.wrong_default(p, "`true` or `false`"),
            },
            (ParamKind::Choice { choices }, ParamDefault::Text(t)) => {
                if choices.contains(&t.value) {
                    return Some(ParamValue::Text(t.value.clone()));
                }
                let mut d = Diagnostic::error(
                    codes::PARAM_TYPE,
                    format!("the default of parameter `{name}` is not one of its choices"),
                    t.span,
                    "not among the choices",
                );
                if let Some(c) = closest(&t.value, choices.iter().map(String::as_str)) {
                    d = d.with_hint(format!("did you mean \"{c}\"?"));
                }
                self.error(d.with_hint(format!("the choices are {}", quoted(choices))));
                None
            }
            (ParamKind::Choice { choices }, _) => {
                let first = choices.first().map_or("a", String::as_str);
                self.wrong_default(
                    p,
                    &format!("one of its choices in quotes, like \"{first}\""),
                )
            }
            _ => self.wrong_default(p, "`true` or `false`"),
        }
    }

    /// E073 for a default of the wrong type; `what` says what it should be.
    fn wrong_default<T>(&mut self, p: &ParamDecl, what: &str) -> Option<T> {
        let kind = match &p.ty {
            Some(t) => match &t.kind {
                ParamTypeKind::Named(id) => format!("`{}`", id.name),
                ParamTypeKind::Choice(_) => "`choice`".to_string(),
            },
            None => "number".to_string(),
        };
        let mut d = Diagnostic::error(
            codes::PARAM_TYPE,
            format!(
                "the default of parameter `{}` does not fit its type {kind}",
                p.name.name
            ),
            p.value.span(),
            format!("expected {what}"),
        );
        if let Some(t) = &p.ty {
            d = d.with_secondary(t.span, "the type");
        }
        self.error(d.with_hint(format!("write {what}")));
        None
    }

    /// The default and range of a number, `int` or `seed`.
    fn number_default(
        &mut self,
        p: &ParamDecl,
        kind: &ParamKind,
    ) -> Option<(ParamValue, Option<[f64; 2]>)> {
        let ParamDefault::Expr(value) = &p.value else {
            return self.wrong_default(p, "a number");
        };
        // One E072 per parameter, however many of its parts use another one.
        let mut reported = false;
        let default = self.fixed(p, value, "default", &mut reported);
        let range = match &p.range {
            None => Some(None),
            Some(r) => {
                let low = self.fixed(p, &r.low, "range", &mut reported);
                let high = self.fixed(p, &r.high, "range", &mut reported);
                low.zip(high).map(Some)
            }
        };
        let (default, range) = (default?, range?);
        if kind.is_whole() {
            let mut parts = vec![(default, value.span, "default")];
            if let (Some((low, high)), Some(r)) = (range, &p.range) {
                parts.push((low, r.low.span, "low end"));
                parts.push((high, r.high.span, "high end"));
            }
            for (v, span, part) in parts {
                if let Some(why) = not_whole(kind, v) {
                    self.error(
                        Diagnostic::error(
                            codes::PARAM_TYPE,
                            format!(
                                "the {part} of `{}` parameter `{}` is {}, {why}",
                                kind.word(),
                                p.name.name,
                                format_number(v)
                            ),
                            span,
                            why.to_string(),
                        )
                        .with_hint(format!(
                            "write a whole number{}, or make `{}` a number (no type)",
                            if *kind == ParamKind::Seed {
                                " from 0"
                            } else {
                                ""
                            },
                            p.name.name
                        )),
                    );
                    return None;
                }
            }
        }
        if let (Some((low, high)), Some(r)) = (range, &p.range) {
            self.check_range(p, value, default, low, high, r.span)?;
        }
        Some((ParamValue::Number(default), range.map(|(l, h)| [l, h])))
    }

    /// E066 for an empty range or a default outside it.
    fn check_range(
        &mut self,
        p: &ParamDecl,
        value: &Expr,
        default: f64,
        low: f64,
        high: f64,
        span: Span,
    ) -> Option<()> {
        if low > high {
            self.error(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    format!(
                        "the range of parameter `{}` is empty: its low end is above its high end",
                        p.name.name
                    ),
                    span,
                    format!("{} is above {}", format_number(low), format_number(high)),
                )
                .with_hint(format!(
                    "write the low end first: `in {}..{}`",
                    format_number(high),
                    format_number(low)
                )),
            );
            return None;
        }
        if !(low..=high).contains(&default) {
            self.error(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    format!(
                        "the default of parameter `{}` is outside its range",
                        p.name.name
                    ),
                    value.span,
                    format!(
                        "{} is not in {}",
                        format_number(default),
                        range_text(low, high)
                    ),
                )
                .with_secondary(span, "the range")
                .with_hint(format!(
                    "make the default a number from {} to {}, or widen the range",
                    format_number(low),
                    format_number(high)
                )),
            );
            return None;
        }
        Some(())
    }

    /// A part of a parameter's declaration (its default or a bound of its range), which must
    /// not depend on another parameter (E072).
    fn fixed(&mut self, p: &ParamDecl, e: &Expr, part: &str, reported: &mut bool) -> Option<f64> {
        self.consts.touched = None;
        let value = self.eval(e);
        let Some(t) = self.consts.touched.take() else {
            return value;
        };
        if std::mem::replace(reported, true) {
            return None;
        }
        let through = if t.used.name == t.dep.param {
            format!("parameter `{}`", t.dep.param)
        } else {
            format!(
                "`{}`, which depends on parameter `{}`",
                t.used.name, t.dep.param
            )
        };
        self.error(
            Diagnostic::error(
                codes::PARAM_NOT_FIXED,
                format!("the {part} of parameter `{}` uses {through}", p.name.name),
                t.used.span,
                "depends on a parameter",
            )
            .with_secondary(
                t.dep.decl,
                format!("`{}` is a parameter: a user may set it", t.dep.param),
            )
            .with_hint(
                "a parameter's default and range are fixed: write them with numbers and \
                 `let` constants that use no parameter",
            ),
        );
        None
    }

    /// A value set for parameter `p` from outside the file, checked against its type (E073)
    /// and range (E071).
    fn checked_override(
        &mut self,
        p: &ParamDecl,
        kind: &ParamKind,
        given: ParamValue,
        range: Option<[f64; 2]>,
    ) -> Option<ParamValue> {
        let name = &p.name.name;
        let label = format!("set to {} from outside the file", shown_value(&given));
        // The error, its hints in order (what the parameter takes last).
        let wrong = |hints: Vec<String>| {
            let d = Diagnostic::error(
                codes::PARAM_TYPE,
                format!(
                    "parameter `{name}` is {}, and {} is not one",
                    kind.with_article(),
                    shown_value(&given)
                ),
                p.name.span,
                label.clone(),
            );
            hints.into_iter().fold(d, Diagnostic::with_hint)
        };
        match kind {
            ParamKind::Bool => {
                let on = match &given {
                    ParamValue::Bool(b) => Some(*b),
                    ParamValue::Text(t) if t == "true" || t == "false" => Some(t == "true"),
                    _ => None,
                };
                if on.is_none() {
                    self.error(wrong(vec![format!("set `{name}` to `true` or `false`")]));
                }
                return on.map(ParamValue::Bool);
            }
            ParamKind::Choice { choices } => {
                let text = given.to_string();
                if choices.contains(&text) {
                    return Some(ParamValue::Text(text));
                }
                let mut hints: Vec<String> = closest(&text, choices.iter().map(String::as_str))
                    .map(|c| format!("did you mean \"{c}\"?"))
                    .into_iter()
                    .collect();
                hints.push(format!("the choices are {}", quoted(choices)));
                self.error(wrong(hints));
                return None;
            }
            _ => {}
        }
        let Some(v) = given.number() else {
            self.error(wrong(vec![format!("set `{name}` to a number")]));
            return None;
        };
        let (message, mut hint) = if !v.is_finite() {
            (
                format!(
                    "parameter `{name}` is set to {}, which is not a finite number",
                    shown(v)
                ),
                "a parameter's value must be a finite number".to_string(),
            )
        } else if not_whole(kind, v).is_some() {
            let from = if *kind == ParamKind::Seed {
                " from 0"
            } else {
                ""
            };
            self.error(wrong(vec![format!("set `{name}` to a whole number{from}")]));
            return None;
        } else {
            match range {
                Some([low, high]) if v < low || v > high => (
                    format!(
                        "parameter `{name}` is set to {}, outside its range {}",
                        shown(v),
                        range_text(low, high)
                    ),
                    String::new(),
                ),
                _ => return Some(ParamValue::Number(v)),
            }
        };
        if let Some([low, high]) = range {
            if !hint.is_empty() {
                hint.push_str("; ");
            }
            hint.push_str(&format!(
                "choose a value of `{name}` from {} to {}",
                format_number(low),
                format_number(high)
            ));
        }
        let mut d = Diagnostic::error(codes::PARAM_OUT_OF_RANGE, message, p.name.span, label);
        if let Some(r) = &p.range {
            d = d.with_secondary(r.span, "its range");
        }
        self.error(d.with_hint(hint));
        None
    }

    /// The value of the `bool` parameter `id` names, for `if ID { ... }`: `None` after
    /// reporting a name that is no `bool` parameter, or silently when the parameter is
    /// poisoned (its declaration's error was reported).
    pub(super) fn switch(&mut self, id: &Ident) -> Option<bool> {
        const WHAT: &str = "a `bool` parameter";
        match self.consts.table.get_mut(&id.name) {
            Some(c) if c.ty == Some(ParamKind::Bool) => {
                c.used = true;
                return self.param(&id.name).and_then(|p| p.value.bool());
            }
            Some(c) => {
                c.used = true;
                let (span, ty) = (c.span, c.ty.clone());
                let is = match ty {
                    Some(k) => format!("{} parameter", k.with_article()),
                    None => "a `let` constant".to_string(),
                };
                self.error(
                    Diagnostic::error(
                        codes::PARAM_TYPE,
                        format!("`{}` is {is}, not {WHAT}", id.name),
                        id.span,
                        format!("expected {WHAT}"),
                    )
                    .with_secondary(span, "declared here")
                    .with_hint(format!(
                        "an `if` switches on a parameter declared `param {}: bool = true`",
                        id.name
                    )),
                );
                return None;
            }
            None => {}
        }
        if self.consts.declared.contains_key(&id.name) {
            return None; // declared, but its declaration failed (reported there)
        }
        let bools: Vec<String> = (self.consts.params.iter())
            .filter(|p| p.kind == ParamKind::Bool)
            .map(|p| p.name.clone())
            .collect();
        let ident = id.clone();
        self.unknown("parameter", &ident, bools.iter().map(String::as_str), None);
        None
    }

    /// The piece a `choice` parameter named `id` picks, when `id` names one (as an ident at
    /// `id`'s span, for the caller's lookup); `None` when `id` is no choice parameter.
    pub(super) fn chosen_piece(&mut self, id: &Ident) -> Option<Ident> {
        let c = self.consts.table.get_mut(&id.name)?;
        if !matches!(c.ty, Some(ParamKind::Choice { .. })) {
            return None;
        }
        c.used = true;
        let value = self
            .param(&id.name)
            .and_then(|p| p.value.text().map(String::from));
        Some(Ident {
            // A poisoned choice picks nothing, silently: an empty name is no piece and the
            // caller's lookup reports nothing for it.
            name: value.unwrap_or_default(),
            span: id.span,
        })
    }

    /// An unknown-piece error for each choice of a `choice` parameter that names no piece.
    pub(super) fn check_choices(&mut self) {
        // A file of constants alone (the language server folds them so) has no pieces to
        // name: its choices are judged where it is imported.
        if self.pieces.is_empty() {
            return;
        }
        for (param, strings) in std::mem::take(&mut self.consts.choices) {
            if self.param(&param).is_none() {
                continue;
            }
            for s in strings {
                if self.piece_index.contains_key(&s.value) {
                    continue;
                }
                let names: Vec<String> = self.pieces.iter().map(|p| p.name.clone()).collect();
                let id = Ident {
                    name: s.value.clone(),
                    span: s.span,
                };
                let ctx = Some(format!("among the choices of `{param}`"));
                self.unknown("piece", &id, names.iter().map(String::as_str), ctx);
            }
        }
    }

    /// The compiled parameter called `name`, when its declaration compiled.
    pub(super) fn param(&self, name: &str) -> Option<&Param> {
        self.consts.params.iter().find(|p| p.name == name)
    }
}

/// Why `v` is no value of a whole-number parameter of `kind`, if it is not.
fn not_whole(kind: &ParamKind, v: f64) -> Option<&'static str> {
    match kind {
        ParamKind::Int if v.fract() != 0.0 => Some("not a whole number"),
        ParamKind::Seed if v.fract() != 0.0 || !(0.0..=MAX_SEED).contains(&v) => {
            Some("not a whole number from 0")
        }
        _ => None,
    }
}

/// A value as messages show it: a number as written, a string in quotes.
fn shown_value(v: &ParamValue) -> String {
    match v {
        ParamValue::Number(x) => shown(*x),
        ParamValue::Bool(b) => b.to_string(),
        ParamValue::Text(t) => format!("\"{t}\""),
    }
}

/// `"a", "b" and "c"`.
fn quoted(choices: &[String]) -> String {
    let all: Vec<String> = choices.iter().map(|c| format!("\"{c}\"")).collect();
    match all.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => all.join(""),
    }
}
