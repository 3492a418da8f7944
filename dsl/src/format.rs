//! The canonical printer of `.clay` text: [`format`] re-prints a source file in the one house
//! style and keeps its comments; [`print_file`] prints a syntax tree built in code (the authoring
//! tools and the editor write grammars through it).
//!
//! Style (docs/authoring.md): 4-space indent, one statement per line, `(x, y)`, `[a, b]`,
//! `a -> b`, `a-b-c`, lowercase colours; a blank line between top-level items, except that runs
//! of one-line items of one kind (`site type` lines; one-line rules) keep the author's choice;
//! inside blocks at most one blank line, only where the author left one; point lists four points
//! to a line (fewer if the line would pass [`MAX_WIDTH`] columns). Numbers keep the text the
//! author wrote (`0.50` stays `0.50`, so formatting never rounds a coordinate); numbers of a tree
//! built in code print as the shortest text that reads back to the same `f64`
//! ([`format_number`]).
//!
//! Comments are not in the syntax tree, so they are recovered from the source by position: each
//! comment is printed before the next statement (or point) that starts after it; a comment on
//! the same line after a statement, a point or a block's `{` or `}` stays trailing on that line;
//! comments before a block's `}` stay inside the block. A comment written inside a one-line
//! statement (`vertex /* x */ a (0, 0)`) moves to its own line just before that statement.

use crate::diagnostic::Diagnostics;
use crate::syntax::*;

/// Point lists are wrapped so that their lines stay within this many columns.
pub const MAX_WIDTH: usize = 100;
/// Points per line in a point list (fewer when they would pass [`MAX_WIDTH`]).
pub const POINTS_PER_LINE: usize = 4;

/// Formats `.clay` source text canonically. Text that does not parse returns the parser's
/// diagnostics; the result of a successful format parses and compiles to the same grammar, and
/// formatting it again returns it unchanged.
pub fn format(source: &str) -> Result<String, Diagnostics> {
    let file = crate::parse::parse(source)?;
    Ok(Printer::new(Some(source)).file(&file))
}

/// Prints a syntax tree (typically built in code, with default spans) in the canonical style.
/// Numbers print through [`format_number`]; the tree carries no comments.
pub fn print_file(file: &File) -> String {
    Printer::new(None).file(file)
}

/// The shortest decimal text that parses back to `x` (`0.5`, `12`, `-3.25`, `1e-7`); exponent
/// form only below 1e-6 or from 1e16 on. The language only has finite numbers: a non-finite
/// `x` prints as `0`, so callers building trees must check their values first.
pub fn format_number(x: f64) -> String {
    if !x.is_finite() {
        return "0".to_string();
    }
    let a = x.abs();
    if a != 0.0 && !(1e-6..1e16).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// The spans of every comment (`// ...` without its newline, and whole nested `/* ... */`) in
/// the text, in order. An unterminated block comment runs to the end of the text. A string
/// (`"..."`, to its closing quote or the end of its line) holds no comment: `"a//b.obj"`.
pub fn comment_spans(source: &str) -> Vec<Span> {
    let b = source.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i + 1 < b.len() {
        if b[i] == b'"' {
            i += 1;
            while i < b.len() && !matches!(b[i], b'"' | b'\n') {
                i += 1;
            }
            i += 1;
        } else if b[i] == b'/' && b[i + 1] == b'/' {
            let start = i;
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            spans.push(Span::new(start, i));
        } else if b[i] == b'/' && b[i + 1] == b'*' {
            let start = i;
            let mut depth = 0usize;
            while i < b.len() {
                if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            spans.push(Span::new(start, i.min(b.len())));
        } else {
            i += 1;
        }
    }
    spans
}

struct Comment {
    span: Span,
    /// The comment's text with trailing whitespace removed.
    text: String,
    /// A block comment spanning several lines never trails a statement.
    multiline: bool,
}

const INDENT: &str = "    ";

struct Printer<'s> {
    src: Option<&'s str>,
    comments: Vec<Comment>,
    /// The next comment not printed yet.
    next: usize,
    lines: Vec<String>,
    /// Source offset where the last printed thing ended (for the author's blank lines).
    last_end: usize,
    /// Nothing printed yet in the current block: no blank line goes here.
    block_start: bool,
    /// The next line starts a top-level item that must be set off by a blank line.
    force_blank: bool,
}

impl<'s> Printer<'s> {
    fn new(src: Option<&'s str>) -> Self {
        let comments = src
            .map(|s| {
                comment_spans(s)
                    .into_iter()
                    .map(|span| {
                        let text = s[span.start..span.end].trim_end().to_string();
                        Comment {
                            span,
                            multiline: text.contains('\n'),
                            text,
                        }
                    })
                    .collect()
            })
            .unwrap_or_default();
        Self {
            src,
            comments,
            next: 0,
            lines: Vec::new(),
            last_end: 0,
            block_start: true,
            force_blank: false,
        }
    }

    // ---- layout primitives -------------------------------------------------------------

    /// Whether the author left a blank line between source offsets `a` and `b`.
    fn author_blank(&self, a: usize, b: usize) -> bool {
        let Some(src) = self.src else { return false };
        let Some(gap) = src.get(a..b) else {
            return false;
        };
        let parts: Vec<&str> = gap.split('\n').collect();
        parts.len() > 2
            && parts[1..parts.len() - 1]
                .iter()
                .any(|p| p.trim().is_empty())
    }

    /// Prints one line (which may hold a multi-line block comment) for source `start..end`.
    fn line(&mut self, indent: usize, text: &str, start: usize, end: usize, allow_blank: bool) {
        let blank = !self.lines.is_empty()
            && !self.block_start
            && (self.force_blank || (allow_blank && self.author_blank(self.last_end, start)));
        if blank && self.lines.last().is_some_and(|l| !l.is_empty()) {
            self.lines.push(String::new());
        }
        self.force_blank = false;
        self.block_start = false;
        self.lines.push(format!("{}{text}", INDENT.repeat(indent)));
        self.last_end = self.last_end.max(end);
    }

    /// Prints, each on its own line, every pending comment that starts before `before`.
    fn leading(&mut self, indent: usize, before: usize) {
        while let Some(c) = self.comments.get(self.next) {
            if c.span.start >= before {
                break;
            }
            let (text, span) = (c.text.clone(), c.span);
            self.next += 1;
            self.line(indent, &text, span.start, span.end, true);
        }
    }

    /// The pending comment that sits on the same line right after source offset `after`
    /// (only whitespace or commas between), taken off the queue.
    fn take_trailing(&mut self, after: usize) -> Option<String> {
        let src = self.src?;
        let c = self.comments.get(self.next)?;
        if c.multiline || c.span.start < after {
            return None;
        }
        let gap = src.get(after..c.span.start)?;
        if !gap
            .chars()
            .all(|ch| ch == ',' || (ch.is_whitespace() && ch != '\n'))
        {
            return None;
        }
        let (text, end) = (c.text.clone(), c.span.end);
        self.next += 1;
        self.last_end = self.last_end.max(end);
        Some(text)
    }

    /// Appends the trailing comment after `after`, if any, to the last printed line.
    fn trailing(&mut self, after: usize) {
        if let Some(t) = self.take_trailing(after)
            && let Some(last) = self.lines.last_mut()
        {
            last.push(' ');
            last.push_str(&t);
        }
    }

    /// Whether a pending comment starts before `before`.
    fn comment_before(&self, before: usize) -> bool {
        self.comments
            .get(self.next)
            .is_some_and(|c| c.span.start < before)
    }

    /// Whether any comment lies inside `span`.
    fn comment_within(&self, span: Span) -> bool {
        self.comments
            .iter()
            .any(|c| c.span.start >= span.start && c.span.end <= span.end)
    }

    /// The offset of the first token at or after `from`, skipping whitespace and comments.
    fn next_token(&self, from: usize) -> usize {
        let Some(src) = self.src else { return from };
        let b = src.as_bytes();
        let mut i = from;
        loop {
            while i < b.len() && b[i].is_ascii_whitespace() {
                i += 1;
            }
            match self.comments.iter().find(|c| c.span.start == i) {
                Some(c) => i = c.span.end,
                None => return i,
            }
        }
    }

    /// A one-line statement covering `span`.
    fn stmt(&mut self, indent: usize, text: &str, span: Span) {
        self.leading(indent, span.end);
        self.line(indent, text, span.start, span.end, true);
        self.trailing(span.end);
    }

    /// Opens a block: `header {`, where the header's last token ends at `header_end`.
    fn open(&mut self, indent: usize, header: &str, start: usize, header_end: usize) {
        let brace = self.next_token(header_end);
        self.leading(indent, brace);
        self.line(indent, &format!("{header} {{"), start, brace + 1, true);
        self.trailing(brace + 1);
        self.block_start = true;
    }

    /// Closes the block whose span is `span` (it ends with `}`), keeping comments before `}`.
    fn close(&mut self, indent: usize, span: Span) {
        let brace = if self.src.is_some() {
            span.end.saturating_sub(1)
        } else {
            0
        };
        self.leading(indent + 1, brace);
        self.line(indent, "}", brace, span.end, false);
        self.trailing(span.end);
    }

    // ---- tokens ----------------------------------------------------------------------------

    /// An expression in canonical spacing (`a + b * 2`, `-x`, `sin(30)`), parentheses as
    /// written; a literal keeps the author's text.
    fn num(&self, n: &Expr) -> String {
        match &n.kind {
            ExprKind::Number(value) => {
                match self.src.and_then(|s| s.get(n.span.start..n.span.end)) {
                    Some(text) if !text.is_empty() && n.span.end > n.span.start => text.to_string(),
                    _ => format_number(*value),
                }
            }
            ExprKind::Name(id) => id.name.clone(),
            ExprKind::Unary(op, x) => {
                let sign = match op {
                    UnaryOp::Neg => "-",
                    UnaryOp::Plus => "+",
                };
                format!("{sign}{}", self.num(x))
            }
            ExprKind::Binary(op, a, b) => {
                format!("{} {} {}", self.num(a), op.symbol(), self.num(b))
            }
            ExprKind::Call(call) => {
                let (f, args) = (&call.func, &call.args);
                let args: Vec<String> = args.iter().map(|a| self.num(a)).collect();
                format!("{}({})", f.name, args.join(", "))
            }
            ExprKind::Paren(x) => format!("({})", self.num(x)),
        }
    }

    fn point(&self, p: &Point) -> String {
        format!("({}, {})", self.num(&p.x), self.num(&p.y))
    }

    fn colour(c: &Colour) -> String {
        let [r, g, b, a] = c.rgba;
        if a == 255 {
            format!("#{r:02x}{g:02x}{b:02x}")
        } else {
            format!("#{r:02x}{g:02x}{b:02x}{a:02x}")
        }
    }

    fn names(list: &[Ident], sep: &str) -> String {
        list.iter()
            .map(|i| i.name.as_str())
            .collect::<Vec<_>>()
            .join(sep)
    }

    fn site_path(p: &SitePath) -> String {
        format!("{}.{}", p.piece.name, p.site.name)
    }

    fn instance_site(p: &InstanceSitePath) -> String {
        let index = match p.index.map(|i| i.index) {
            None => String::new(),
            Some(ElementIndexKind::At(n)) => format!("[{n}]"),
            Some(ElementIndexKind::Last) => "[last]".to_string(),
        };
        format!("{}{index}.{}", p.instance.name, p.site.name)
    }

    fn placement(&self, at: &Option<Point>, rotate: &Option<Expr>) -> String {
        let mut s = String::new();
        if let Some(p) = at {
            s += &format!(" at {}", self.point(p));
        }
        if let Some(r) = rotate {
            s += &format!(" rotate {}", self.num(r));
        }
        s
    }

    // ---- items -----------------------------------------------------------------------------

    fn file(mut self, file: &File) -> String {
        let mut prev: Option<u8> = None;
        for (i, item) in file.items.iter().enumerate() {
            let kind = self.one_line_kind(item);
            self.force_blank = i > 0 && (kind.is_none() || kind != prev);
            prev = kind;
            self.item(item);
        }
        // Comments after the last item.
        self.force_blank = false;
        self.leading(0, usize::MAX);
        let mut out = self.lines.join("\n");
        out.push('\n');
        out
    }

    /// Items printed on one line, tagged by kind (site types; rules): consecutive ones of a
    /// kind need no blank line between them.
    fn one_line_kind(&self, item: &Item) -> Option<u8> {
        match item {
            Item::Import(_) => Some(3),
            Item::SiteType(_) => Some(1),
            Item::Let(_) | Item::Param(_) => Some(3),
            Item::Merge(_) | Item::Cut(_) => Some(2),
            Item::Stretch(s) if self.stretch_inline(s) => Some(2),
            _ => None,
        }
    }

    fn item(&mut self, item: &Item) {
        match item {
            Item::Let(l) => {
                let t = format!("let {} = {}", l.name.name, self.num(&l.value));
                self.stmt(0, &t, l.span);
            }
            Item::Param(p) => {
                let ty = match p.ty.as_ref().map(|t| &t.kind) {
                    None => String::new(),
                    Some(ParamTypeKind::Named(id)) => format!(": {}", id.name),
                    Some(ParamTypeKind::Choice(strings)) => {
                        let all: Vec<String> =
                            strings.iter().map(|s| format!("\"{}\"", s.value)).collect();
                        format!(": choice({})", all.join(", "))
                    }
                };
                let value = match &p.value {
                    ParamDefault::Expr(e) => self.num(e),
                    ParamDefault::Text(t) => format!("\"{}\"", t.value),
                };
                let mut t = format!("param {}{ty} = {value}", p.name.name);
                if let Some(r) = &p.range {
                    t += &format!(" in {}..{}", self.num(&r.low), self.num(&r.high));
                }
                self.stmt(0, &t, p.span);
            }
            Item::Import(i) => self.stmt(0, &format!("import \"{}\"", i.path.value), i.span),
            Item::Solver(s) => {
                self.open(0, "solver", s.span.start, s.keyword.end);
                for e in &s.entries {
                    self.stmt(
                        1,
                        &format!("{} = {}", e.name.name, self.num(&e.value)),
                        e.span,
                    );
                }
                self.close(0, s.span);
            }
            Item::SiteType(s) => {
                let mut t = format!("site type {}", s.name.name);
                if !s.docks.is_empty() {
                    t += &format!(" docks {}", Self::names(&s.docks, ", "));
                }
                self.stmt(0, &t, s.span);
            }
            Item::Piece(p) => self.piece(p),
            Item::Stretch(s) => self.stretch(s),
            Item::Merge(m) => {
                let mut t = format!(
                    "merge {} onto {}",
                    Self::site_path(&m.mover),
                    Self::site_path(&m.target)
                );
                if let Some(j) = &m.junction {
                    t += &format!(" into {}", Self::site_path(j));
                }
                if let Some(w) = &m.within {
                    t += &format!(" within {}", self.num(w));
                }
                self.stmt(0, &t, m.span);
            }
            Item::Cut(c) => {
                let t = format!("cut {} into {}", Self::site_path(&c.junction), c.into.name);
                self.stmt(0, &t, c.span);
            }
            Item::Model(m) => self.model(m),
        }
    }

    fn piece(&mut self, p: &PieceDecl) {
        let (header, header_end) = match &p.extends {
            Some(b) => (
                format!("piece {} extends {}", p.name.name, b.name),
                b.span.end,
            ),
            None => (format!("piece {}", p.name.name), p.name.span.end),
        };
        self.open(0, &header, p.span.start, header_end);
        for s in &p.stmts {
            match s {
                PieceStmt::Vertex(v) => self.vertex(1, v, "vertex "),
                PieceStmt::Edges(e) => self.edges(1, e),
                PieceStmt::Site(s) => {
                    let t = format!(
                        "site {}: {} [{}] out {}",
                        s.name.name,
                        s.site_type.name,
                        Self::names(&s.vertices, ", "),
                        self.point(&s.out)
                    );
                    self.stmt(1, &t, s.span);
                }
                PieceStmt::Axis(a) => {
                    self.stmt(1, &format!("axis {} -> {}", a.from.name, a.to.name), a.span)
                }
                PieceStmt::Geometry(g) => self.geometry(1, g),
                PieceStmt::State(s) => self.state(1, s),
            }
        }
        self.close(0, p.span);
    }

    fn vertex(&mut self, indent: usize, v: &VertexDecl, keyword: &str) {
        let t = format!("{keyword}{} {}", v.name.name, self.point(&v.pos));
        self.stmt(indent, &t, v.span);
    }

    fn edges(&mut self, indent: usize, e: &EdgesDecl) {
        let paths: Vec<String> = e.paths.iter().map(|p| Self::names(p, "-")).collect();
        self.stmt(indent, &format!("edges {}", paths.join(", ")), e.span);
    }

    fn geometry(&mut self, indent: usize, g: &GeometryDecl) {
        let binding = match g.binding {
            None => "",
            Some((BindingKw::Rigid, _)) => " rigid",
            Some((BindingKw::Skinned, _)) => " skinned",
        };
        let header = match &g.shape {
            ShapeDecl::Mesh { path, fill } => {
                let fill = fill
                    .as_ref()
                    .map_or(String::new(), |c| format!(" fill {}", Self::colour(c)));
                let text = format!("mesh{binding} \"{}\"{fill}", path.value);
                return self.stmt(indent, &text, g.span);
            }
            ShapeDecl::Polygon { .. } => format!("polygon{binding} fill {}", Self::colour(&g.fill)),
            ShapeDecl::Polyline { width, .. } => {
                format!(
                    "polyline{binding} width {} fill {}",
                    self.num(width),
                    Self::colour(&g.fill)
                )
            }
        };
        let mut header = header;
        let mut head_end = g.fill.span.end;
        if let Some(e) = &g.extrude {
            header += &format!(" extrude {}", self.num(&e.height));
            if let Some(b) = &e.above {
                header += &format!(" above {}", self.num(b));
            }
            head_end = e.span.end;
        }
        self.open(indent, &header, g.span.start, head_end);
        match &g.shape {
            ShapeDecl::Polygon { outer, holes } => {
                self.points(indent + 1, outer);
                for h in holes {
                    self.open(
                        indent + 1,
                        "hole",
                        h.span.start,
                        h.span.start + "hole".len(),
                    );
                    self.points(indent + 2, &h.points);
                    self.close(indent + 1, h.span);
                }
            }
            ShapeDecl::Polyline { points, .. } => self.points(indent + 1, points),
            ShapeDecl::Mesh { .. } => {}
        }
        self.close(indent, g.span);
    }

    /// Points, [`POINTS_PER_LINE`] to a line and never past [`MAX_WIDTH`]; a comment between
    /// points breaks the line.
    fn points(&mut self, indent: usize, points: &[Point]) {
        let width = MAX_WIDTH.saturating_sub(indent * INDENT.len());
        let mut cur = String::new();
        let (mut start, mut end) = (0, 0);
        let mut on_line = 0;
        for p in points {
            if self.comment_before(p.span.end) {
                self.flush_points(indent, &mut cur, start, end);
                self.leading(indent, p.span.end);
            }
            let t = self.point(p);
            if !cur.is_empty() && (on_line == POINTS_PER_LINE || cur.len() + 1 + t.len() > width) {
                self.flush_points(indent, &mut cur, start, end);
            }
            if cur.is_empty() {
                start = p.span.start;
                on_line = 0;
            } else {
                cur.push(' ');
            }
            cur += &t;
            on_line += 1;
            end = p.span.end;
            if let Some(c) = self.take_trailing(p.span.end) {
                cur.push(' ');
                cur += &c;
                self.flush_points(indent, &mut cur, start, end);
            }
        }
        self.flush_points(indent, &mut cur, start, end);
    }

    fn flush_points(&mut self, indent: usize, cur: &mut String, start: usize, end: usize) {
        if !cur.is_empty() {
            self.line(indent, cur, start, end, false);
            cur.clear();
        }
    }

    fn state(&mut self, indent: usize, s: &StateDecl) {
        if let Some(d) = &s.derive {
            return self.derived_state(indent, s, d);
        }
        self.open(
            indent,
            &format!("state {}", s.name.name),
            s.span.start,
            s.name.span.end,
        );
        // The tree keeps a state's statements by kind; print them in source order.
        enum St<'a> {
            Pos(&'a VertexDecl),
            Edges(&'a EdgesDecl),
            Geom(&'a GeometryDecl),
        }
        let mut stmts: Vec<(usize, St)> = Vec::new();
        stmts.extend(s.positions.iter().map(|v| (v.span.start, St::Pos(v))));
        stmts.extend(s.edges.iter().map(|e| (e.span.start, St::Edges(e))));
        stmts.extend(s.geometry.iter().map(|g| (g.span.start, St::Geom(g))));
        if self.src.is_some() {
            stmts.sort_by_key(|(start, _)| *start);
        }
        for (_, st) in stmts {
            match st {
                St::Pos(v) => self.vertex(indent + 1, v, ""),
                St::Edges(e) => self.edges(indent + 1, e),
                St::Geom(g) => self.geometry(indent + 1, g),
            }
        }
        self.close(indent, s.span);
    }

    /// `state NAME bend ANGLE` / `state NAME mirror OTHER`, with its geometry body if it has
    /// geometry (an empty body is dropped: it means the same as none).
    fn derived_state(&mut self, indent: usize, s: &StateDecl, d: &StateDerive) {
        let how = match &d.kind {
            DeriveKind::Bend(angle) => format!("bend {}", self.num(angle)),
            DeriveKind::Mirror(other) => format!("mirror {}", other.name),
        };
        let header = format!("state {} {how}", s.name.name);
        // only a comment inside the braces keeps them: one before `{` is printed before the
        // statement, and a second `fmt` would drop the braces the first kept (issue 47)
        let inside = Span::new(self.next_token(d.span.end), s.span.end);
        if s.geometry.is_empty() && !self.comment_within(inside) {
            // No comment sits in an empty `{ }` (checked above), so its braces can go.
            self.stmt(indent, &header, s.span);
            return;
        }
        self.open(indent, &header, s.span.start, d.span.end);
        for g in &s.geometry {
            self.geometry(indent + 1, g);
        }
        self.close(indent, s.span);
    }

    /// Whether the stretch rule's body is written `{ min N }` or `{ max N }` on its line (or
    /// has no body): one statement at most. `min` and `max` together take a line each. Only a
    /// comment inside the braces keeps them on several lines: one before `{` is printed before
    /// the rule, and a second `fmt` would join what the first split (issue 47).
    fn stretch_inline(&self, s: &StretchDecl) -> bool {
        s.variants.is_empty()
            && s.min.len() + s.max.len() <= 1
            && !self.comment_within(Span::new(self.next_token(s.to.span.end), s.span.end))
    }

    fn stretch(&mut self, s: &StretchDecl) {
        let header = format!(
            "stretch {} from {} to {}",
            s.piece.name, s.from.name, s.to.name
        );
        if self.stretch_inline(s) {
            let t = match (s.min.first(), s.max.first()) {
                (Some(m), _) => format!("{header} {{ min {} }}", self.num(m)),
                (None, Some(m)) => format!("{header} {{ max {} }}", self.num(m)),
                (None, None) => header,
            };
            return self.stmt(0, &t, s.span);
        }
        self.open(0, &header, s.span.start, s.to.span.end);
        // A statement of the body: `min N` / `max N` (the keyword and N), or `variants`.
        enum Stmt<'a> {
            Bound(&'static str, &'a Expr),
            Variants(&'a VariantsDecl),
        }
        // Without the source: `min`, `max`, then `variants`.
        let mut body: Vec<(usize, Stmt)> = Vec::new();
        body.extend(s.min.iter().map(|m| (m.span.start, Stmt::Bound("min", m))));
        body.extend(s.max.iter().map(|m| (m.span.start, Stmt::Bound("max", m))));
        body.extend(s.variants.iter().map(|v| (v.span.start, Stmt::Variants(v))));
        if self.src.is_some() {
            body.sort_by_key(|b| b.0);
        }
        for (_, stmt) in body {
            match stmt {
                Stmt::Bound(keyword, m) => {
                    // The span of a `min`/`max` statement is not kept; the keyword is 4 bytes
                    // before a number written after one space, and a comment in between is
                    // printed before it.
                    let span = Span::new(m.span.start.saturating_sub(4), m.span.end);
                    self.stmt(1, &format!("{keyword} {}", self.num(m)), span);
                }
                Stmt::Variants(v) => self.variants(1, v),
            }
        }
        // Only a rule with a body is printed as a block, so its span ends with `}`.
        self.close(0, s.span);
    }

    fn variants(&mut self, indent: usize, v: &VariantsDecl) {
        let entries: Vec<String> = v
            .entries
            .iter()
            .map(|e| format!("{} {}", e.piece.name, self.num(&e.frequency)))
            .collect();
        let inline = format!("variants {{ {} }}", entries.join(", "));
        // a comment between `variants` and `{` is printed before the statement (by `open` or
        // `stmt`): only comments inside the braces keep the block on several lines, or a
        // second `fmt` would join what the first split (issue 47)
        let inside = Span::new(self.next_token(v.span.start + "variants".len()), v.span.end);
        if !self.comment_within(inside) && indent * INDENT.len() + inline.len() <= MAX_WIDTH {
            return self.stmt(indent, &inline, v.span);
        }
        self.open(
            indent,
            "variants",
            v.span.start,
            v.span.start + "variants".len(),
        );
        for (e, text) in v.entries.iter().zip(entries) {
            self.stmt(indent + 1, &format!("{text},"), e.span);
        }
        self.close(indent, v.span);
    }

    fn model(&mut self, m: &ModelBlock) {
        self.open(0, "model", m.span.start, m.keyword.end);
        self.model_stmts(1, &m.stmts);
        self.close(0, m.span);
    }

    fn model_stmts(&mut self, indent: usize, stmts: &[ModelStmt]) {
        for s in stmts {
            match s {
                ModelStmt::Instance(i) => {
                    let t = format!(
                        "{} = {}{}",
                        i.name.name,
                        i.piece.name,
                        self.placement(&i.at, &i.rotate)
                    );
                    self.stmt(indent, &t, i.span);
                }
                ModelStmt::Chain(c) => {
                    let mut t = format!(
                        "{} = chain {} x {}",
                        c.name.name,
                        c.piece.name,
                        self.num(&c.count)
                    );
                    if let Some((a, b)) = &c.along {
                        t += &format!(" along {} -> {}", a.name, b.name);
                    }
                    t += &self.placement(&c.at, &c.rotate);
                    self.stmt(indent, &t, c.span);
                }
                ModelStmt::Dock(d) => {
                    let t = format!(
                        "dock {} to {}",
                        Self::instance_site(&d.a),
                        Self::instance_site(&d.b)
                    );
                    self.stmt(indent, &t, d.span);
                }
                ModelStmt::If(b) => self.if_block(indent, b),
            }
        }
    }

    /// `if NAME {`, its statements, and `} else {` with the others when there are any.
    fn if_block(&mut self, indent: usize, b: &IfBlock) {
        let header = format!("if {}", b.cond.name);
        self.open(indent, &header, b.span.start, b.cond.span.end);
        self.model_stmts(indent + 1, &b.then);
        match (&b.otherwise, b.else_keyword) {
            (Some(otherwise), Some(keyword)) if self.src.is_some() => {
                // Comments between `}` and `else {` go inside the first block, where a
                // second pass finds them.
                let brace = self.next_token(keyword.end);
                self.leading(indent + 1, brace);
                self.line(indent, "} else {", b.then_close.start, brace + 1, false);
                self.trailing(brace + 1);
                self.block_start = true;
                self.model_stmts(indent + 1, otherwise);
            }
            (Some(otherwise), _) => {
                // A tree without its text (written by a tool): no comments to keep.
                self.line(indent, "} else {", 0, 0, true);
                self.block_start = true;
                self.model_stmts(indent + 1, otherwise);
            }
            (None, _) => {}
        }
        self.close(indent, b.span);
    }
}
