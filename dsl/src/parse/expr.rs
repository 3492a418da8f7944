//! Expressions and points: number literals (E012 when one overflows), the operator tree built
//! by precedence without recursion per operator (E002 past [`MAX_EXPR_DEPTH`]), and `(x, y)`.

use pest::iterators::Pair;

use super::codes;
use super::grammar::Rule;
use super::lower::{Lower, first, kids, of, span_of};
use crate::diagnostic::Diagnostic;
use crate::syntax::*;

/// Deepest expression tree accepted (operators, signs and parentheses on one path), so that
/// every pass over an expression can recurse safely. Real expressions are a few levels deep.
pub const MAX_EXPR_DEPTH: usize = 128;

/// Pops the top operator and its two operands and pushes their binary node (with its depth).
fn reduce(operands: &mut Vec<(Expr, usize)>, operators: &mut Vec<BinaryOp>) {
    let (Some(op), Some((rhs, dr)), Some((lhs, dl))) =
        (operators.pop(), operands.pop(), operands.pop())
    else {
        return;
    };
    let span = lhs.span.to(rhs.span);
    let depth = dl.max(dr) + 1;
    if depth > MAX_EXPR_DEPTH {
        // Too deep (reported by the caller): a leaf keeps the tree shallow.
        operands.push((Expr::number(0.0, span), depth));
        return;
    }
    operands.push((
        Expr {
            kind: ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
            span,
        },
        dl.max(dr) + 1,
    ));
}

impl Lower {
    pub(super) fn number(&mut self, p: Pair<Rule>) -> Expr {
        self.literal(p.as_str(), span_of(&p))
    }

    /// A decimal literal's value, or E012 at `span` when it does not fit in an f64.
    pub(super) fn literal(&mut self, text: &str, span: Span) -> Expr {
        // The grammar only admits decimal literals, which Rust's float parser accepts; a
        // literal beyond f64's range parses to infinity and is reported here.
        let value = text.parse::<f64>().unwrap_or(f64::NAN);
        if !value.is_finite() {
            self.diags.push(
                Diagnostic::error(
                    codes::NON_FINITE,
                    "number is too large",
                    span,
                    "does not fit in a 64-bit float",
                )
                .with_hint("numbers must be finite; the largest is about 1.8e308"),
            );
            return Expr::number(0.0, span);
        }
        Expr::number(value, span)
    }

    /// An `expr` pair (or a missing one, as zero at `fallback`) as a tree.
    pub(super) fn expr_or(&mut self, p: Option<Pair<Rule>>, fallback: Span) -> Expr {
        match p {
            Some(p) => self.expr(p).0,
            None => Expr::number(0.0, fallback),
        }
    }

    /// Lowers an `expr` pair, a flat list `operand (infix operand)*`, into a tree by
    /// precedence (shunting-yard, so no recursion per operator), and returns it with its depth.
    /// A tree deeper than [`MAX_EXPR_DEPTH`] is reported: every later pass walks it recursively.
    pub(super) fn expr(&mut self, p: Pair<Rule>) -> (Expr, usize) {
        let span = span_of(&p);
        let mut operands: Vec<(Expr, usize)> = Vec::new();
        let mut operators: Vec<BinaryOp> = Vec::new();
        let mut prefixes: Vec<(UnaryOp, usize)> = Vec::new();
        for c in kids(p) {
            let start = c.as_span().start();
            let op = match c.as_rule() {
                Rule::neg => {
                    prefixes.push((UnaryOp::Neg, start));
                    continue;
                }
                Rule::pos => {
                    prefixes.push((UnaryOp::Plus, start));
                    continue;
                }
                Rule::add => BinaryOp::Add,
                Rule::sub => BinaryOp::Sub,
                Rule::mul => BinaryOp::Mul,
                Rule::div => BinaryOp::Div,
                _ => {
                    let mut operand = self.primary(c);
                    // Never build a tree deeper than the limit (dropping one would recurse).
                    if operand.1 + prefixes.len() > MAX_EXPR_DEPTH {
                        prefixes.clear();
                        operand = (Expr::number(0.0, operand.0.span), MAX_EXPR_DEPTH + 1);
                    }
                    while let Some((op, start)) = prefixes.pop() {
                        let span = Span::new(start, operand.0.span.end);
                        operand = (
                            Expr {
                                kind: ExprKind::Unary(op, Box::new(operand.0)),
                                span,
                            },
                            operand.1 + 1,
                        );
                    }
                    operands.push(operand);
                    continue;
                }
            };
            while operators
                .last()
                .is_some_and(|top| top.precedence() >= op.precedence())
            {
                reduce(&mut operands, &mut operators);
            }
            operators.push(op);
        }
        while !operators.is_empty() {
            reduce(&mut operands, &mut operators);
        }
        let (tree, depth) = operands.pop().unwrap_or((Expr::number(0.0, span), 1));
        if depth > MAX_EXPR_DEPTH {
            self.diags.push(
                Diagnostic::error(
                    codes::TOO_DEEP,
                    "expression is nested too deeply",
                    span,
                    format!("more than {MAX_EXPR_DEPTH} levels of operators and parentheses"),
                )
                .with_hint("split it into several `let` constants"),
            );
            return (Expr::number(0.0, span), 1);
        }
        (tree, depth)
    }

    fn primary(&mut self, c: Pair<Rule>) -> (Expr, usize) {
        let span = span_of(&c);
        match c.as_rule() {
            Rule::number => (self.number(c), 1),
            Rule::name => (
                Expr {
                    kind: ExprKind::Name(Box::new(self.ident(c))),
                    span,
                },
                1,
            ),
            Rule::paren_expr => {
                let inner = first(&kids(c), Rule::expr).map(|e| self.expr(e));
                let (inner, depth) = inner.unwrap_or((Expr::number(0.0, span), 1));
                (
                    Expr {
                        kind: ExprKind::Paren(Box::new(inner)),
                        span,
                    },
                    depth + 1,
                )
            }
            Rule::call => {
                let ch = kids(c);
                let func = self.name_or(&ch, span);
                let mut depth = 1;
                let mut args = Vec::new();
                for a in of(&ch, Rule::expr) {
                    let (arg, d) = self.expr(a);
                    depth = depth.max(d + 1);
                    args.push(arg);
                }
                (
                    Expr {
                        kind: ExprKind::Call(Box::new(Call { func, args })),
                        span,
                    },
                    depth,
                )
            }
            _ => (Expr::number(0.0, span), 1),
        }
    }

    pub(super) fn point(&mut self, p: Pair<Rule>) -> Point {
        let span = span_of(&p);
        let mut inner = p.clone().into_inner();
        if let Some(q) = inner.next().filter(|q| q.as_rule() == Rule::plain_point) {
            return self.plain_point(q.as_str(), span);
        }
        let mut coords = kids(p)
            .into_iter()
            .filter(|c| matches!(c.as_rule(), Rule::expr | Rule::plain));
        let mut coord = |s: &mut Self| match coords.next() {
            // A plain literal (with its sign) is a number: its text parses as one.
            Some(c) if c.as_rule() == Rule::plain => s.number(c),
            c => s.expr_or(c, span),
        };
        let x = coord(self);
        let y = coord(self);
        Point { x, y, span }
    }

    /// A `plain_point` token, `(x, y)` with two literals and only blanks between: its
    /// coordinates are found in its text, each with the span of its digits.
    fn plain_point(&mut self, text: &str, span: Span) -> Point {
        let inside = &text[1..text.len() - 1];
        let comma = inside.find(',').unwrap_or(inside.len());
        let coord = |s: &mut Self, from: usize, to: usize| {
            let part = &inside[from..to];
            let lead = part.len() - part.trim_start().len();
            let digits = part.trim();
            let start = span.start + 1 + from + lead;
            s.literal(digits, Span::new(start, start + digits.len()))
        };
        let x = coord(self, 0, comma);
        let y = coord(self, (comma + 1).min(inside.len()), inside.len());
        Point { x, y, span }
    }

    pub(super) fn points(&mut self, p: Pair<Rule>) -> Vec<Point> {
        of(&kids(p), Rule::point)
            .into_iter()
            .map(|q| self.point(q))
            .collect()
    }
}
