//! The compiler: syntax tree -> [`CompiledGrammar`]. This file drives the passes and compiles
//! the declarations (solver, site types, pieces); `state.rs` holds the compiler's state and
//! `limits.rs` its limits, which every pass imports instead of this file; `constants.rs` folds `let` constants,
//! `param` parameters (with their overrides) and every expression; `rules.rs` compiles stretch, merge and cut
//! rules, `assembly.rs` places the model, and `usage.rs` finds unused pieces and dead rules.

pub mod codes;

pub(crate) mod limits;
mod state;

mod assembly;
mod constants;
mod derive;
mod extends;
mod imports;
mod mesh_files;
mod meshes;

pub(crate) use constants::{constant_values, functions, is_function};
mod params;
mod pieces;
mod rules;
mod switches;
mod usage;

use std::collections::HashMap;

use glam::DVec2;

use crate::compiled::*;
use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::suggest::closest;
use crate::syntax::{self, Expr, Ident, Item, PieceStmt, Point, Span};

pub use extends::{MAX_EXTENDS_DEPTH, MAX_INHERITED};
pub use imports::{FsLoader, Loader, MAX_IMPORT_BYTES, MAX_IMPORTS, resolve as resolve_import};
pub use limits::{DOCK_TOLERANCE, MAX_COORDINATE, MAX_INSTANCES, MAX_MODEL_INSTANCES};
pub use meshes::{MAX_MESH_BYTES, MAX_MESH_TOTAL_BYTES, MAX_MESH_TRIANGLES, MAX_MESH_VERTICES};
use state::Compiler;
use state::{Constants, Inheritance, Meshes};

/// The result of a successful compilation: the grammar, and the warnings found on the way.
#[derive(Clone, Debug, PartialEq)]
pub struct Compiled {
    pub grammar: CompiledGrammar,
    /// The warnings, with the imported files they may point into (`warnings.sources`).
    pub warnings: Diagnostics,
}

impl Compiled {
    /// The files the grammar imported, directly or not (for a watcher, say).
    pub fn imported_files(&self) -> impl Iterator<Item = &str> {
        self.warnings.sources.files.iter().map(|f| f.path.as_str())
    }
}

/// How to compile a grammar: where its imported files and mesh assets are read from, and the
/// values of its parameters. `CompileOptions::default()` reads the file system and sets no
/// parameter.
#[derive(Clone)]
pub struct CompileOptions<'a> {
    /// Reads imported files and mesh assets ([`FsLoader`] by default).
    pub loader: &'a dyn Loader,
    /// Values for the grammar's parameters (`param NAME = ...`), by name, replacing their
    /// defaults; of two values for one name the last counts. A name that is not a parameter
    /// of the grammar is E070; a value outside the parameter's range, or not finite, E071;
    /// a value of another type (2.5 for an `int`, 1 for a `bool`), E073.
    pub params: Vec<(String, ParamValue)>,
}

impl Default for CompileOptions<'_> {
    fn default() -> Self {
        Self {
            loader: &FsLoader,
            params: Vec::new(),
        }
    }
}

impl<'a> CompileOptions<'a> {
    /// Options that read through `loader` and set no parameter.
    pub fn with_loader(loader: &'a dyn Loader) -> Self {
        Self {
            loader,
            params: Vec::new(),
        }
    }

    /// The same options, with parameter `name` set to `value`.
    pub fn param(mut self, name: impl Into<String>, value: impl Into<ParamValue>) -> Self {
        self.params.push((name.into(), value.into()));
        self
    }
}

impl std::fmt::Debug for CompileOptions<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompileOptions")
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

/// Compiles the text of a `.clay` file, the one entry point of the compiler.
///
/// `path` is recorded in the result, and its folder is where `import`ed files are resolved
/// from ([`resolve_import`]); `options` says how they and mesh assets are read (the loader
/// gets the resolved path; a language server can serve unsaved buffers this way) and sets the
/// grammar's parameters. `&CompileOptions::default()` reads the file system ([`FsLoader`]) and
/// sets no parameter. The compiled grammar lists every parameter with the value used
/// ([`CompiledGrammar::params`]). Bytes read from a file become text through
/// [`decode_utf8`](crate::decode_utf8) first.
pub fn compile(
    source: &str,
    path: &str,
    options: &CompileOptions,
) -> Result<Compiled, Diagnostics> {
    compile_tree(
        crate::parse::parse(source)?,
        source.len(),
        path,
        options.loader,
        &options.params,
    )
}

/// Compiles a parsed file whose text is `source_len` bytes long (the analysis layer parses
/// once, for its tree and the compiler), with the parameter values `params`.
pub(crate) fn compile_tree(
    file: syntax::File,
    source_len: usize,
    path: &str,
    loader: &dyn Loader,
    params: &[(String, ParamValue)],
) -> Result<Compiled, Diagnostics> {
    // Only a grammar with typed parameters (or imports, which may declare them) can have
    // switches: the others compile once, without a copy of their tree.
    let typed = file.items.iter().any(|i| match i {
        Item::Import(_) => true,
        Item::Param(p) => p.ty.is_some(),
        _ => false,
    });
    if !typed {
        return compile_once(file, source_len, path, loader, params);
    }
    let ok = compile_once(file.clone(), source_len, path, loader, params)?;
    let found = switches::other_value_errors(&ok.grammar.params, params, |values| {
        compile_once(file.clone(), source_len, path, loader, values).err()
    });
    if found.is_empty() {
        return Ok(ok);
    }
    let mut diags = ok.warnings;
    diags.extend(found);
    diags.sort();
    Err(diags)
}

/// One compilation with the parameter values `params`.
fn compile_once(
    file: syntax::File,
    source_len: usize,
    path: &str,
    loader: &dyn Loader,
    params: &[(String, ParamValue)],
) -> Result<Compiled, Diagnostics> {
    let span = file.span;
    let spliced = imports::splice(file, path, source_len, loader);
    if !spliced.diags.is_empty() {
        // A file that failed to load would only add "unknown" errors for what it declares.
        let mut diags = spliced.diags;
        diags.sort();
        diags.sources = spliced.sources;
        return Err(diags);
    }
    let mut file = syntax::File {
        items: spliced.items,
        span,
    };
    let mut c = Compiler::new(path);
    c.consts.overrides = params.to_vec();
    c.expand_extends(&mut file);
    c.meshes = meshes::load(
        &file,
        path,
        source_len,
        &spliced.sources,
        loader,
        &mut c.diags,
    );
    c.run(&file);
    c.drop_poisoned();
    let mut diags = c.diags;
    // A library's unused pieces and rules are not the importer's concern.
    diags.items.retain(|d| {
        d.primary.span.start <= source_len
            || !matches!(d.code, codes::UNUSED_PIECE | codes::DEAD_RULE)
    });
    diags.sort();
    diags.sources = spliced.sources;
    match c.grammar {
        Some(grammar) if !diags.has_errors() => Ok(Compiled {
            grammar,
            warnings: diags,
        }),
        _ => Err(diags),
    }
}

impl Compiler {
    fn new(path: &str) -> Self {
        Self {
            path: path.to_string(),
            diags: Diagnostics::new(),
            solver: SolverParams::default(),
            site_types: Vec::new(),
            site_type_index: HashMap::new(),
            site_type_spans: Vec::new(),
            pieces: Vec::new(),
            piece_spans: Vec::new(),
            piece_index: HashMap::new(),
            stretch_rules: Vec::new(),
            stretch_spans: Vec::new(),
            merge_rules: Vec::new(),
            merge_spans: Vec::new(),
            cut_rules: Vec::new(),
            cut_spans: Vec::new(),
            merge_first: HashMap::new(),
            cut_index: HashMap::new(),
            stretch_named: Vec::new(),
            dock_failed: false,
            inheritance: Inheritance::default(),
            grammar: None,
            consts: Constants::default(),
            meshes: Meshes::default(),
            suggestion_budget: limits::MAX_SUGGESTION_WORK,
        }
    }

    pub fn error(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    pub fn duplicate(&mut self, what: &str, ident: &Ident, first: Span) {
        self.diags.push(
            Diagnostic::error(
                codes::DUPLICATE,
                format!("{what} `{}` is defined twice", ident.name),
                ident.span,
                "defined again here",
            )
            .with_secondary(first, "first defined here")
            .with_hint(format!("rename one of them or remove the second {what}")),
        );
    }

    /// Reports an unknown name, suggesting the closest known one.
    pub fn unknown<'a>(
        &mut self,
        what: &str,
        ident: &Ident,
        known: impl IntoIterator<Item = &'a str>,
        context: Option<String>,
    ) {
        let known: Vec<&str> = known.into_iter().collect();
        let mut d = Diagnostic::error(
            codes::UNKNOWN,
            match &context {
                Some(ctx) => format!("unknown {what} `{}` {ctx}", ident.name),
                None => format!("unknown {what} `{}`", ident.name),
            },
            ident.span,
            format!("no {what} of this name"),
        );
        // bounded per compilation: 8,000 misspelt names among 8,000 took 13.8 s (issue 47);
        // past the budget an unknown name is reported without a suggestion
        let searched = self.suggestion_budget >= known.len();
        self.suggestion_budget = self.suggestion_budget.saturating_sub(known.len());
        if let Some(c) = searched
            .then(|| closest(&ident.name, known.iter().copied()))
            .flatten()
        {
            d = d.with_hint(format!("did you mean `{c}`?"));
        } else if known.is_empty() {
            d = d.with_hint(format!("no {what} is declared here"));
        } else if known.len() <= 8 {
            let list: Vec<String> = known.iter().map(|k| format!("`{k}`")).collect();
            d = d.with_hint(format!("known: {}", list.join(", ")));
        }
        self.diags.push(d);
    }

    /// A number that must lie in a range; reports and returns `None` otherwise.
    pub fn in_range(
        &mut self,
        n: &Expr,
        what: &str,
        ok: impl Fn(f64) -> bool,
        allowed: &str,
    ) -> Option<f64> {
        let value = self.eval(n)?;
        if ok(value) {
            Some(value)
        } else {
            self.diags.push(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    format!("{what} is out of range"),
                    n.span,
                    format!("must be {allowed}"),
                )
                .with_hint(format!(
                    "{what} must be {allowed}; see the table in docs/language.md"
                )),
            );
            None
        }
    }

    /// A whole number at least `min`.
    pub fn whole(&mut self, n: &Expr, what: &str, min: u64) -> Option<u64> {
        let v = self.eval(n)?;
        if v.fract() == 0.0 && v >= min as f64 && v <= u64::MAX as f64 / 2.0 {
            Some(v as u64)
        } else {
            self.diags.push(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    format!("{what} must be a whole number of at least {min}"),
                    n.span,
                    format!("expected a whole number >= {min}"),
                )
                .with_hint(format!(
                    "write {what} as a whole number, like `{}`",
                    min.max(2)
                )),
            );
            None
        }
    }

    /// A point whose coordinates are within [`MAX_COORDINATE`].
    pub fn point(&mut self, p: &Point) -> DVec2 {
        let (Some(x), Some(y)) = (self.eval(&p.x), self.eval(&p.y)) else {
            // Reported (or poisoned): NaN keeps later checks silent, as below.
            return DVec2::NAN;
        };
        for (n, v) in [(&p.x, x), (&p.y, y)] {
            if v.abs() > MAX_COORDINATE {
                self.diags.push(
                    Diagnostic::error(
                        codes::OUT_OF_RANGE,
                        "coordinate is out of range",
                        n.span,
                        "too far from the origin",
                    )
                    .with_hint(format!(
                        "coordinates are metres and must lie within +/-{MAX_COORDINATE:e}"
                    )),
                );
                // Not a number: every later geometric test on it is false, so the reported
                // E013 is not followed by a false "zero length" or "same place" (the grammar
                // is not produced with an error, so the NaN never leaves the compiler).
                return DVec2::NAN;
            }
        }
        DVec2::new(x, y)
    }

    pub fn site_type_index(&self, name: &str) -> Option<usize> {
        self.site_type_index.get(name).copied()
    }

    /// Resolves a piece name, reporting it when unknown.
    pub fn resolve_piece(&mut self, ident: &Ident) -> Option<usize> {
        match self.piece_index.get(&ident.name) {
            Some(&i) => Some(i),
            None => {
                let names: Vec<String> = self.pieces.iter().map(|p| p.name.clone()).collect();
                self.unknown("piece", ident, names.iter().map(String::as_str), None);
                None
            }
        }
    }

    /// Resolves a site of a piece, reporting it when unknown.
    pub fn resolve_site(&mut self, piece: usize, ident: &Ident) -> Option<usize> {
        let p = &self.pieces[piece];
        match p.sites.iter().position(|s| s.name == ident.name) {
            Some(i) => Some(i),
            // Declared, but with an error that was reported: one error per mistake.
            None if self
                .piece_spans
                .get(piece)
                .is_some_and(|s| s.poisoned || s.failed_sites.contains(&ident.name)) =>
            {
                None
            }
            None => {
                let names: Vec<String> = p.sites.iter().map(|s| s.name.clone()).collect();
                let ctx = Some(format!("on piece `{}`", p.name));
                self.unknown("site", ident, names.iter().map(String::as_str), ctx);
                None
            }
        }
    }

    fn run(&mut self, file: &syntax::File) {
        self.constants(&file.items);
        let mut solver_seen: Option<Span> = None;
        let mut model: Option<&syntax::ModelBlock> = None;
        for item in &file.items {
            match item {
                Item::Solver(s) => {
                    if let Some(first) = solver_seen {
                        let id = Ident {
                            name: "solver".into(),
                            span: s.keyword,
                        };
                        self.duplicate("block", &id, first);
                    } else {
                        solver_seen = Some(s.keyword);
                        self.solver_block(s);
                    }
                }
                Item::Model(m) => {
                    if let Some(first) = model {
                        let id = Ident {
                            name: "model".into(),
                            span: m.keyword,
                        };
                        self.duplicate("block", &id, first.keyword);
                    } else {
                        model = Some(m);
                    }
                }
                _ => {}
            }
        }
        let decls: Vec<&syntax::SiteTypeDecl> = file
            .items
            .iter()
            .filter_map(|i| {
                if let Item::SiteType(s) = i {
                    Some(s)
                } else {
                    None
                }
            })
            .collect();
        self.site_type_decls(&decls);
        for item in &file.items {
            if let Item::Piece(p) = item {
                self.piece_item(p);
            }
        }
        self.settle_children();
        self.rules(file);
        self.check_skinned(file);
        let usage = usage::Usage::find(self, file, model);
        let assembly = assembly::build(self, model);
        match model {
            Some(_) => usage.report(self, file),
            // Without a model every piece is unused: one warning says why, not one per piece.
            None => self.no_model(file),
        }
        // A declaration skipped for an error may hold the only use: warn only on clean files.
        if !self.diags.has_errors() {
            self.unused_constants();
        }
        let grammar = CompiledGrammar {
            format_version: FORMAT_VERSION,
            source: self.path.clone(),
            solver: self.solver,
            params: std::mem::take(&mut self.consts.params),
            site_types: std::mem::take(&mut self.site_types),
            pieces: std::mem::take(&mut self.pieces),
            stretch_rules: std::mem::take(&mut self.stretch_rules),
            merge_rules: std::mem::take(&mut self.merge_rules),
            cut_rules: std::mem::take(&mut self.cut_rules),
            assembly: AssemblyData::default(),
        };
        if self.diags.has_errors() {
            return;
        }
        let mut grammar = grammar;
        grammar.assembly = assembly;
        grammar.assembly.parts = grammar.parts(&grammar.assembly);
        if !grammar.all_finite() {
            // Guarded by MAX_COORDINATE; kept so that no NaN or infinity can ever reach output.
            self.error(Diagnostic::error(
                codes::OUT_OF_RANGE,
                "the compiled grammar has coordinates that are not finite",
                file.span,
                "somewhere in this file",
            ));
            return;
        }
        self.grammar = Some(grammar);
    }

    /// W005: the file declares nothing to sculpt.
    fn no_model(&mut self, file: &syntax::File) {
        let end = Span::new(file.span.end, file.span.end);
        let (message, label) = if file.items.is_empty() {
            (
                "the grammar is empty: there is nothing to sculpt",
                "the file ends here",
            )
        } else {
            (
                "the grammar has no `model` block: there is nothing to sculpt",
                "a `model { ... }` block would go here",
            )
        };
        self.diags.push(
            Diagnostic::warning(codes::NO_MODEL, message, end, label).with_hint(
                "add a model that places pieces, e.g. `model { wall = chain brick x 8 }` \
                 (docs/language.md, `model { ... }`)",
            ),
        );
    }

    fn solver_block(&mut self, s: &syntax::SolverBlock) {
        let mut seen: HashMap<&str, Span> = HashMap::new();
        for e in &s.entries {
            if let Some(&first) = seen.get(e.name.name.as_str()) {
                self.duplicate("solver parameter", &e.name, first);
                continue;
            }
            seen.insert(&e.name.name, e.name.span);
            let v = &e.value;
            let name = e.name.name.as_str();
            let Some(setting) = crate::settings::setting(name).filter(|s| s.in_grammar) else {
                let names: Vec<&str> = crate::settings::grammar_names().collect();
                self.unknown("solver parameter", &e.name, names, None);
                continue;
            };
            let what = format!("`{name}`");
            let range = setting.range;
            if let Some(x) = self.in_range(v, &what, |x| range.allows(x), &range.words()) {
                match name {
                    "hysteresis" => self.solver.hysteresis = x,
                    "norm" => self.solver.norm = x,
                    "irls_epsilon" => self.solver.irls_epsilon = x,
                    _ => self.solver.merge_distance = x,
                }
            }
        }
    }

    fn site_type_decls(&mut self, decls: &[&syntax::SiteTypeDecl]) {
        for d in decls {
            if let Some(i) = self.site_type_index(&d.name.name) {
                self.duplicate("site type", &d.name, self.site_type_spans[i]);
                continue;
            }
            (self.site_type_index).insert(d.name.name.clone(), self.site_types.len());
            self.site_types.push(SiteType {
                name: d.name.name.clone(),
                docks_with: Vec::new(),
            });
            self.site_type_spans.push(d.name.span);
        }
        // which types dock with which, as sorted sets: 60,000 types made a 3.6 GB matrix of
        // n x n flags (issue 47); the sets hold only the pairs the grammar writes
        let n = self.site_types.len();
        let mut dock = vec![std::collections::BTreeSet::new(); n];
        for d in decls {
            let Some(me) = self.site_type_index(&d.name.name) else {
                continue;
            };
            if self.site_type_spans[me] != d.name.span {
                continue; // a duplicate, already reported
            }
            if d.docks.is_empty() {
                dock[me].insert(me);
            }
            for other in &d.docks {
                match self.site_type_index(&other.name) {
                    Some(o) => {
                        dock[me].insert(o);
                        dock[o].insert(me);
                    }
                    None => {
                        // borrowed, not cloned per unknown name (`unknown` reads no type)
                        let types = std::mem::take(&mut self.site_types);
                        self.unknown("site type", other, types.iter().map(|t| &*t.name), None);
                        self.site_types = types;
                    }
                }
            }
        }
        for (i, set) in dock.into_iter().enumerate() {
            self.site_types[i].docks_with = set.into_iter().collect();
        }
    }

    /// Skinned geometry needs an axis (set by `axis` or by a stretch rule).
    fn check_skinned(&mut self, file: &syntax::File) {
        for item in &file.items {
            let Item::Piece(decl) = item else { continue };
            let Some(&pi) = self.piece_index.get(&decl.name.name) else {
                continue;
            };
            // A piece named by a stretch rule gets its axis from the rule; if the rule failed,
            // its own error says why, and "no axis" would only repeat it.
            if self.piece_spans[pi].name != decl.name.span
                || self.piece_spans[pi].poisoned
                || self.pieces[pi].axis.is_some()
                || self.stretch_named.get(pi).copied().unwrap_or(false)
            {
                continue;
            }
            // A derived state there already reports the missing axis (E055).
            let derived = |s: &PieceStmt| matches!(s, PieceStmt::State(st) if st.derive.is_some());
            if decl.stmts.iter().any(derived) {
                continue;
            }
            let mut geoms: Vec<&syntax::GeometryDecl> = Vec::new();
            for s in &decl.stmts {
                match s {
                    PieceStmt::Geometry(g) => geoms.push(g),
                    PieceStmt::State(st) => geoms.extend(st.geometry.iter()),
                    _ => {}
                }
            }
            for g in geoms {
                if let Some((syntax::BindingKw::Skinned, span)) = g.binding
                    && !self.inherited_skinned_is_quiet(decl, span)
                {
                    let mut d = Diagnostic::error(codes::NO_AXIS, format!("skinned geometry in piece `{}`, which has no axis", decl.name.name), span, "needs an axis to skin along")
                            .with_secondary(decl.name.span, "piece declared here")
                            .with_hint("add `axis FROM -> TO` to the piece, name it in a `stretch` rule, or make the geometry `rigid`");
                    if let Some(h) = self.inherited_skinned_hint(decl, span) {
                        d = d.with_hint(h);
                    }
                    self.error(d);
                    break;
                }
            }
        }
    }
}

impl CompiledGrammar {
    /// Whether every number in the grammar is finite.
    pub(crate) fn all_finite(&self) -> bool {
        let v = |p: &DVec2| p.is_finite();
        let proxies = |g: &[Proxy]| {
            g.iter().all(|p| match &p.shape {
                ProxyShape::Polygon { outer, holes } => {
                    outer.iter().all(v) && holes.iter().flatten().all(v)
                }
                ProxyShape::Polyline { points, width } => points.iter().all(v) && width.is_finite(),
                ProxyShape::Mesh {
                    points, heights, ..
                } => points.iter().all(v) && heights.iter().all(|h| h.is_finite()),
            })
        };
        self.pieces.iter().all(|p| {
            p.sites.iter().all(|s| v(&s.out))
                && p.states
                    .iter()
                    .all(|s| s.positions.iter().all(v) && proxies(&s.geometry))
        }) && self
            .stretch_rules
            .iter()
            .all(|r| r.part.states.iter().all(|s| s.positions.iter().all(v)))
            && self.assembly.positions.iter().all(v)
            && self
                .assembly
                .parts
                .iter()
                .all(|p| p.states.iter().all(|s| s.positions.iter().all(v)))
    }
}
