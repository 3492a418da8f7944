//! The typed syntax tree of a `.clay` file: exactly what was written, with a byte span on every
//! node. It knows nothing of compilation; `parse.rs` builds it and `compile` reads it.

use serde::{Deserialize, Serialize};

/// A byte range `start..end` in the source text.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Span {
    pub start: usize,
    pub end: usize,
}

impl Span {
    pub fn new(start: usize, end: usize) -> Self {
        Self { start, end }
    }

    /// The smallest span covering both.
    pub fn to(self, other: Span) -> Span {
        Span {
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }
}

/// A name as written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ident {
    pub name: String,
    pub span: Span,
}

/// A numeric expression as written, wherever the language takes a number (docs/language.md,
/// "Expressions and constants"). Every sub-expression has its own span so diagnostics can point
/// inside; the compiler folds the tree to one number, and the compiled grammar holds only numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// A literal; finite (the parser rejects literals that overflow f64).
    Number(f64),
    /// A constant: a `let` name or a built-in such as `pi`. Boxed, like `Call`, to keep every
    /// number of a large grammar small (a literal is most of them).
    Name(Box<Ident>),
    Unary(UnaryOp, Box<Expr>),
    Binary(BinaryOp, Box<Expr>, Box<Expr>),
    /// A built-in function applied to its arguments: `sin(30)`.
    Call(Box<Call>),
    /// `(e)`, kept so that the formatter prints the parentheses as written.
    Paren(Box<Expr>),
}

/// `FUNCTION(ARG, ...)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Call {
    pub func: Ident,
    pub args: Vec<Expr>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnaryOp {
    Neg,
    Plus,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
}

impl BinaryOp {
    /// How tightly the operator binds: `*` and `/` before `+` and `-`.
    pub fn precedence(self) -> u8 {
        match self {
            BinaryOp::Add | BinaryOp::Sub => 1,
            BinaryOp::Mul | BinaryOp::Div => 2,
        }
    }

    pub fn symbol(self) -> &'static str {
        match self {
            BinaryOp::Add => "+",
            BinaryOp::Sub => "-",
            BinaryOp::Mul => "*",
            BinaryOp::Div => "/",
        }
    }
}

impl Expr {
    /// A literal, as tools that build trees (authoring) write numbers.
    pub fn number(value: f64, span: Span) -> Self {
        Self {
            kind: ExprKind::Number(value),
            span,
        }
    }
}

/// `(x, y)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub x: Expr,
    pub y: Expr,
    pub span: Span,
}

/// `let NAME = EXPR`: a named constant, visible from the end of its declaration to the end of
/// the file.
#[derive(Clone, Debug, PartialEq)]
pub struct LetDecl {
    pub name: Ident,
    pub value: Expr,
    pub span: Span,
}

/// `param NAME [: TYPE] = DEFAULT [in LO..HI]`: a grammar parameter, a constant whose value a
/// user may override when compiling (within the range, when one is written). Visible like a
/// `let`.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamDecl {
    pub name: Ident,
    /// The type written after `:`; a number without one.
    pub ty: Option<ParamTypeDecl>,
    /// The default value.
    pub value: ParamDefault,
    pub range: Option<ParamRange>,
    pub span: Span,
}

/// A parameter's default: an expression (a number, `true`, `false`) or a string (a choice).
#[derive(Clone, Debug, PartialEq)]
pub enum ParamDefault {
    Expr(Expr),
    Text(StringLit),
}

impl ParamDefault {
    pub fn span(&self) -> Span {
        match self {
            ParamDefault::Expr(e) => e.span,
            ParamDefault::Text(s) => s.span,
        }
    }
}

/// `: TYPE` after a parameter's name; `span` is the type without the colon.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamTypeDecl {
    pub kind: ParamTypeKind,
    pub span: Span,
}

/// The type of a parameter as written.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamTypeKind {
    /// A type name (`number`, `int`, `bool`, `seed`, or a mistake the compiler reports).
    Named(Ident),
    /// `choice("a", "b", ...)`.
    Choice(Vec<StringLit>),
}

/// `in LO..HI`: the inclusive range of a parameter's values.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamRange {
    pub low: Expr,
    pub high: Expr,
    /// From `in` to the end of HI.
    pub span: Span,
}

/// A whole file.
#[derive(Clone, Debug, PartialEq)]
pub struct File {
    pub items: Vec<Item>,
    pub span: Span,
}

/// A top-level item.
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    Import(ImportDecl),
    Let(LetDecl),
    Param(ParamDecl),
    Solver(SolverBlock),
    SiteType(SiteTypeDecl),
    Piece(PieceDecl),
    Stretch(StretchDecl),
    Merge(MergeDecl),
    Cut(CutDecl),
    Model(ModelBlock),
}

impl Item {
    pub fn span(&self) -> Span {
        match self {
            Item::Import(x) => x.span,
            Item::Let(x) => x.span,
            Item::Param(x) => x.span,
            Item::Solver(x) => x.span,
            Item::SiteType(x) => x.span,
            Item::Piece(x) => x.span,
            Item::Stretch(x) => x.span,
            Item::Merge(x) => x.span,
            Item::Cut(x) => x.span,
            Item::Model(x) => x.span,
        }
    }
}

/// `import "PATH"`: the declarations of another file (relative to this one's folder).
#[derive(Clone, Debug, PartialEq)]
pub struct ImportDecl {
    pub path: StringLit,
    pub span: Span,
}

/// A string literal; `value` is the text between the quotes, `span` includes them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StringLit {
    pub value: String,
    pub span: Span,
}

/// `solver { NAME = NUMBER ... }`; `keyword` is the span of `solver`.
#[derive(Clone, Debug, PartialEq)]
pub struct SolverBlock {
    pub entries: Vec<SolverEntry>,
    pub keyword: Span,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SolverEntry {
    pub name: Ident,
    pub value: Expr,
    pub span: Span,
}

/// `site type NAME [docks A, B, ...]`.
#[derive(Clone, Debug, PartialEq)]
pub struct SiteTypeDecl {
    pub name: Ident,
    pub docks: Vec<Ident>,
    pub span: Span,
}

/// `piece NAME [extends BASE] { ... }`.
#[derive(Clone, Debug, PartialEq)]
pub struct PieceDecl {
    pub name: Ident,
    /// `extends BASE`: the piece inherits BASE's statements (docs/language.md).
    pub extends: Option<Ident>,
    pub stmts: Vec<PieceStmt>,
    pub span: Span,
}

/// A statement inside a piece.
#[derive(Clone, Debug, PartialEq)]
pub enum PieceStmt {
    Vertex(VertexDecl),
    Edges(EdgesDecl),
    Site(SiteDecl),
    Axis(AxisDecl),
    Geometry(GeometryDecl),
    State(StateDecl),
}

/// `vertex NAME (x, y)`, or `NAME (x, y)` inside a state.
#[derive(Clone, Debug, PartialEq)]
pub struct VertexDecl {
    pub name: Ident,
    pub pos: Point,
    pub span: Span,
}

/// `edges a-b-c, d-e`: each path is a list of at least two names.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgesDecl {
    pub paths: Vec<Vec<Ident>>,
    pub span: Span,
}

/// `site NAME: TYPE [v1, v2, ...] out (dx, dy)`.
#[derive(Clone, Debug, PartialEq)]
pub struct SiteDecl {
    pub name: Ident,
    pub site_type: Ident,
    pub vertices: Vec<Ident>,
    /// Span of the `[...]` list.
    pub vertices_span: Span,
    pub out: Point,
    pub span: Span,
}

/// `axis FROM -> TO`.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisDecl {
    pub from: Ident,
    pub to: Ident,
    pub span: Span,
}

/// `rigid` or `skinned`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKw {
    Rigid,
    Skinned,
}

/// A `polygon` or `polyline` of proxy geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct GeometryDecl {
    pub shape: ShapeDecl,
    /// The binding keyword and its span, when written.
    pub binding: Option<(BindingKw, Span)>,
    pub fill: Colour,
    /// `extrude HEIGHT [above BASE]`, when written.
    pub extrude: Option<ExtrudeDecl>,
    /// Span of the `polygon`/`polyline` keyword.
    pub keyword: Span,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ShapeDecl {
    Polygon {
        outer: Vec<Point>,
        holes: Vec<HoleDecl>,
    },
    Polyline {
        width: Expr,
        points: Vec<Point>,
    },
    /// `mesh [rigid|skinned] "PATH" [fill COLOUR]`: a 3D mesh asset (`GeometryDecl::fill` is
    /// unused; `fill` here overrides the asset's own colours when written).
    Mesh {
        path: StringLit,
        fill: Option<Colour>,
    },
}

/// `extrude HEIGHT [above BASE]`: the proxy's heights in the 3D export.
#[derive(Clone, Debug, PartialEq)]
pub struct ExtrudeDecl {
    pub height: Expr,
    pub above: Option<Expr>,
    pub span: Span,
}

/// `hole { POINT... }`.
#[derive(Clone, Debug, PartialEq)]
pub struct HoleDecl {
    pub points: Vec<Point>,
    pub span: Span,
}

/// `#rrggbb` or `#rrggbbaa`, already decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Colour {
    pub rgba: [u8; 4],
    pub span: Span,
}

/// `state NAME { ... }`, or a derived state `state NAME bend ANGLE [{ ... }]` /
/// `state NAME mirror OTHER [{ ... }]` (then `positions` and `edges` are empty and `geometry`
/// is the optional body's).
#[derive(Clone, Debug, PartialEq)]
pub struct StateDecl {
    pub name: Ident,
    pub positions: Vec<VertexDecl>,
    pub edges: Vec<EdgesDecl>,
    pub geometry: Vec<GeometryDecl>,
    /// How a derived state is made from another; `None` for a state that lists positions.
    pub derive: Option<StateDerive>,
    pub span: Span,
}

/// The transformation a derived rest state applies.
#[derive(Clone, Debug, PartialEq)]
pub enum DeriveKind {
    /// `bend ANGLE`: the axis laid on a circular arc turning by ANGLE degrees (counter-clockwise).
    Bend(Expr),
    /// `mirror OTHER`: state OTHER (or `base`) reflected across the axis line.
    Mirror(Ident),
}

/// `bend ANGLE` or `mirror OTHER` after a state's name.
#[derive(Clone, Debug, PartialEq)]
pub struct StateDerive {
    pub kind: DeriveKind,
    /// Span of the `bend`/`mirror` keyword.
    pub keyword: Span,
    /// From the keyword to the end of its argument.
    pub span: Span,
}

/// `stretch PIECE from SITE to SITE { ... }`.
#[derive(Clone, Debug, PartialEq)]
pub struct StretchDecl {
    pub piece: Ident,
    pub from: Ident,
    pub to: Ident,
    /// Every `min N` written (more than one is reported).
    pub min: Vec<Expr>,
    /// Every `max N` written (more than one is reported).
    pub max: Vec<Expr>,
    /// Every `variants { ... }` written (more than one is reported).
    pub variants: Vec<VariantsDecl>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct VariantsDecl {
    pub entries: Vec<VariantEntry>,
    pub span: Span,
}

/// `PIECE FREQ`.
#[derive(Clone, Debug, PartialEq)]
pub struct VariantEntry {
    pub piece: Ident,
    pub frequency: Expr,
    pub span: Span,
}

/// `PIECE.SITE`.
#[derive(Clone, Debug, PartialEq)]
pub struct SitePath {
    pub piece: Ident,
    pub site: Ident,
    pub span: Span,
}

/// `merge A.s onto B.t [into J.u] [within D]`.
#[derive(Clone, Debug, PartialEq)]
pub struct MergeDecl {
    pub mover: SitePath,
    pub target: SitePath,
    pub junction: Option<SitePath>,
    pub within: Option<Expr>,
    pub span: Span,
}

/// `cut J.u into PIECE`.
#[derive(Clone, Debug, PartialEq)]
pub struct CutDecl {
    pub junction: SitePath,
    pub into: Ident,
    pub span: Span,
}

/// `model { ... }`; `keyword` is the span of `model`.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelBlock {
    pub stmts: Vec<ModelStmt>,
    pub keyword: Span,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ModelStmt {
    Instance(InstanceDecl),
    Chain(ChainDecl),
    Dock(DockDecl),
    If(IfBlock),
}

/// `if PARAM { ... } [else { ... }]`: model statements a `bool` parameter switches.
#[derive(Clone, Debug, PartialEq)]
pub struct IfBlock {
    /// The `bool` parameter.
    pub cond: Ident,
    pub then: Vec<ModelStmt>,
    /// The `else` block's statements, when one is written.
    pub otherwise: Option<Vec<ModelStmt>>,
    /// The `if` keyword.
    pub keyword: Span,
    /// The `}` that closes the first block.
    pub then_close: Span,
    /// The `else` keyword, when there is one.
    pub else_keyword: Option<Span>,
    pub span: Span,
}

impl ModelStmt {
    /// Every statement, those inside `if` blocks too, depth first in source order.
    pub fn walk<'a>(stmts: &'a [ModelStmt], out: &mut Vec<&'a ModelStmt>) {
        for s in stmts {
            out.push(s);
            if let ModelStmt::If(b) = s {
                Self::walk(&b.then, out);
                if let Some(e) = &b.otherwise {
                    Self::walk(e, out);
                }
            }
        }
    }
}

/// `NAME = PIECE [at (x, y)] [rotate DEG]`.
#[derive(Clone, Debug, PartialEq)]
pub struct InstanceDecl {
    pub name: Ident,
    pub piece: Ident,
    pub at: Option<Point>,
    pub rotate: Option<Expr>,
    pub span: Span,
}

/// `NAME = chain PIECE x N [along S -> T] [at (x, y)] [rotate DEG]`.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainDecl {
    pub name: Ident,
    pub piece: Ident,
    pub count: Expr,
    pub along: Option<(Ident, Ident)>,
    pub at: Option<Point>,
    pub rotate: Option<Expr>,
    pub span: Span,
}

/// `dock A.s to B.t`.
#[derive(Clone, Debug, PartialEq)]
pub struct DockDecl {
    pub a: InstanceSitePath,
    pub b: InstanceSitePath,
    pub span: Span,
}

/// `INSTANCE.SITE` or `CHAIN[INDEX].SITE`.
#[derive(Clone, Debug, PartialEq)]
pub struct InstanceSitePath {
    pub instance: Ident,
    pub index: Option<ElementIndex>,
    pub site: Ident,
    pub span: Span,
}

/// `[3]` or `[last]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ElementIndex {
    pub index: ElementIndexKind,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ElementIndexKind {
    /// A written index; saturates at `u64::MAX` for absurd literals.
    At(u64),
    Last,
}
