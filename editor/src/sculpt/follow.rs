//! `clay-editor --follow`: the preview follows the text editor (docs/editors.md). `clayc lsp`
//! writes what the text editor's cursor is on to a small file (`clay_dsl::analysis::follow`);
//! this reads it a few times a second and highlights that part of the model: every instance
//! of a piece, the instances of a chain, a site on each instance of its piece. The other way,
//! `G` over a part writes the part's instance for the server, which asks the text editor to
//! show its declaration.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

use clay_dsl::analysis::follow::{self, Focus};
use clay_dsl::compiled::{AssemblyData, CompiledGrammar};
use egui::{Color32, Key, Stroke};

use super::Sculpt;
use super::canvas::Canvas;

/// How often the cursor file is looked at.
pub const POLL: Duration = Duration::from_millis(150);
const FOLLOWED: Color32 = Color32::from_rgb(0, 170, 200);

/// The channel to the language server and what it last said.
pub struct Follow {
    dir: PathBuf,
    seen: Option<SystemTime>,
    looked: Option<Instant>,
    /// What the text editor's cursor is on (in this grammar or a file it imports).
    pub focus: Option<Focus>,
    /// The last reveal asked for, or why it failed (for the status bar).
    pub message: Option<String>,
}

/// What a focus lights up in the model.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Highlight {
    pub instances: Vec<usize>,
    /// (instance, site of its piece).
    pub sites: Vec<(usize, usize)>,
}

impl Follow {
    /// Follows through the folder `dir`, created if missing (the server writes only while it
    /// exists).
    pub fn new(dir: PathBuf) -> Self {
        if let Err(e) = std::fs::create_dir_all(&dir) {
            eprintln!("clay-editor: cannot follow through {}: {e}", dir.display());
        }
        Self {
            dir,
            seen: None,
            looked: None,
            focus: None,
            message: None,
        }
    }

    /// Reads the cursor file if it changed; `true` when the focus did.
    pub fn poll(&mut self) -> bool {
        if self.looked.is_some_and(|t| t.elapsed() < POLL) {
            return false;
        }
        self.looked = Some(Instant::now());
        let file = self.dir.join(follow::CURSOR);
        let now = std::fs::metadata(&file).and_then(|m| m.modified()).ok();
        if now == self.seen {
            return false;
        }
        self.seen = now;
        let focus = follow::read(&file);
        let changed = focus != self.focus;
        self.focus = focus;
        changed
    }

    /// Asks the text editor (through the server) to show the declaration of `part`'s instance.
    pub fn reveal(
        &mut self,
        grammar_file: &Path,
        grammar: &CompiledGrammar,
        data: &AssemblyData,
        part: usize,
    ) {
        let Some(instance) = data.part_instances(part).into_iter().min() else {
            return;
        };
        let Some(i) = data.instances.get(instance) else {
            return;
        };
        // A chain's element `wall[3]` is declared as the chain `wall`.
        let name = i.name.split('[').next().unwrap_or(&i.name).to_string();
        let focus = Focus {
            file: real(grammar_file),
            kind: "instance".into(),
            piece: grammar.pieces.get(i.piece).map(|p| p.name.clone()),
            name,
        };
        self.message = Some(match follow::write(&self.dir, follow::REVEAL, &focus) {
            Ok(()) => format!("asked the text editor to show `{}`", focus.name),
            Err(e) => format!("cannot ask the text editor: {e}"),
        });
    }
}

/// A path as both sides compare it: absolute, links resolved (as given when that fails).
fn real(p: &Path) -> String {
    std::fs::canonicalize(p)
        .unwrap_or_else(|_| p.to_path_buf())
        .display()
        .to_string()
}

/// Whether a focus in `file` concerns the grammar `grammar_file` importing `imports`.
fn concerns(file: &str, grammar_file: &Path, imports: &[String]) -> bool {
    let file = real(Path::new(file));
    file == real(grammar_file) || imports.iter().any(|i| real(Path::new(i)) == file)
}

/// The instances and sites a focus names in the model.
pub fn highlight(focus: &Focus, grammar: &CompiledGrammar, data: &AssemblyData) -> Highlight {
    let piece_of = |i: usize| &grammar.pieces[data.instances[i].piece];
    let of_piece = |name: &str| -> Vec<usize> {
        (0..data.instances.len())
            .filter(|&i| piece_of(i).name == name)
            .collect()
    };
    let piece = focus.piece.as_deref().unwrap_or("");
    let mut h = Highlight::default();
    match focus.kind.as_str() {
        "piece" => h.instances = of_piece(&focus.name),
        "instance" | "chain" => {
            let element = format!("{}[", focus.name);
            h.instances = (0..data.instances.len())
                .filter(|&i| {
                    let n = &data.instances[i].name;
                    *n == focus.name || n.starts_with(&element)
                })
                .collect();
        }
        "site" => {
            for i in of_piece(piece) {
                if let Some(s) = piece_of(i).sites.iter().position(|s| s.name == focus.name) {
                    h.sites.push((i, s));
                }
            }
        }
        "vertex" | "rest state" => h.instances = of_piece(piece),
        "site type" => {
            let Some(t) = grammar.site_types.iter().position(|t| t.name == focus.name) else {
                return h;
            };
            for i in 0..data.instances.len() {
                for (s, site) in piece_of(i).sites.iter().enumerate() {
                    if site.site_type == t {
                        h.sites.push((i, s));
                    }
                }
            }
        }
        _ => {}
    }
    h
}

impl Follow {
    /// Once a frame: reads the cursor file, and `G` over the `hovered` part (while sculpting)
    /// asks for its declaration. Returns a message for the status bar.
    pub fn frame(
        &mut self,
        ctx: &egui::Context,
        sculpting: bool,
        hovered: Option<usize>,
        grammar_file: Option<&Path>,
        sculpt: &Sculpt,
    ) -> Option<String> {
        if self.poll() {
            ctx.request_repaint();
        }
        ctx.request_repaint_after(POLL);
        let key =
            sculpting && !ctx.egui_wants_keyboard_input() && ctx.input(|i| i.key_pressed(Key::G));
        if let (true, Some(part), Some(path)) = (key, hovered, grammar_file) {
            self.reveal(path, sculpt.grammar(), sculpt.data(), part);
        }
        self.message.take()
    }

    /// The followed instances and sites in the grammar `grammar_file` (importing `imports`).
    pub fn followed(
        &self,
        grammar_file: Option<&Path>,
        imports: &[String],
        sculpt: &Sculpt,
    ) -> Highlight {
        match (&self.focus, grammar_file) {
            (Some(focus), Some(path)) if concerns(&focus.file, path, imports) => {
                highlight(focus, sculpt.grammar(), sculpt.data())
            }
            _ => Highlight::default(),
        }
    }
}

/// Outlines the followed instances and rings the followed sites over the canvas.
pub fn paint(
    ui: &egui::Ui,
    canvas: &Canvas,
    grammar: &CompiledGrammar,
    data: &AssemblyData,
    h: &Highlight,
) {
    let painter = ui.painter_at(canvas.rect);
    let stroke = Stroke::new(3.0, FOLLOWED);
    let at = |v: usize| data.positions.get(v).map(|&p| canvas.to_screen(p));
    for &i in &h.instances {
        let inst = &data.instances[i];
        for [a, b] in &grammar.pieces[inst.piece].edges {
            let ends = (inst.vertices.get(*a), inst.vertices.get(*b));
            if let (Some(&a), Some(&b)) = ends
                && let (Some(a), Some(b)) = (at(a), at(b))
            {
                painter.line_segment([a, b], stroke);
            }
        }
    }
    for &(i, s) in &h.sites {
        let inst = &data.instances[i];
        let points: Vec<egui::Pos2> = grammar.pieces[inst.piece].sites[s]
            .vertices
            .iter()
            .filter_map(|&v| inst.vertices.get(v).and_then(|&g| at(g)))
            .collect();
        if points.is_empty() {
            continue;
        }
        let centre = points
            .iter()
            .fold(egui::Vec2::ZERO, |acc, p| acc + p.to_vec2())
            / points.len() as f32;
        painter.circle_stroke(centre.to_pos2(), 8.0, stroke);
    }
}
