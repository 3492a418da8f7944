//! `import "PATH"`: loads the files a grammar imports (through a [`Loader`], so that a language
//! server can serve unsaved buffers), places each in the source map, parses it there, and
//! splices its declarations into the importing file's item list at the `import`.
//!
//! What an import brings: site types, pieces and rules (stretch, merge, cut), and the file's own
//! imports, transitively; not its `model` or `solver` block, which belong to the grammar being
//! sculpted. Names share one namespace across all files. A file is loaded once however often it
//! is imported (directly twice, or through two libraries); a file that imports itself, directly
//! or through others, is E061.

use std::collections::HashSet;
use std::io::Read;
use std::path::{Component, Path, PathBuf};
use std::sync::Arc;

use super::codes;
use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::source_map::{SourceFile, SourceMap};
use crate::syntax::{self, ImportDecl, Item, Span};

/// Most files one compilation may import (all levels together).
pub const MAX_IMPORTS: usize = 256;
/// Most bytes the imported files may have together (32 MiB).
pub const MAX_IMPORT_BYTES: usize = crate::input::MAX_SOURCE_BYTES;

/// Where imported files come from. `path` is already resolved against the importing file's
/// folder (`grammars/lib/roads.clay` for `import "lib/roads.clay"` in `grammars/town.clay`).
pub trait Loader {
    /// The bytes of the file at `path`. Reading more than [`MAX_IMPORT_BYTES`] is not needed:
    /// a longer file is reported as too large either way.
    fn load(&self, path: &str) -> std::io::Result<Vec<u8>>;
}

/// Reads imported files from the file system (what [`crate::compile`] uses).
#[derive(Clone, Copy, Debug, Default)]
pub struct FsLoader;

impl Loader for FsLoader {
    fn load(&self, path: &str) -> std::io::Result<Vec<u8>> {
        // the limit and a byte more, without error: a longer file is too large, reported at
        // its import with the others' sizes
        crate::input::regular_file(Path::new(path))?;
        let mut bytes = Vec::new();
        std::fs::File::open(path)?
            .take(MAX_IMPORT_BYTES as u64 + 1)
            .read_to_end(&mut bytes)?;
        Ok(bytes)
    }
}

/// The path of `import "target"` written in the file `importer`: relative to the importer's
/// folder (an absolute target is kept), with `.` and inner `..` removed lexically so that two
/// spellings of one file are recognised as the same file.
pub fn resolve(importer: &str, target: &str) -> String {
    let folder = Path::new(importer).parent().unwrap_or(Path::new(""));
    normalise(&folder.join(target))
}

fn normalise(path: &Path) -> String {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if matches!(out.components().next_back(), Some(Component::Normal(_))) {
                    out.pop();
                } else if !matches!(
                    out.components().next_back(),
                    Some(Component::RootDir | Component::Prefix(_))
                ) {
                    out.push("..");
                }
            }
            other => out.push(other),
        }
    }
    out.to_string_lossy().into_owned()
}

/// The main file's items with every import replaced by the imported declarations, the source
/// map of the imported files, and the problems found loading them.
pub(super) struct Spliced {
    pub items: Vec<Item>,
    pub sources: SourceMap,
    pub diags: Diagnostics,
}

struct Imports<'l> {
    loader: &'l dyn Loader,
    sources: SourceMap,
    main_len: usize,
    /// Every file asked for (the main one too): a file is loaded at most once.
    seen: HashSet<String>,
    /// The files being loaded, outermost first, each with the `import` string that led to it
    /// (none for the main file).
    stack: Vec<(String, Option<Span>)>,
    bytes: usize,
    limit_reported: bool,
    diags: Diagnostics,
}

/// Splices the imports of the main file (`main_len` bytes long, shown as `path`).
pub(super) fn splice(
    file: syntax::File,
    path: &str,
    main_len: usize,
    loader: &dyn Loader,
) -> Spliced {
    let main = normalise(Path::new(path));
    let mut imports = Imports {
        loader,
        sources: SourceMap::default(),
        main_len,
        seen: HashSet::from([main.clone()]),
        stack: vec![(main.clone(), None)],
        bytes: 0,
        limit_reported: false,
        diags: Diagnostics::new(),
    };
    let mut items = Vec::with_capacity(file.items.len());
    imports.items(file, &main, true, &mut items);
    Spliced {
        items,
        sources: imports.sources,
        diags: imports.diags,
    }
}

impl Imports<'_> {
    fn items(&mut self, file: syntax::File, path: &str, main: bool, out: &mut Vec<Item>) {
        for item in file.items {
            match item {
                Item::Import(i) => self.import(&i, path, out),
                // A library's own model and solver settings are not the importer's.
                Item::Model(_) | Item::Solver(_) if !main => {}
                other => out.push(other),
            }
        }
    }

    // Long because: each way an import can fail, in the order they are checked, with its own diagnostic.
    fn import(&mut self, i: &ImportDecl, importer: &str, out: &mut Vec<Item>) {
        let target = resolve(importer, &i.path.value);
        let at = i.path.span;
        if let Some(k) = self.stack.iter().position(|(p, _)| *p == target) {
            self.cycle(k, &target, at);
            return;
        }
        if !self.seen.insert(target.clone()) {
            return; // imported before: loaded once
        }
        if self.sources.files.len() >= MAX_IMPORTS {
            self.limit(at, format!("more than {MAX_IMPORTS} files are imported"));
            return;
        }
        let bytes = match self.loader.load(&target) {
            Ok(b) => b,
            Err(e) => {
                let why = match e.kind() {
                    std::io::ErrorKind::NotFound => "no such file".to_string(),
                    _ => strip_os_error(&e.to_string()),
                };
                self.diags.push(
                    Diagnostic::error(
                        codes::IMPORT_UNREADABLE,
                        format!("cannot read imported file `{target}`: {why}"),
                        at,
                        "imported here",
                    )
                    .with_hint(format!(
                        "an import's path is relative to the folder of the file that imports it \
                         (`{importer}`); check the spelling"
                    )),
                );
                return;
            }
        };
        if self.bytes + bytes.len() > MAX_IMPORT_BYTES {
            self.limit(
                at,
                format!(
                    "the imported files have more than {} MiB together",
                    MAX_IMPORT_BYTES >> 20
                ),
            );
            return;
        }
        self.bytes += bytes.len();
        let text = match String::from_utf8(bytes) {
            Ok(t) => t,
            Err(e) => {
                let bad = e.utf8_error().valid_up_to();
                self.diags.push(
                    Diagnostic::error(
                        codes::NOT_UTF8,
                        format!("imported file `{target}` is not valid UTF-8 text"),
                        at,
                        format!("invalid byte at offset {bad} of that file"),
                    )
                    .with_hint(
                        "an imported file must be a `.clay` grammar saved as UTF-8; \
                         check that the path names the right file",
                    ),
                );
                return;
            }
        };
        let base = self.sources.next_base(self.main_len);
        let text: Arc<str> = Arc::from(text);
        self.sources.files.push(SourceFile {
            path: target.clone(),
            text: Arc::clone(&text),
            base,
        });
        match crate::parse::parse_at(&text, base) {
            Ok(file) => {
                self.stack.push((target.clone(), Some(at)));
                self.items(file, &target, false, out);
                self.stack.pop();
            }
            Err(d) => self.diags.items.extend(d.items),
        }
    }

    /// E061: `target` is `stack[k]`, which is still being loaded. The primary span is the
    /// first import of the cycle (in the outermost file), the others are secondary.
    fn cycle(&mut self, k: usize, target: &str, at: Span) {
        // Each import of the cycle: the file it is in, the file it imports, where.
        let mut hops: Vec<(&str, &str, Span)> = Vec::new();
        for w in self.stack[k..].windows(2) {
            if let (from, (to, Some(span))) = (&w[0].0, &w[1]) {
                hops.push((from, to, *span));
            }
        }
        let last = &self.stack[self.stack.len() - 1].0;
        hops.push((last, target, at));
        let mut d = if hops.len() == 1 {
            Diagnostic::error(
                codes::IMPORT_CYCLE,
                format!("`{target}` imports itself"),
                at,
                "this is the file's own path",
            )
        } else {
            let mut names: Vec<String> = hops.iter().map(|(f, _, _)| format!("`{f}`")).collect();
            names.push(format!("`{target}`"));
            let (from, to, span) = hops[0];
            Diagnostic::error(
                codes::IMPORT_CYCLE,
                format!(
                    "import cycle: {} imports {}",
                    names[0],
                    names[1..].join(", which imports ")
                ),
                span,
                format!("`{from}` imports `{to}` here"),
            )
        };
        for &(from, to, span) in hops.iter().skip(1) {
            d = d.with_secondary(span, format!("`{from}` imports `{to}` here"));
        }
        self.diags.push(d.with_hint(
            "files may not import each other in a circle; move the shared declarations into a \
             file that both import",
        ));
    }

    fn limit(&mut self, at: Span, what: String) {
        if std::mem::replace(&mut self.limit_reported, true) {
            return;
        }
        self.diags.push(
            Diagnostic::error(
                codes::TOO_MUCH_REUSE,
                format!("too many imports: {what}"),
                at,
                "this import passes the limit",
            )
            .with_hint(format!(
                "a grammar may import at most {MAX_IMPORTS} files of at most {} MiB together",
                MAX_IMPORT_BYTES >> 20
            )),
        );
    }
}

/// `No such file or directory (os error 2)` -> `No such file or directory`.
fn strip_os_error(s: &str) -> String {
    match s.find(" (os error") {
        Some(i) => s[..i].to_string(),
        None => s.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_resolve_against_the_importer_folder() {
        assert_eq!(
            resolve("grammars/town.clay", "lib/roads.clay"),
            "grammars/lib/roads.clay"
        );
        assert_eq!(resolve("town.clay", "roads.clay"), "roads.clay");
        assert_eq!(resolve("a/b/c.clay", "../x.clay"), "a/x.clay");
        assert_eq!(resolve("a/c.clay", "./../../x.clay"), "../x.clay");
        assert_eq!(resolve("a/c.clay", "/abs/x.clay"), "/abs/x.clay");
        assert_eq!(resolve("/x.clay", "../y.clay"), "/y.clay");
    }
}
