//! Analysis of one `.clay` text for editors: diagnostics, the symbol table, and the queries a
//! language server answers (definition, references, hover, completion, outline, rename,
//! semantic tokens, folding, fixes). No protocol types here: `clayc lsp` translates.
//!
//! Architecture Invariant: every query answers from byte offsets into the analysed text; the
//! conversion to protocol positions goes through [`LineIndex`] only.
//!
//! Resilience: a text with a syntax error still answers for the declarations before the error
//! (the longest prefix of whole top-level items that parses) and, given the analysis of the last
//! text that parsed ([`Analysis::with_previous`]), for the rest: outside the edited region the
//! old text is the new one, so the old symbols there keep their place (before the edit) or move
//! by the change in length (after it).
//!
//! Across files: the declarations of the imported files join the symbol table at their global
//! positions (past the end of the text, as in the compiler's source map), so definition,
//! hover, completion and references reach into them; [`Analysis::place`] maps such a span back
//! to its file, and [`Analysis::declared_at`] finds a declaration of another file's analysis
//! here (how `clayc lsp` gathers references and renames over every open file).

mod analysed;
mod complete;
pub mod follow;
mod imports;
mod symbols;
mod tokens;

use std::collections::HashMap;

pub use crate::line_index::{LineIndex, LinePos};
pub use analysed::{Analysis, KEYWORDS};
pub use complete::{Completion, CompletionKind};
pub use imports::Place;
pub use symbols::{Reference, Symbol, SymbolKind, Symbols};
pub use tokens::{SemanticToken, TokenKind};

use crate::compile::Loader;
use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::syntax::{File, Item, Span};
use imports::Imported;

/// Words that start a top-level item, where a parsed prefix may end.
const ITEM_STARTS: &[&str] = &[
    "let", "param", "solver", "site", "piece", "stretch", "merge", "cut", "model",
];

/// A node of the outline (document symbols).
#[derive(Clone, Debug, PartialEq)]
pub struct Outline {
    pub name: String,
    /// `None` for the `model` block itself.
    pub kind: Option<SymbolKind>,
    pub span: Span,
    /// The name (or keyword) to select.
    pub selection: Span,
    pub children: Vec<Outline>,
}

/// A fix for a diagnostic: text edits (span replaced by text).
#[derive(Clone, Debug, PartialEq)]
pub struct Fix {
    pub title: String,
    pub edits: Vec<(Span, String)>,
}

impl Analysis {
    /// Analyses `text` (compiled as the file `path`, imports read from the file system).
    pub fn new(text: &str, path: &str) -> Self {
        Self::with_loader(text, path, None, &crate::FsLoader)
    }

    /// Analyses `text`; when it does not parse to the end, the declarations after the error are
    /// taken from `previous` (the analysis of the last text that did), moved to where the
    /// unchanged tail of that text now lies.
    pub fn with_previous(text: &str, path: &str, previous: &Analysis) -> Self {
        Self::with_loader(text, path, Some(previous), &crate::FsLoader)
    }

    /// The general form: imported files come through `loader` (a server serves its open,
    /// unsaved buffers this way). While the text does not parse, its imports are those of
    /// `previous`.
    pub fn with_loader(
        text: &str,
        path: &str,
        previous: Option<&Analysis>,
        loader: &dyn Loader,
    ) -> Self {
        // One parse for the tree and the compiler (`compile` would parse again).
        let (tree, parsed_to, diagnostics, sources) = match crate::parse(text) {
            Ok(tree) => {
                let compiled =
                    crate::compile::compile_tree(tree.clone(), text.len(), path, loader, &[]);
                let diagnostics = match compiled {
                    Ok(c) => c.warnings,
                    Err(d) => d,
                };
                let sources = diagnostics.sources.clone();
                (Some(tree), text.len(), diagnostics, sources)
            }
            Err(d) => {
                let (tree, parsed_to) = parsed_prefix(text, &d);
                let sources = previous.map(|p| p.imported.sources.clone());
                (tree, parsed_to, d, sources.unwrap_or_default())
            }
        };
        let (imported, imported_items) = Imported::of(&sources, text.len());
        // The text's own items, then what its imports declare (a copy only when there are
        // imports: the common case reads the tree as it is).
        let joined;
        let all = match &tree {
            Some(t) if imported_items.is_empty() => t,
            _ => {
                joined = crate::syntax::File {
                    items: tree
                        .iter()
                        .flat_map(|t| t.items.iter().cloned())
                        .chain(imported_items)
                        .collect(),
                    span: Span::new(0, text.len()),
                };
                &joined
            }
        };
        let (symbols, values) = (Symbols::of(all), crate::compile::constant_values(all));
        let mut a = Self {
            index: LineIndex::new(text),
            path: crate::resolve_import("", path),
            imported,
            symbols,
            values,
            tree,
            parsed_to,
            diagnostics,
        };
        if let Some(previous) = previous.filter(|_| parsed_to < text.len()) {
            a.borrow_tail(previous);
        }
        a
    }

    fn borrow_tail(&mut self, previous: &Analysis) {
        let old = previous.text();
        let new = self.index.text();
        // The edit lies between the common head and the common tail of the two texts: a span
        // of the old text in its head keeps its offsets, one in its tail moves by the change
        // in length, one that touches the edit is dropped.
        let head = old
            .bytes()
            .zip(new.bytes())
            .take_while(|(a, b)| a == b)
            .count();
        let tail = old
            .bytes()
            .rev()
            .zip(new.bytes().rev())
            .take_while(|(a, b)| a == b)
            .count()
            .min(old.len().min(new.len()) - head);
        let (old_tail, new_tail) = (old.len() - tail, new.len() - tail);
        let from = self.parsed_to;
        let moved = |s: Span| {
            let s = if s.end <= head {
                s
            } else if s.start >= old_tail {
                Span::new(s.start - old_tail + new_tail, s.end - old_tail + new_tail)
            } else {
                return None;
            };
            (s.start >= from).then_some(s)
        };
        let mut map: HashMap<usize, usize> = HashMap::new();
        // Imported declarations (past the old text) are this analysis' own already.
        let own = |s: Span| s.start <= old.len();
        for (i, sym) in previous.symbols.symbols.iter().enumerate() {
            if !own(sym.span) {
                continue;
            }
            let (Some(span), Some(full)) = (moved(sym.span), moved(sym.full)) else {
                continue;
            };
            let container = sym.container.and_then(|c| map.get(&c).copied());
            map.insert(i, self.symbols.symbols.len());
            self.symbols.symbols.push(Symbol {
                span,
                full,
                container,
                ..sym.clone()
            });
        }
        for r in previous.symbols.references.iter().filter(|r| own(r.span)) {
            let Some(span) = moved(r.span) else { continue };
            let target = &previous.symbols.symbols[r.symbol];
            let symbol = map.get(&r.symbol).copied().or_else(|| {
                self.symbols
                    .symbols
                    .iter()
                    .position(|s| s.kind == target.kind && s.name == target.name)
            });
            if let Some(symbol) = symbol {
                self.symbols.references.push(Reference { span, symbol });
            }
        }
    }

    pub fn text(&self) -> &str {
        self.index.text()
    }

    /// Whether the whole text parses (then this analysis is the one to pass as `previous`
    /// to [`Analysis::with_previous`] while later texts do not).
    pub fn parses(&self) -> bool {
        self.parsed_to == self.text().len()
    }

    pub fn line_index(&self) -> &LineIndex {
        &self.index
    }

    pub fn diagnostics(&self) -> &Diagnostics {
        &self.diagnostics
    }

    pub fn symbols(&self) -> &Symbols {
        &self.symbols
    }

    /// The analysed file's path (`file` 0) or that of its imported file `file` (a
    /// [`Place`]'s), as the compiler resolved it.
    pub fn path(&self, file: usize) -> &str {
        match file.checked_sub(1) {
            None => &self.path,
            Some(k) => self.imported.sources.files.get(k).map_or("", |f| &f.path),
        }
    }

    /// The line index of file `file` (0: the analysed text).
    pub fn file_index(&self, file: usize) -> Option<&LineIndex> {
        match file.checked_sub(1) {
            None => Some(&self.index),
            Some(k) => self.imported.indexes.get(k),
        }
    }

    /// The files the text imports (directly or not), as [`Analysis::path`] names them.
    pub fn imported_paths(&self) -> impl Iterator<Item = &str> {
        self.imported.sources.files.iter().map(|f| f.path.as_str())
    }

    /// A span of this analysis (of the text, or past its end in an imported file) in its file.
    pub fn place(&self, span: Span) -> Place {
        let at = self.imported.sources.locate(self.text(), &self.path, span);
        Place {
            file: at.file,
            span: Span::new(at.start, at.end),
        }
    }

    /// The text of a span of this analysis, in whichever file it lies.
    pub(super) fn source(&self, span: Span) -> &str {
        let at = self.imported.sources.locate(self.text(), &self.path, span);
        &at.text[at.start..at.end]
    }

    /// The symbol whose name is declared at `span` of the file `path` (an analysis of another
    /// file names its declarations so: [`Analysis::path`] and [`Place::span`]).
    pub fn declared_at(&self, path: &str, span: Span) -> Option<usize> {
        let file = if path == self.path {
            0
        } else {
            1 + self.imported_paths().position(|p| p == path)?
        };
        let want = Place { file, span };
        self.symbols
            .symbols
            .iter()
            .position(|s| s.kind != SymbolKind::Rule && self.place(s.span) == want)
    }

    /// The symbol declared or used at `offset`.
    pub fn symbol_at(&self, offset: usize) -> Option<usize> {
        let inside = |s: Span| s.start <= offset && offset <= s.end;
        self.symbols
            .symbols
            .iter()
            .position(|s| s.kind != SymbolKind::Rule && inside(s.span))
            .or_else(|| {
                self.symbols
                    .references
                    .iter()
                    .find(|r| inside(r.span))
                    .map(|r| r.symbol)
            })
    }

    /// Where the name at `offset` is declared: past the end of the text when in an imported
    /// file ([`Analysis::place`] says which).
    pub fn definition(&self, offset: usize) -> Option<Span> {
        self.symbol_at(offset).map(|i| self.symbols.symbols[i].span)
    }

    /// Every use of the name at `offset` (and its declaration when asked), in the text and in
    /// its imported files, in order of position.
    pub fn references(&self, offset: usize, declaration: bool) -> Vec<Span> {
        match self.symbol_at(offset) {
            Some(i) => self.references_of(i, declaration),
            None => Vec::new(),
        }
    }

    /// Every use of symbol `i` (and its declaration when asked), in order of position.
    pub fn references_of(&self, i: usize, declaration: bool) -> Vec<Span> {
        let Some(sym) = self.symbols.symbols.get(i) else {
            return Vec::new();
        };
        let mut spans: Vec<Span> = self
            .symbols
            .references
            .iter()
            .filter(|r| r.symbol == i)
            .map(|r| r.span)
            .collect();
        if declaration {
            spans.push(sym.span);
        }
        spans.sort_by_key(|s| s.start);
        spans
    }

    /// Markdown describing the name at `offset`, and the span it describes.
    pub fn hover(&self, offset: usize) -> Option<(Span, String)> {
        let i = self.symbol_at(offset)?;
        let here = self
            .symbols
            .references
            .iter()
            .find(|r| r.symbol == i && r.span.start <= offset && offset <= r.span.end)
            .map_or(self.symbols.symbols[i].span, |r| r.span);
        Some((here, self.describe(i)))
    }

    fn first_line(&self, s: Span) -> &str {
        self.source(s)
            .lines()
            .next()
            .unwrap_or("")
            .trim_end_matches('{')
            .trim_end()
    }

    fn describe(&self, i: usize) -> String {
        let sym = &self.symbols.symbols[i];
        let mut out = format!("```clay\n{}\n```\n", self.first_line(sym.full));
        let file = self.place(sym.span).file;
        if file > 0 {
            out += &format!("\nin `{}`\n", self.path(file));
        }
        let container = sym.container.map(|c| self.symbols.symbols[c].name.as_str());
        match sym.kind {
            SymbolKind::Piece => out += &self.describe_piece(i),
            SymbolKind::Constant => {
                if let Some(v) = self.values.get(&sym.name) {
                    out += &format!("\n= `{}`\n", crate::format_number(*v));
                }
            }
            SymbolKind::Vertex | SymbolKind::Site | SymbolKind::State => {
                out += &format!(
                    "\n{} of piece `{}`\n",
                    sym.kind.word(),
                    container.unwrap_or("?")
                );
            }
            SymbolKind::Instance | SymbolKind::Chain => {
                out += &format!(
                    "\n{} of piece `{}`\n",
                    sym.kind.word(),
                    sym.piece.as_deref().unwrap_or("?")
                );
            }
            SymbolKind::SiteType | SymbolKind::Rule => {}
        }
        out
    }

    fn describe_piece(&self, piece: usize) -> String {
        let members = |kind: SymbolKind| -> Vec<&Symbol> {
            self.symbols
                .symbols
                .iter()
                .filter(|s| s.container == Some(piece) && s.kind == kind)
                .collect()
        };
        let names = |list: &[&Symbol]| -> String {
            list.iter()
                .map(|s| format!("`{}`", s.name))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let mut out = String::new();
        let vertices = members(SymbolKind::Vertex);
        out += &format!("\n**{} vertices**: {}\n", vertices.len(), names(&vertices));
        let sites = members(SymbolKind::Site);
        if !sites.is_empty() {
            out += "\n**sites**:\n";
            for s in sites {
                out += &format!(
                    "- `{}`\n",
                    self.first_line(s.full).trim_start_matches("site ")
                );
            }
        }
        let mut states = vec!["`base`".to_string()];
        states.extend(
            members(SymbolKind::State)
                .iter()
                .map(|s| format!("`{}`", s.name)),
        );
        out += &format!("\n**rest states**: {}\n", states.join(", "));
        let rules: Vec<&str> = self
            .symbols
            .symbols
            .iter()
            .filter(|s| s.kind == SymbolKind::Rule)
            .filter(|rule| {
                self.symbols.references.iter().any(|r| {
                    r.symbol == piece
                        && rule.full.start <= r.span.start
                        && r.span.end <= rule.full.end
                })
            })
            .map(|rule| self.first_line(rule.full))
            .collect();
        if !rules.is_empty() {
            out += "\n**rules**:\n";
            for r in rules {
                out += &format!("- `{r}`\n");
            }
        }
        out
    }

    /// The outline: top-level declarations with their members, the model with its instances.
    pub fn outline(&self) -> Vec<Outline> {
        let syms = &self.symbols.symbols;
        let node = |i: usize| Outline {
            name: syms[i].name.clone(),
            kind: Some(syms[i].kind),
            span: syms[i].full,
            selection: syms[i].span,
            children: Vec::new(),
        };
        let mut out = Vec::new();
        let own = |s: &Symbol| s.span.start <= self.text().len();
        for (i, s) in syms.iter().enumerate().filter(|(_, s)| own(s)) {
            match s.kind {
                SymbolKind::Vertex | SymbolKind::Site | SymbolKind::State => {}
                SymbolKind::Instance | SymbolKind::Chain => {}
                SymbolKind::Piece => {
                    let mut n = node(i);
                    n.children = (0..syms.len())
                        .filter(|&j| syms[j].container == Some(i))
                        .map(node)
                        .collect();
                    out.push(n);
                }
                _ => out.push(node(i)),
            }
        }
        if let Some(model) = self
            .tree
            .iter()
            .flat_map(|t| &t.items)
            .find_map(|i| match i {
                Item::Model(m) => Some(m),
                _ => None,
            })
        {
            out.push(Outline {
                name: "model".into(),
                kind: None,
                span: model.span,
                selection: model.keyword,
                children: (0..syms.len())
                    .filter(|&j| matches!(syms[j].kind, SymbolKind::Instance | SymbolKind::Chain))
                    .map(node)
                    .collect(),
            });
        }
        out.sort_by_key(|o| o.span.start);
        out
    }

    /// The edits that rename the name at `offset` to `new_name` everywhere (spans past the
    /// end of the text lie in imported files), or why not.
    pub fn rename(&self, offset: usize, new_name: &str) -> Result<Vec<(Span, String)>, String> {
        let i = self
            .symbol_at(offset)
            .ok_or_else(|| "there is no name to rename here".to_string())?;
        self.rename_symbol(i, new_name)
    }

    /// The edits that rename symbol `i` to `new_name`, or why not.
    pub fn rename_symbol(&self, i: usize, new_name: &str) -> Result<Vec<(Span, String)>, String> {
        let sym = self
            .symbols
            .symbols
            .get(i)
            .ok_or_else(|| "there is no such name".to_string())?;
        let valid = new_name
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && new_name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !valid {
            return Err(format!(
                "`{new_name}` is not a name: names are ASCII letters, digits and `_`, not starting with a digit"
            ));
        }
        if KEYWORDS.contains(&new_name) {
            return Err(format!("`{new_name}` is a keyword"));
        }
        let namespace = |k: SymbolKind| match k {
            SymbolKind::Instance | SymbolKind::Chain => SymbolKind::Instance,
            k => k,
        };
        let clash = self.symbols.symbols.iter().find(|s| {
            s.name == new_name
                && namespace(s.kind) == namespace(sym.kind)
                && s.container == sym.container
        });
        if let Some(other) = clash {
            let place = self.place(other.span);
            let line = self
                .file_index(place.file)
                .map_or(0, |x| x.position(place.span.start).line + 1);
            let file = if place.file > 0 {
                format!("`{}` ", self.path(place.file))
            } else {
                String::new()
            };
            return Err(format!(
                "{} `{new_name}` already exists ({file}line {line})",
                other.kind.word(),
            ));
        }
        if sym.kind == SymbolKind::Constant
            && (new_name == "pi" || crate::compile::is_function(new_name))
        {
            return Err(format!("`{new_name}` is built in"));
        }
        Ok(self
            .references_of(i, true)
            .into_iter()
            .map(|s| (s, new_name.to_string()))
            .collect())
    }

    /// The canonical text, or `None` when the text does not parse.
    pub fn format(&self) -> Option<String> {
        crate::format(self.text()).ok()
    }

    /// Edits that put the top-level declarations overlapping `range` in the canonical style
    /// (each replaced whole by its printed form; the text between declarations is left as it
    /// is), or `None` when the text does not parse.
    pub fn format_range(&self, range: Span) -> Option<Vec<(Span, String)>> {
        let ours = self.tree.as_ref().filter(|_| self.parses())?;
        let formatted = crate::format(self.text()).ok()?;
        // The printer keeps every item, in order: the nth item of its output is the nth here.
        let theirs = crate::parse(&formatted).ok()?;
        if theirs.items.len() != ours.items.len() {
            return None;
        }
        let overlaps = |s: Span| s.start <= range.end && range.start <= s.end;
        Some(
            ours.items
                .iter()
                .zip(&theirs.items)
                .map(|(a, b)| (a.span(), &formatted[b.span().start..b.span().end]))
                .filter(|(a, b)| overlaps(*a) && self.source(*a) != *b)
                .map(|(a, b)| (a, b.to_string()))
                .collect(),
        )
    }

    /// Fixes offered for a diagnostic of this text.
    pub fn fixes(&self, d: &Diagnostic) -> Vec<Fix> {
        let mut fixes = Vec::new();
        for hint in &d.hints {
            if let Some(word) = between(hint, "did you mean `", "`?") {
                fixes.push(Fix {
                    title: format!("replace with `{word}`"),
                    edits: vec![(d.primary.span, word.to_string())],
                });
            }
            if let Some(fix) =
                between(hint, "declare `site type ", "`").and_then(|decl| self.allow_docking(decl))
            {
                fixes.push(fix);
            }
        }
        fixes
    }

    /// `declare site type A docks B`: extend A's declaration so it also docks with B.
    fn allow_docking(&self, decl: &str) -> Option<Fix> {
        let (a, b) = decl.split_once(" docks ")?;
        let tree = self.tree.as_ref()?;
        let t = tree.items.iter().find_map(|i| match i {
            Item::SiteType(t) if t.name.name == a => Some(t),
            _ => None,
        })?;
        let end = Span::new(t.span.end, t.span.end);
        let text = if t.docks.is_empty() {
            // Without `docks` the type docks with itself: keep that.
            format!(" docks {a}, {b}")
        } else {
            format!(", {b}")
        };
        Some(Fix {
            title: format!("let `{a}` dock with `{b}`"),
            edits: vec![(end, text)],
        })
    }

    pub fn completions(&self, offset: usize) -> Vec<Completion> {
        complete::at(self, offset)
    }

    pub fn semantic_tokens(&self) -> Vec<SemanticToken> {
        tokens::semantic(self)
    }

    /// Ranges worth folding: multi-line blocks and block comments.
    pub fn folding_ranges(&self) -> Vec<Span> {
        tokens::folding(self)
    }
}

/// The text between `open` and the next `close` in `s`.
fn between<'a>(s: &'a str, open: &str, close: &str) -> Option<&'a str> {
    let start = s.find(open)? + open.len();
    let len = s[start..].find(close)?;
    Some(&s[start..start + len])
}

/// The tree of the longest prefix of whole top-level items before the first syntax error.
fn parsed_prefix(text: &str, diags: &Diagnostics) -> (Option<File>, usize) {
    let error = diags
        .iter()
        .map(|d| d.primary.span.start)
        .min()
        .unwrap_or(0);
    let mut cuts = vec![0];
    cuts.extend(
        text.match_indices('\n')
            .map(|(i, _)| i + 1)
            .filter(|&i| i <= error)
            .filter(|&i| {
                let rest = &text[i..];
                ITEM_STARTS.iter().any(|w| {
                    rest.starts_with(w)
                        && !rest[w.len()..]
                            .starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_')
                })
            }),
    );
    // The latest cut usually parses; a few earlier ones cover an error inside an item that
    // starts at column 0 with its body's lines.
    for &cut in cuts.iter().rev().take(4) {
        if let Ok(tree) = crate::parse(&text[..cut]) {
            return (Some(tree), cut);
        }
    }
    (None, 0)
}
