//! The architecture invariants of `docs/architecture.md` that a reading of the source can
//! check: no import cycle between the modules of a crate (children naming their parents
//! counted, over an import graph parsed whole with `syn`, the `clayc` binary included), the library's
//! top-level modules import one another only along the documented table of allowed edges,
//! the editor uses only the library's surfaces (the session, rendering, authoring, and the
//! solver's settings and report types) and its two modes import neither each other nor the app
//! that holds them, rules never import sessions or scripts, protocol types
//! stay in the language server, a solver frame changes no part, instance or connection, and
//! the libraries print nothing, every file is read through the one bounded reader, and no
//! `use` imports a whole crate root, no two public types share a name, and the library's top
//! level holds no function or constant only tests use. The editor's library and the Python
//! module are graphs too.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

fn cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for m in g.get(n).into_iter().flatten() {
            match state.get(m.as_str()).copied().unwrap_or(0) {
                1 => {
                    let at = stack.iter().position(|s| s == m).unwrap();
                    return Some(stack[at..].to_vec());
                }
                0 => {
                    if let Some(c) = visit(m, g, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in g.keys() {
        if state.get(n.as_str()).copied().unwrap_or(0) == 0 {
            let mut stack = Vec::new();
            if let Some(c) = visit(n, g, &mut state, &mut stack) {
                return Some(c);
            }
        }
    }
    None
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

// The import graph. Every file of a crate is parsed whole with `syn` (test modules included),
// starting at the crate's root file and following its `mod` declarations; every `use` tree and
// every path (in code, types, patterns and macro bodies) that begins with `crate::`, `super::`,
// `self::`, a child module's name, or (in the `clayc` binary) `clay::` is resolved to the module it
// names. A node is a file's module (`rules::cut`); an inline module (`mod tests { .. }`) counts
// for its file. Paths through the crate root's re-exports (`crate::parse(..)` in clay-dsl)
// count for the module the root re-exports them from.

/// One crate's modules, read whole.
struct Crate {
    /// Every module path (file or inline) -> the file module it counts for (the root is "").
    node_of: BTreeMap<String, String>,
    /// Each file module, its file and its syntax tree.
    files: Vec<(String, PathBuf, syn::File)>,
    /// The root's re-exports: name -> the path it re-exports (`parse` -> `parse::parse`).
    root_uses: BTreeMap<String, Vec<String>>,
}

/// One import: a file module names another module at `file:line`.
#[derive(Clone, Debug)]
struct Import {
    from: String,
    to: String,
    file: PathBuf,
    line: usize,
}

/// A file as the failure messages show it: from the repository's root.
fn shown(file: &Path) -> String {
    file.strip_prefix(root())
        .unwrap_or(file)
        .display()
        .to_string()
}

fn join(module: &str, name: &str) -> String {
    if module.is_empty() {
        name.to_string()
    } else {
        format!("{module}::{name}")
    }
}

fn parent(module: &str) -> Option<String> {
    if module.is_empty() {
        return None;
    }
    Some(module.rsplit_once("::").map_or("", |(p, _)| p).to_string())
}

/// The leaves of a `use` tree as paths (`use a::{b, c::*}` -> `a::b`, `a::c`), each with the
/// name it binds (none for a glob) and its line.
fn use_leaves(tree: &syn::UseTree, prefix: &mut Vec<String>, out: &mut Vec<UseLeaf>) {
    let line = |i: &syn::Ident| i.span().start().line;
    match tree {
        syn::UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            use_leaves(&p.tree, prefix, out);
            prefix.pop();
        }
        syn::UseTree::Name(n) => {
            let mut path = prefix.clone();
            path.push(n.ident.to_string());
            // `use a::b::{self}` binds `b`.
            let bound = match (n.ident == "self", prefix.last()) {
                (true, Some(last)) => last.clone(),
                _ => n.ident.to_string(),
            };
            out.push((path, Some(bound), line(&n.ident)));
        }
        syn::UseTree::Rename(r) => {
            let mut path = prefix.clone();
            path.push(r.ident.to_string());
            out.push((path, Some(r.rename.to_string()), line(&r.ident)));
        }
        syn::UseTree::Glob(g) => out.push((prefix.clone(), None, g.star_token.span.start().line)),
        syn::UseTree::Group(g) => {
            for t in &g.items {
                use_leaves(t, prefix, out);
            }
        }
    }
}

/// A `use` leaf: its path, the name it binds (none for a glob) and its line.
type UseLeaf = (Vec<String>, Option<String>, usize);

impl Crate {
    /// The crate whose root file is `root_file`, every module it declares read and parsed.
    fn read(root_file: &Path) -> Crate {
        let mut krate = Crate {
            node_of: BTreeMap::new(),
            files: Vec::new(),
            root_uses: BTreeMap::new(),
        };
        krate.load(root_file, "");
        let root = &krate.files.iter().find(|f| f.0.is_empty()).unwrap().2;
        for item in &root.items {
            if let syn::Item::Use(u) = item {
                let mut leaves = Vec::new();
                use_leaves(&u.tree, &mut Vec::new(), &mut leaves);
                for (path, bound, _) in leaves {
                    if let Some(bound) = bound {
                        krate.root_uses.insert(bound, path);
                    }
                }
            }
        }
        krate
    }

    fn load(&mut self, file: &Path, module: &str) {
        let text =
            std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let tree = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        self.node_of.insert(module.to_string(), module.to_string());
        let name = file.file_name().unwrap().to_string_lossy();
        let dir = if ["mod.rs", "lib.rs", "main.rs"].contains(&name.as_ref()) {
            file.parent().unwrap().to_path_buf()
        } else {
            file.with_extension("")
        };
        self.declare(&tree.items, module, &dir, module);
        self.files
            .push((module.to_string(), file.to_path_buf(), tree));
    }

    /// Follows the `mod` declarations among `items` (of `module`, whose child files are in
    /// `dir`); inline modules count for the file module `node`.
    fn declare(&mut self, items: &[syn::Item], module: &str, dir: &Path, node: &str) {
        for item in items {
            let syn::Item::Mod(m) = item else { continue };
            assert!(
                !m.attrs.iter().any(|a| a.path().is_ident("path")),
                "{module}: `#[path]` on `mod {}` is not followed by this test",
                m.ident
            );
            let name = m.ident.to_string();
            let path = join(module, &name);
            match &m.content {
                Some((_, inner)) => {
                    self.node_of.insert(path.clone(), node.to_string());
                    self.declare(inner, &path, &dir.join(&name), node);
                }
                None => {
                    let flat = dir.join(format!("{name}.rs"));
                    let file = if flat.exists() {
                        flat
                    } else {
                        dir.join(&name).join("mod.rs")
                    };
                    self.load(&file, &path);
                }
            }
        }
    }

    /// The file module a path names, or `None` for a path outside the crate. `current` is the
    /// module the path is written in; `whole`: the last name may be a module (a `use`), else it
    /// is a type's, value's or macro's own name (which may still be one the root re-exports).
    fn resolve(&self, current: &str, segments: &[String], whole: bool) -> Option<String> {
        self.resolve_hops(current, segments, whole, 0)
    }

    fn resolve_hops(
        &self,
        current: &str,
        segments: &[String],
        whole: bool,
        hops: usize,
    ) -> Option<String> {
        let first = segments.first()?;
        let (mut at, rest) = match first.as_str() {
            "crate" => (String::new(), &segments[1..]),
            "self" => (current.to_string(), &segments[1..]),
            "super" => {
                let mut at = current.to_string();
                let mut k = 0;
                while segments.get(k).is_some_and(|s| s == "super") {
                    at = parent(&at)?;
                    k += 1;
                }
                (at, &segments[k..])
            }
            name if self.node_of.contains_key(&join(current, name)) => {
                (current.to_string(), segments)
            }
            _ => return None,
        };
        for (k, s) in rest.iter().enumerate() {
            let item = !whole && k + 1 == rest.len();
            let next = join(&at, s);
            if s == "self" {
                continue;
            } else if !item && self.node_of.contains_key(&next) {
                at = next;
            } else if at.is_empty()
                && hops < 8
                && let Some(target) = self.root_uses.get(s)
            {
                // Through the root's re-export to where the name lives.
                let mut path = target.clone();
                path.extend(rest[k + 1..].iter().cloned());
                return self.resolve_hops("", &path, whole, hops + 1);
            } else {
                break;
            }
        }
        self.node(&at)
    }

    /// The file module that `module` counts for (a module inside a function body, which
    /// `declare` does not list, counts for the nearest listed one around it).
    fn node(&self, module: &str) -> Option<String> {
        let mut at = module.to_string();
        loop {
            if let Some(node) = self.node_of.get(&at) {
                return Some(node.clone());
            }
            at = parent(&at)?;
        }
    }
}

/// Reads one file's imports.
struct Reader<'a> {
    krate: &'a Crate,
    /// The library, for the binary's `clay::` paths.
    library: Option<&'a Crate>,
    /// The module the code being read is in (an inline module's path inside its file).
    current: String,
    node: String,
    file: PathBuf,
    out: Vec<Import>,
}

impl Reader<'_> {
    fn import(&mut self, segments: &[String], whole: bool, line: usize) {
        let to = match (segments.first().map(String::as_str), self.library) {
            (Some("clay"), Some(library)) => {
                let mut path = vec!["crate".to_string()];
                path.extend(segments[1..].iter().cloned());
                library.resolve("", &path, whole).map(|m| join("clay", &m))
            }
            _ => self.krate.resolve(&self.current, segments, whole),
        };
        if let Some(to) = to
            && to != self.node
        {
            self.out.push(Import {
                from: self.node.clone(),
                to,
                file: self.file.clone(),
                line,
            });
        }
    }
}

impl<'ast> syn::visit::Visit<'ast> for Reader<'_> {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if let Some((_, items)) = &m.content {
            let inner = join(&self.current, &m.ident.to_string());
            let outer = std::mem::replace(&mut self.current, inner);
            for item in items {
                self.visit_item(item);
            }
            self.current = outer;
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        if u.leading_colon.is_some() {
            return;
        }
        let mut leaves = Vec::new();
        use_leaves(&u.tree, &mut Vec::new(), &mut leaves);
        for (path, _, line) in leaves {
            self.import(&path, true, line);
        }
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        if p.leading_colon.is_none() && p.segments.len() >= 2 {
            let segments: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
            let line = p.segments[0].ident.span().start().line;
            self.import(&segments, false, line);
        }
        syn::visit::visit_path(self, p);
    }

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        syn::visit::visit_macro(self, m);
        // Macro bodies are tokens: every `a::b::c` run in them is read as a path.
        let mut paths = Vec::new();
        token_paths(m.tokens.clone(), &mut paths);
        for (segments, line) in paths {
            if segments.len() >= 2 {
                self.import(&segments, false, line);
            }
        }
    }
}

/// The `a::b::c` runs among `tokens` (groups searched too), each with its line.
fn token_paths(tokens: proc_macro2::TokenStream, out: &mut Vec<(Vec<String>, usize)>) {
    use proc_macro2::TokenTree;
    let tokens: Vec<TokenTree> = tokens.into_iter().collect();
    let mut i = 0;
    while i < tokens.len() {
        match &tokens[i] {
            TokenTree::Group(g) => {
                token_paths(g.stream(), out);
                i += 1;
            }
            TokenTree::Ident(first) => {
                let preceded_by_colons = i >= 2
                    && matches!((&tokens[i - 2], &tokens[i - 1]),
                        (TokenTree::Punct(a), TokenTree::Punct(b)) if a.as_char() == ':' && b.as_char() == ':');
                let mut segments = vec![first.to_string()];
                let mut j = i + 1;
                while let (
                    Some(TokenTree::Punct(a)),
                    Some(TokenTree::Punct(b)),
                    Some(TokenTree::Ident(next)),
                ) = (tokens.get(j), tokens.get(j + 1), tokens.get(j + 2))
                {
                    if a.as_char() != ':' || b.as_char() != ':' {
                        break;
                    }
                    segments.push(next.to_string());
                    j += 3;
                }
                if !preceded_by_colons {
                    out.push((segments, first.span().start().line));
                }
                i = j;
            }
            TokenTree::Punct(_) | TokenTree::Literal(_) => i += 1,
        }
    }
}

/// Every import of a crate, file by file (`library`: the crate the binary's `clay::` names).
fn imports(krate: &Crate, library: Option<&Crate>) -> Vec<Import> {
    let mut out = Vec::new();
    for (module, file, tree) in &krate.files {
        let mut reader = Reader {
            krate,
            library,
            current: module.clone(),
            node: module.clone(),
            file: file.clone(),
            out: Vec::new(),
        };
        syn::visit::Visit::visit_file(&mut reader, tree);
        out.extend(reader.out);
    }
    out
}

/// The library, the `clayc` binary (its own crate in `cli/`, rooted at its `main.rs`; its
/// `clay::` imports name `clay::X` nodes), clay-dsl, the editor's library and the Python
/// module, each with its imports (issue 47: a cycle inside the editor went unseen).
fn crates() -> Vec<(&'static str, Crate, Vec<Import>)> {
    let library = Crate::read(&root().join("src/lib.rs"));
    let binary = Crate::read(&root().join("cli/src/main.rs"));
    let dsl = Crate::read(&root().join("dsl/src/lib.rs"));
    let lib_imports = imports(&library, None);
    let bin_imports = imports(&binary, Some(&library));
    let dsl_imports = imports(&dsl, None);
    let editor = Crate::read(&root().join("editor/src/lib.rs"));
    let editor_imports = imports(&editor, None);
    let python = Crate::read(&root().join("python/src/lib.rs"));
    let python_imports = imports(&python, None);
    vec![
        ("src", library, lib_imports),
        ("cli/src", binary, bin_imports),
        ("dsl/src", dsl, dsl_imports),
        ("editor/src", editor, editor_imports),
        ("python/src", python, python_imports),
    ]
}

/// Module -> the modules it imports, every file module a node (edges to the crate root, a
/// list of `mod` and `pub use`, left out).
fn graph_of(krate: &Crate, imports: &[Import]) -> BTreeMap<String, BTreeSet<String>> {
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (m, _, _) in &krate.files {
        g.entry(m.clone()).or_default();
    }
    for i in imports {
        if !i.to.is_empty() {
            g.entry(i.from.clone()).or_default().insert(i.to.clone());
        }
    }
    g
}

/// The file-level import graph of the library (children naming their parents included).
fn graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let krate = Crate::read(&src.join("lib.rs"));
    let imports = imports(&krate, None);
    graph_of(&krate, &imports)
}

/// `rules::cut` -> `rules`; `clay::local` -> `clay::solver`. The test helpers behind the
/// feature `testing` count one level down (`testing::gallery`): they
/// were top-level modules before `testing` gathered them, and they import different things.
fn top(m: &str) -> String {
    let mut parts = m.split("::");
    let first = parts.next().unwrap_or("");
    if first == "clay" {
        join("clay", parts.next().unwrap_or(""))
    } else if first == "testing" {
        parts
            .next()
            .map_or(first.to_string(), |child| join(first, child))
    } else {
        first.to_string()
    }
}

/// Edges between the library's top-level modules that the code has and means to have. An
/// edge outside this table fails `the_library_imports_only_along_the_allowed_edges`; the same
/// table is in docs/architecture.md ("Architecture Invariant: the library's modules import
/// only along these edges"), and the two are kept equal by a test.
const ALLOWED: &[(&str, &[&str])] = &[
    ("assembly", &["fit"]),
    ("authoring", &["plane"]),
    ("export", &["files", "fit", "plane", "render"]),
    ("figure", &[]),
    ("files", &[]),
    ("fit", &[]),
    ("plane", &[]),
    ("render", &["fit", "plane", "solver"]),
    ("rules", &["assembly", "figure", "fit", "plane", "solver"]),
    ("script", &["assembly"]),
    (
        "session",
        &[
            "assembly", "figure", "files", "rules", "script", "solver", "summary",
        ],
    ),
    // `synthetic`: only the tests of `solver/chunks.rs`, which build a city.
    ("solver", &["assembly", "fit", "synthetic"]),
    ("summary", &["assembly", "figure", "rules", "solver"]),
    // `testing`: the re-exports of the names only tests and benches use.
    (
        "testing",
        &[
            "assembly", "export", "plane", "render", "rules", "session", "solver", "summary",
        ],
    ),
    (
        "testing::gallery",
        &[
            "assembly", "export", "render", "script", "session", "solver",
        ],
    ),
    ("synthetic", &[]),
];

#[test]
fn no_module_imports_one_that_imports_it_back() {
    for (name, krate, imports) in crates() {
        let g = graph_of(&krate, &imports);
        // every file of the crate is a module of the graph (the editor's `main.rs` is its
        // binary's root, not the library's)
        let mut files = Vec::new();
        rust_files(&root().join(name), &mut files);
        files.retain(|f| !(name == "editor/src" && f.ends_with("main.rs")));
        assert!(
            g.len() >= files.len() && files.len() >= 5,
            "{name}: {} modules read of {} files",
            g.len(),
            files.len()
        );
        // Every module, children naming their parents counted: what siblings share lives in a
        // sibling (a `state.rs`, `drawing.rs`, `analysed.rs`, `document.rs`), never the parent.
        if let Some(c) = cycle(&g) {
            let at: Vec<String> = c
                .iter()
                .zip(c.iter().cycle().skip(1))
                .filter_map(|(a, b)| imports.iter().find(|i| &i.from == a && &i.to == b))
                .map(|i| format!("{}:{}", shown(&i.file), i.line))
                .collect();
            panic!(
                "{name}: an import cycle: {} (imports at {})",
                c.join(" -> "),
                at.join(", ")
            );
        }
        // The same between the crate's top-level modules (`rules::cut` counts as `rules`).
        let mut tops: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (m, to) in &g {
            let entry = tops.entry(top(m)).or_default();
            entry.extend(to.iter().map(|t| top(t)).filter(|t| *t != top(m)));
        }
        if let Some(c) = cycle(&tops) {
            panic!(
                "{name}: an import cycle between top-level modules: {}",
                c.join(" -> ")
            );
        }
    }
}

#[test]
fn the_library_imports_only_along_the_allowed_edges() {
    let krate = Crate::read(&root().join("src/lib.rs"));
    let imports = imports(&krate, None);
    let allowed: BTreeMap<&str, &[&str]> = ALLOWED.iter().copied().collect();
    let tops: BTreeSet<String> = krate.files.iter().map(|f| top(&f.0)).collect();
    for t in tops.iter().filter(|t| !t.is_empty()) {
        assert!(
            allowed.contains_key(t.as_str()),
            "`{t}` has no row in the table of allowed imports: add it to the table in \
             docs/architecture.md and here"
        );
    }
    let mut used = BTreeSet::new();
    for i in &imports {
        let (from, to) = (top(&i.from), top(&i.to));
        if from.is_empty() || to.is_empty() || from == to {
            continue;
        }
        assert!(
            allowed
                .get(from.as_str())
                .is_some_and(|a| a.contains(&to.as_str())),
            "{}:{}: `{}` imports `{}`, an edge between top-level modules (`{from}` -> `{to}`) \
             outside the table of allowed imports; add it to the table in docs/architecture.md \
             and here if it is meant",
            shown(&i.file),
            i.line,
            i.from,
            i.to
        );
        used.insert((from, to));
    }
    for (from, to) in ALLOWED
        .iter()
        .flat_map(|(f, ts)| ts.iter().map(move |t| (*f, *t)))
    {
        assert!(
            used.contains(&(from.to_string(), to.to_string())),
            "`{from}` no longer imports `{to}`: remove the edge from the table in \
             docs/architecture.md and here"
        );
    }
}

/// The table of allowed imports in docs/architecture.md, row by row.
fn documented_edges() -> Vec<(String, Vec<String>)> {
    let text = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let start = text
        .find("the library's top-level modules import one another only along")
        .expect("docs/architecture.md states the allowed imports");
    let ticked = |cell: &str| -> Vec<String> {
        cell.split('`')
            .skip(1)
            .step_by(2)
            .map(str::to_string)
            .collect()
    };
    text[start..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').collect();
            let from = ticked(cells.get(1)?).pop()?;
            Some((from, ticked(cells.get(2)?)))
        })
        .collect()
}

#[test]
fn the_allowed_imports_are_the_documented_ones() {
    let here: Vec<(String, Vec<String>)> = ALLOWED
        .iter()
        .map(|(f, t)| (f.to_string(), t.iter().map(|s| s.to_string()).collect()))
        .collect();
    assert_eq!(
        documented_edges(),
        here,
        "the table in docs/architecture.md and ALLOWED in tests/architecture.rs differ"
    );
}

/// The graph builder on a crate made for it: a `use` in a test module, a path in a macro, a
/// path through the root's re-export and a child naming its parent's item each make an edge,
/// and the cycle is found with its lines.
#[test]
fn the_import_graph_sees_test_modules_macros_re_exports_and_parents() {
    let dir = std::env::temp_dir().join(format!("clay-architecture-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("a")).unwrap();
    let files = [
        ("lib.rs", "mod a;\nmod b;\nmod c;\npub use c::helper;\n"),
        (
            "a/mod.rs",
            "mod child;\npub struct Shared;\nfn f() { child::g(); }\n",
        ),
        ("a/child.rs", "use super::Shared;\npub fn g() {}\n"),
        (
            "b.rs",
            "pub fn f() {}\n#[cfg(test)]\nmod tests {\n    use crate::c::h;\n}\n",
        ),
        (
            "c.rs",
            "pub fn helper() {}\npub fn h() { assert!(crate::b::f() == ()); }\n",
        ),
    ];
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let krate = Crate::read(&dir.join("lib.rs"));
    let imports = imports(&krate, None);
    let g = graph_of(&krate, &imports);
    std::fs::remove_dir_all(&dir).unwrap();
    let edges: Vec<(&str, &str)> = g
        .iter()
        .flat_map(|(f, ts)| ts.iter().map(move |t| (f.as_str(), t.as_str())))
        .collect();
    assert_eq!(
        edges,
        [
            ("", "c"),
            ("a", "a::child"),
            ("a::child", "a"),
            ("b", "c"),
            ("c", "b"),
        ]
    );
    let child = imports.iter().find(|i| i.from == "a::child").unwrap();
    assert_eq!(child.line, 1);
    assert!(cycle(&g).is_some());
}

#[test]
fn rules_know_nothing_of_sessions_and_scripts() {
    let g = graph(&root().join("src"));
    for (m, to) in &g {
        if m == "rules" || m.starts_with("rules::") || m == "solver" || m.starts_with("solver::") {
            for t in to {
                assert!(
                    ![
                        "session",
                        "script",
                        "summary",
                        "testing",
                        "testing::gallery"
                    ]
                    .contains(&t.as_str()),
                    "{m} imports {t}"
                );
            }
        }
    }
}

/// Architecture Invariant: the editor is laid out by mode. A mode (`sculpt`, `author`) imports
/// neither the other mode nor the app that holds both; what both modes use (`camera`,
/// `compile`, `diagnostics`, ...) imports no mode and not the app.
#[test]
fn the_editors_modes_import_neither_each_other_nor_the_app() {
    let editor = Crate::read(&root().join("editor/src/lib.rs"));
    let imports = imports(&editor, None);
    let modes = ["sculpt", "author"];
    let mut seen = BTreeSet::new();
    for i in &imports {
        let (from, to) = (top(&i.from), top(&i.to));
        seen.insert(from.clone());
        if from.is_empty() || to.is_empty() || from == to || from == "app" {
            continue;
        }
        assert!(
            to != "app" && !modes.contains(&to.as_str()),
            "{}:{}: `{}` imports `{}`: {} imports `{to}` (docs/architecture.md, \
             `clay-editor`: the modes import neither each other nor the app)",
            shown(&i.file),
            i.line,
            i.from,
            i.to,
            if modes.contains(&from.as_str()) {
                format!("the mode `{from}`")
            } else {
                format!("`{from}`, which both modes share,")
            }
        );
    }
    for m in modes {
        assert!(seen.contains(m), "editor/src has no mode `{m}`: {seen:?}");
    }
}

/// Where each name of `clay`'s flat surface comes from: `pub use solver::{Solver, ..}` in
/// `src/lib.rs` maps `Solver` to `solver`; a name re-exported from a namespace (`authoring`,
/// `session_file`, `testing`) maps to that namespace.
fn surface_homes() -> BTreeMap<String, String> {
    let text = std::fs::read_to_string(root().join("src/lib.rs")).unwrap();
    let file = syn::parse_file(&text).unwrap();
    let mut homes = BTreeMap::new();
    for item in &file.items {
        match item {
            syn::Item::Use(u) if matches!(u.vis, syn::Visibility::Public(_)) => {
                let mut leaves = Vec::new();
                use_leaves(&u.tree, &mut Vec::new(), &mut leaves);
                for (path, bound, _) in leaves {
                    if let (Some(home), Some(name)) = (path.first(), bound) {
                        homes.insert(name, home.clone());
                    }
                }
            }
            syn::Item::Mod(m) if matches!(m.vis, syn::Visibility::Public(_)) => {
                homes.insert(m.ident.to_string(), m.ident.to_string());
            }
            _ => {}
        }
    }
    homes
}

/// Every name a file takes from `clay` (`use clay::{A, b::C}` gives `A` and `b`; a path
/// `clay::A::new` gives `A`), with its line.
fn clay_names(file: &syn::File) -> Vec<(String, usize)> {
    struct Names(Vec<(String, usize)>);
    impl<'ast> syn::visit::Visit<'ast> for Names {
        fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
            let mut leaves = Vec::new();
            use_leaves(&u.tree, &mut Vec::new(), &mut leaves);
            for (path, _, line) in leaves {
                if path.len() >= 2 && path[0] == "clay" {
                    self.0.push((path[1].clone(), line));
                }
            }
        }
        fn visit_path(&mut self, p: &'ast syn::Path) {
            let segments: Vec<&syn::Ident> = p.segments.iter().map(|s| &s.ident).collect();
            if segments.len() >= 2 && segments[0] == "clay" {
                let line = segments[1].span().start().line;
                self.0.push((segments[1].to_string(), line));
            }
            syn::visit::visit_path(self, p);
        }
    }
    let mut names = Names(Vec::new());
    syn::visit::Visit::visit_file(&mut names, file);
    names.0
}

/// Architecture Invariant: the editor sculpts through the session. Of the solver it names only
/// the settings and the report types; it names nothing of the rules (the session runs them)
/// and nothing behind the feature `testing`.
#[test]
fn the_editor_uses_the_librarys_surfaces_only() {
    let homes = surface_homes();
    assert_eq!(
        homes.get("Solver").map(String::as_str),
        Some("solver"),
        "{homes:?}"
    );
    assert_eq!(homes.get("RuleKind").map(String::as_str), Some("rules"));
    let allowed_solver = ["FrameReport", "SolverConfig", "SolverError"];
    let mut files = Vec::new();
    rust_files(&root().join("editor/src"), &mut files);
    let mut read = 0;
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let file = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        for (name, line) in clay_names(&file) {
            read += 1;
            let home = homes.get(&name).map(String::as_str);
            let at = format!("{}:{line}", f.display());
            assert!(home.is_some(), "{at}: `clay::{name}` is not on the surface");
            assert!(
                home != Some("solver") || allowed_solver.contains(&name.as_str()),
                "{at} uses the solver's `{name}` (only its settings and report types are the \
                 editor's)"
            );
            assert!(
                home != Some("rules"),
                "{at} uses the rules' `{name}` (use the session)"
            );
            assert!(home != Some("testing"), "{at} uses `clay::testing`");
        }
    }
    assert!(read > 50, "only {read} names read from clay in editor/src");
}

#[test]
fn protocol_types_live_only_in_the_language_server() {
    let server = root().join("cli/src/lsp");
    let mut files = Vec::new();
    for dir in ["src", "dsl/src", "editor/src", "cli/src"] {
        rust_files(&root().join(dir), &mut files);
    }
    let outside: Vec<&PathBuf> = files.iter().filter(|f| !f.starts_with(&server)).collect();
    assert!(outside.len() > 20, "only {} files read", outside.len());
    for f in outside {
        let text = std::fs::read_to_string(f).unwrap();
        for name in ["lsp_types", "lsp_server"] {
            assert!(
                !text.contains(name),
                "{} names `{name}`: protocol types belong in cli/src/lsp",
                f.display()
            );
        }
    }
    for manifest in ["Cargo.toml", "dsl/Cargo.toml", "editor/Cargo.toml"] {
        let text = std::fs::read_to_string(root().join(manifest)).unwrap();
        assert!(
            !text.contains("lsp-"),
            "{manifest} depends on a protocol crate"
        );
    }
}

/// The structure of an assembly a solver frame must leave alone: its parts (all but the
/// active state), its instances (all but the state shown), docks and chains.
fn structure(data: &clay_dsl::compiled::AssemblyData) -> String {
    let parts: Vec<_> = (data.parts.iter())
        .map(|p| (p.kind, &p.vertices, &p.edges, &p.states))
        .collect();
    let instances: Vec<_> = (data.instances.iter())
        .map(|i| (i.id, &i.name, i.piece, &i.vertices))
        .collect();
    format!(
        "{parts:?}\n{instances:?}\n{:?}\n{:?}\n{}",
        data.docks,
        data.chains,
        data.positions.len()
    )
}

/// Architecture Invariant: the solver moves vertices and picks rest states; only the rules
/// change what the assembly is made of. Frames that stretch, squeeze, bend and let go of the
/// example models (where the rules would rewrite them) leave parts, instances and connections
/// as they were.
#[test]
fn a_solver_frame_changes_no_part_instance_or_connection() {
    use clay::{Assembly, Compass, HandleKind};
    use clay::{Solver, SolverConfig};
    use glam::DVec2;
    let mut models = Vec::new();
    for name in [
        "wall.clay",
        "bend.clay",
        "castle.clay",
        "junction.clay",
        "centipede.clay",
    ] {
        let path = root().join("grammars").join(name);
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let compiled = clay_dsl::compile(
            &text,
            &path.to_string_lossy(),
            &clay_dsl::CompileOptions::default(),
        )
        .unwrap();
        models.push((name, compiled.grammar));
    }
    assert!(models.len() >= 3, "the example grammars are read");
    for (name, grammar) in models {
        let mut asm = Assembly::new(std::sync::Arc::new(grammar));
        let before = structure(asm.data());
        let mut solver = Solver::new(SolverConfig::from_params(&asm.grammar().solver));
        let west = asm.part_extreme(Compass::West).unwrap();
        let east = asm.part_extreme(Compass::East).unwrap();
        asm.hold_part(west, HandleKind::Pin).unwrap();
        let grab = asm.hold_part(east, HandleKind::Grab).unwrap();
        let size = clay::testing::bbox_diagonal(&asm.data().positions);
        let moves = [
            (DVec2::new(size, 0.0), 0.0),
            (DVec2::new(-0.8 * size, 0.0), 0.0),
            (DVec2::new(0.0, 0.5 * size), 1.2),
        ];
        for (translation, angle) in moves {
            assert!(asm.move_handle(grab, translation, angle));
            for _ in 0..20 {
                solver.frame(&mut asm).unwrap();
                assert_eq!(structure(asm.data()), before, "{name}");
            }
        }
        asm.release(grab);
        for _ in 0..40 {
            solver.frame(&mut asm).unwrap();
        }
        assert_eq!(structure(asm.data()), before, "{name}");
    }
}

/// Architecture Invariant: the libraries (`clay`, `clay-dsl`) never write to the terminal;
/// they return text and diagnostics, and the binaries (`clayc` in `cli/`, and the editor)
/// decide where they go. Whole files are read, tests included.
#[test]
fn the_libraries_print_nothing() {
    let mut files = Vec::new();
    for dir in ["src", "dsl/src"] {
        rust_files(&root().join(dir), &mut files);
    }
    assert!(files.len() > 40, "only {} files read", files.len());
    let writers = [
        "println!",
        "eprintln!",
        "print!(",
        "eprint!(",
        "dbg!(",
        "io::stdout",
        "io::stderr",
        "stdout()",
        "stderr()",
        "BufferWriter",
        "StandardStream",
    ];
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            for w in writers {
                assert!(
                    !code.contains(w),
                    "{}:{}: `{w}` in a library: return the text and let the binary print it",
                    f.display(),
                    n + 1
                );
            }
        }
    }
}

/// Architecture Invariant: no source file is over 900 lines outside its tests (a file has one
/// job; issue 38). The lines from a top-level `#[cfg(test)]` module on are the file's tests.
#[test]
fn no_source_file_is_over_900_lines_outside_its_tests() {
    let mut files = Vec::new();
    for dir in ["src", "dsl/src", "editor/src", "cli/src", "python/src"] {
        rust_files(&root().join(dir), &mut files);
    }
    assert!(files.len() > 100, "only {} files read", files.len());
    let mut long = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let code = (lines.windows(2))
            .position(|w| w[0] == "#[cfg(test)]" && w[1].starts_with("mod "))
            .unwrap_or(lines.len());
        if code > 900 {
            long.push(format!("{}: {code} lines", shown(&f)));
        }
    }
    assert!(long.is_empty(), "over 900 lines outside tests: {long:#?}");
}

/// Architecture Invariant: every file Clay reads goes through `clay_dsl::read_input` (or its
/// `regular_file` check before a bounded `take`), which refuses named pipes and devices before
/// opening them and stops at a limit: no input blocks a program or eats its memory (issue 47:
/// `clayc check /dev/zero` reached 11.5 GB; a FIFO as the editor's grammar froze its window).
/// Files' code outside their tests is read.
#[test]
fn every_file_is_read_through_the_one_bounded_reader() {
    let mut files = Vec::new();
    for dir in ["src", "dsl/src", "editor/src", "cli/src", "python/src"] {
        rust_files(&root().join(dir), &mut files);
    }
    assert!(files.len() > 100, "only {} files read", files.len());
    let readers = [
        "fs::read(",
        "fs::read_to_string(",
        "File::open(",
        "read_to_end(",
        "read_to_string(&mut",
    ];
    // the reader itself, and the loaders that check `regular_file` before a bounded `take`
    let home = ["dsl/src/input.rs", "dsl/src/compile/imports.rs"];
    // reads that are no user's file: a folder opened to make a rename durable, and the
    // language server's message body (bounded by its Content-Length, itself bounded)
    let known = [
        ("src/files.rs", "fs::File::open(&dir)"),
        ("cli/src/lsp/transport.rs", ".take(n as u64).read_to_end("),
    ];
    let mut unbounded = Vec::new();
    for f in files {
        let name = shown(&f);
        if home.contains(&name.as_str()) {
            continue;
        }
        let text = std::fs::read_to_string(&f).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let code = (lines.windows(2))
            .position(|w| w[0] == "#[cfg(test)]" && w[1].starts_with("mod "))
            .unwrap_or(lines.len());
        for (n, line) in lines[..code].iter().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            let exempt = known.iter().any(|(f, s)| *f == name && code.contains(s));
            if let Some(r) = readers.iter().find(|r| code.contains(*r))
                && !exempt
            {
                unbounded.push(format!("{name}:{}: `{r}`", n + 1));
            }
        }
    }
    assert!(
        unbounded.is_empty(),
        "read without clay_dsl::read_input: {unbounded:#?}"
    );
}

/// Architecture Invariant: no `use` imports a whole crate root (`use crate::*`, `use clay::*`,
/// `use clay_dsl::*`). Such a glob hides what a module uses from every test above, which
/// resolve names through their paths (issue 47: a forbidden call through `use crate::*` went
/// unseen). `use super::*` in a test module stays: it names its own parent.
#[test]
fn no_module_imports_a_whole_crate_root() {
    /// Every `use` item of a file, inline modules included.
    struct Uses(Vec<syn::ItemUse>);
    impl<'a> syn::visit::Visit<'a> for Uses {
        fn visit_item_use(&mut self, u: &'a syn::ItemUse) {
            self.0.push(u.clone());
        }
    }
    let roots = ["crate", "clay", "clay_dsl", "clay_editor"];
    let mut found = Vec::new();
    let mut read = 0;
    for (_, krate, _) in crates() {
        for (_, file, tree) in &krate.files {
            read += 1;
            let mut uses = Uses(Vec::new());
            syn::visit::Visit::visit_file(&mut uses, tree);
            for u in &uses.0 {
                let mut leaves = Vec::new();
                use_leaves(&u.tree, &mut Vec::new(), &mut leaves);
                for (path, bound, line) in leaves {
                    let root = path.len() == 1 && roots.contains(&path[0].as_str());
                    if bound.is_none() && root {
                        found.push(format!("{}:{line}: use {}::*", shown(file), path[0]));
                    }
                }
            }
        }
    }
    assert!(read > 150, "only {read} files read");
    assert!(found.is_empty(), "globs of a crate root: {found:#?}");
}

/// Architecture Invariant: the shipped binaries (`clayc`, the editor, the Python module) are
/// built without the test helpers: no `[dependencies]` entry of theirs (inline, or a
/// `[dependencies.clay]` table) enables `clay`'s feature `testing` (issue 47: `clayc` did, for the synthetic city its bench solves, which
/// now lives in `clay::synthetic`).
#[test]
fn the_shipped_binaries_are_built_without_the_test_helpers() {
    for manifest in ["cli/Cargo.toml", "editor/Cargo.toml", "python/Cargo.toml"] {
        let text = std::fs::read_to_string(root().join(manifest)).unwrap();
        let mut section = "";
        let mut clay_seen = false;
        for line in text.lines() {
            let line = line.trim();
            if line.starts_with('[') {
                section = line;
                continue;
            }
            // `clay = { ... }` under `[dependencies]`, or any line of a `[dependencies.clay]`
            // table (its `features = [...]`)
            let inline = section == "[dependencies]"
                && line.starts_with("clay")
                && !line.starts_with("clay-dsl");
            let table = section == "[dependencies.clay]";
            if inline || table {
                clay_seen = true;
                assert!(
                    !line.contains("testing"),
                    "{manifest}: `{line}` ships the test helpers"
                );
            }
        }
        assert!(clay_seen, "{manifest}: no `clay` dependency read");
    }
}

/// The packages `Cargo.lock` says `name` depends on, directly or not, any kind (normal, build,
/// dev), itself included.
fn locked_closure(lock: &str, name: &str) -> BTreeSet<String> {
    let mut deps: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for package in lock.split("[[package]]").skip(1) {
        let field = |key: &str| {
            package
                .lines()
                .find_map(|l| l.strip_prefix(key))
                .map(|v| v.trim().trim_matches('"').to_string())
        };
        let Some(own) = field("name = ") else {
            continue;
        };
        let listed = package.split("dependencies = [").nth(1).unwrap_or("");
        let listed = listed.split(']').next().unwrap_or("");
        let names = listed
            .split(',')
            .filter_map(|d| d.trim().trim_matches('"').split(' ').next())
            .filter(|d| !d.is_empty())
            .map(str::to_string);
        deps.entry(own).or_default().extend(names);
    }
    let mut seen = BTreeSet::from([name.to_string()]);
    let mut todo = vec![name.to_string()];
    while let Some(p) = todo.pop() {
        for d in deps.get(&p).into_iter().flatten() {
            if seen.insert(d.clone()) {
                todo.push(d.clone());
            }
        }
    }
    seen
}

/// Architecture Invariant: the dependencies the dev profile builds without optimisation
/// (`Cargo.toml`, `[profile.dev.package.NAME] opt-level = 0`: the editor's window system, GPU
/// and GUI) are none the core library or its tests use, whose solver and parser the tests
/// spend their time in.
#[test]
fn unoptimised_dependencies_are_none_of_the_cores() {
    let manifest = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    let lock = std::fs::read_to_string(root().join("Cargo.lock")).unwrap();
    let mut unoptimised = Vec::new();
    let mut current = None;
    for line in manifest.lines() {
        if let Some(p) = line.strip_prefix("[profile.dev.package.") {
            current = Some(p.trim_end_matches(']').trim_matches('"').to_string());
        } else if line.starts_with('[') {
            current = None;
        } else if line.replace(' ', "") == "opt-level=0"
            && let Some(p) = current.take()
        {
            unoptimised.push(p);
        }
    }
    assert!(unoptimised.len() > 10, "{unoptimised:?}");
    let core = locked_closure(&lock, "clay");
    assert!(
        core.contains("faer") && core.contains("proptest"),
        "{core:?}"
    );
    let mut all = locked_closure(&lock, "clay-editor");
    all.extend(locked_closure(&lock, "clayc"));
    for p in &unoptimised {
        assert!(
            all.contains(p),
            "`{p}` is not a dependency: remove its profile entry"
        );
        assert!(
            !core.contains(p),
            "`{p}` is built without optimisation but `clay` depends on it"
        );
    }
}

/// Architecture Invariant: no two public types of the libraries and the Python module share a
/// name, so a name read in any of them means one thing (issue 47: `clay::Session` and the
/// Python module's `Session`). A Python class whose Rust type would repeat a library name is
/// `Py<Name>` with `#[pyclass(name = "<Name>")]`, as `PySession` is `clay.Session`.
#[test]
fn no_two_public_types_share_a_name() {
    /// Every `pub` struct, enum, union, trait and type alias of a file, inline modules included.
    struct Types(Vec<(String, usize)>);
    impl<'a> syn::visit::Visit<'a> for Types {
        fn visit_item(&mut self, item: &'a syn::Item) {
            let named = match item {
                syn::Item::Struct(i) => Some((&i.vis, &i.ident)),
                syn::Item::Enum(i) => Some((&i.vis, &i.ident)),
                syn::Item::Union(i) => Some((&i.vis, &i.ident)),
                syn::Item::Trait(i) => Some((&i.vis, &i.ident)),
                syn::Item::Type(i) => Some((&i.vis, &i.ident)),
                _ => None,
            };
            if let Some((syn::Visibility::Public(_), ident)) = named {
                self.0.push((ident.to_string(), ident.span().start().line));
            }
            syn::visit::visit_item(self, item);
        }
    }
    let mut homes: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for (dir, krate, _) in crates() {
        if !["src", "dsl/src", "python/src"].contains(&dir) {
            continue;
        }
        for (_, file, tree) in &krate.files {
            let mut types = Types(Vec::new());
            syn::visit::Visit::visit_file(&mut types, tree);
            for (name, line) in types.0 {
                homes
                    .entry(name)
                    .or_default()
                    .push(format!("{}:{line}", shown(file)));
            }
        }
    }
    assert!(homes.contains_key("PySession") && homes.contains_key("Assembly"));
    let twice: Vec<_> = homes.iter().filter(|(_, at)| at.len() > 1).collect();
    assert!(twice.is_empty(), "public types of one name: {twice:#?}");
}

/// Architecture Invariant: `clay`'s top level is what the shipped code uses (issue 47: a
/// newcomer reads the surface once). Every function and constant re-exported in `src/lib.rs`
/// is named by the editor, `clayc` or the Python module; one only tests and benches use is
/// re-exported by `clay::testing` instead. (A type stays on the top level when a signature
/// there names it: `unnameable_types` keeps that side.)
#[test]
fn the_top_level_functions_and_constants_are_the_shipped_codes() {
    let homes = surface_homes();
    let mut used = BTreeSet::new();
    let mut files = Vec::new();
    for dir in ["editor/src", "cli/src", "python/src"] {
        rust_files(&root().join(dir), &mut files);
    }
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let file = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        used.extend(clay_names(&file).into_iter().map(|(name, _)| name));
    }
    assert!(
        used.contains("render_png") && used.contains("Session"),
        "{used:?}"
    );
    let type_name = |name: &str| {
        name.starts_with(|c: char| c.is_ascii_uppercase())
            && name.contains(|c: char| c.is_ascii_lowercase())
    };
    let unused: Vec<&String> = homes
        .iter()
        .filter(|(name, home)| name != home && !type_name(name) && !used.contains(*name))
        .map(|(name, _)| name)
        .collect();
    assert!(
        homes.len() > 60,
        "only {} names read from src/lib.rs",
        homes.len()
    );
    assert!(
        unused.is_empty(),
        "on clay's top level but used by no shipped code (re-export them in \
         src/testing/mod.rs): {unused:?}"
    );
}
