//! Measures the editor's UI frame time on a large synthetic city (`clay::synthetic::city`) while
//! a part near one corner is dragged with the mouse, and while the settled model is redrawn
//! idle or hovered, to check the claim that a 10k-part model still redraws at 60 frames per
//! second (issue 6).
//!
//! Run: `cargo bench -p clay-editor --bench drag` (the city at 1k and 10k parts, the walls at
//! 1k, 5k and 10k), or `cargo bench -p clay-editor --bench drag -- walls 2000 20000` for one
//! model at other sizes. Besides the frame times it prints the drag latency: from a pointer
//! move to the end of the UI frame that draws the dragged part there (median and p95), and in
//! which UI frame of the drag the part is grabbed and first drawn moved.
//!
//! Each UI frame is what eframe does per frame short of the GPU: one `egui::Context::run_ui`
//! pass with the real `EditorApp::logic` (hot reload; the solver on the UI thread within its
//! budget, or on its own thread for a model whose frames cost more than 4 ms) and
//! `EditorApp::ui` (panels, the canvas's posing, picking and painting), fed the same pointer
//! events a mouse drag produces, followed by `Context::tessellate` of the painted shapes. The
//! egui_kittest harness the tests use is not used here: it also builds an AccessKit tree of
//! every labelled part each frame, which a real window without a screen reader does not, and
//! it does not tessellate. The GPU upload and draw of the tessellated mesh are not measured.
//! The drag's frames are paced at 60 Hz (a sleep to 16.7 ms after each), so the `sf/UI`
//! column (solver frames taken in per UI frame) shows how fast the model follows the mouse.

use std::sync::Arc;
use std::time::{Duration, Instant};

use clay::testing::pose_assembly;
use clay::{TessellationCache, synthetic};
use clay_editor::EditorApp;
use clay_editor::sculpt::Sculpt;
use egui::epaint::Primitive;
use egui::{Event, Modifiers, PointerButton, Pos2, RawInput, Rect, Vec2};
use glam::DVec2;

/// The window of `clay-editor` (its `main.rs` opens 1280 x 800 points).
const WINDOW: Vec2 = Vec2::new(1280.0, 800.0);
/// Measured frames of each scenario.
const FRAMES: usize = 120;
/// Frame time that 60 frames per second allows.
const BUDGET_MS: f64 = 1000.0 / 60.0;
/// How far the dragged part travels over the drag, as a fraction of the model's diagonal.
const DRAG_FRACTION: f64 = 0.04;
/// egui starts a drag once the pointer moved this far from the press (its click distance is
/// 6 points); the first move frame jumps this far so the gesture starts at once, as a real
/// mouse flick does.
const DRAG_START_JUMP: f32 = 8.0;
/// Longest wait for the model to settle before measuring.
const SETTLE_LIMIT: Duration = Duration::from_secs(60);

/// Timings of one UI frame, in milliseconds, and the solver's work in it.
#[derive(Clone, Copy, Debug, Default)]
struct FrameTime {
    /// `run_ui` plus tessellation: the CPU side of a frame.
    total: f64,
    /// `EditorApp::logic`: mostly the solver frames run within the budget.
    logic: f64,
    /// `EditorApp::ui`: panels, canvas posing, picking, painting, commands applied.
    ui: f64,
    tessellate: f64,
    /// Solver frames run in this UI frame.
    solver_frames: usize,
    /// Pass-1 and pass-2 iterations of the last solver frame (if one ran).
    pass1: usize,
    l2: usize,
    /// The last solver frame ran all its iterations (not cut short by the budget).
    complete: bool,
    /// Vertices sent to the GPU.
    vertices: usize,
}

/// The models measured: the synthetic city (streets, junctions, one long wall) and a
/// chain-heavy model of rows of 50-brick walls (`grammars/wall.clay`'s brick, one chain per
/// row; issue 40 measured 100 such rows trailing the pointer by a second).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Model {
    City,
    Walls,
}

impl Model {
    fn name(self) -> &'static str {
        match self {
            Model::City => "city",
            Model::Walls => "walls",
        }
    }

    fn grammar(self, parts: usize) -> clay_dsl::compiled::CompiledGrammar {
        match self {
            Model::City => synthetic::city(parts),
            Model::Walls => walls(parts),
        }
    }
}

/// Bricks per row of the walls model (49 two-brick parts per row).
const BRICKS_PER_ROW: usize = 50;

/// `grammars/wall.clay` with its model replaced by enough rows of [`BRICKS_PER_ROW`] bricks,
/// 1.5 m apart, for about `parts` parts.
fn walls(parts: usize) -> clay_dsl::compiled::CompiledGrammar {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../grammars/wall.clay");
    let text = std::fs::read_to_string(path).expect("grammars/wall.clay");
    let head = &text[..text.find("model {").expect("wall.clay has a model")];
    let rows = parts.div_ceil(BRICKS_PER_ROW - 1).max(1);
    let mut source = format!("{head}model {{\n");
    for r in 0..rows {
        let y = 1.5 * r as f64;
        source += &format!("    row{r} = chain brick x {BRICKS_PER_ROW} at (0, {y})\n");
    }
    source += "}\n";
    clay_dsl::compile(&source, "walls.clay", &clay_dsl::CompileOptions::default())
        .map(|c| c.grammar)
        .expect("the walls model compiles")
}

/// The editor inside a bare egui context, stepped one frame at a time.
struct Window {
    ctx: egui::Context,
    app: EditorApp,
    start: Instant,
}

impl Window {
    /// The editor on `model` of about `parts` parts, fitted in the window.
    fn open(model: Model, parts: usize) -> Self {
        let mut app = EditorApp::bundled();
        app.sculpt = Sculpt::new(Arc::new(model.grammar(parts)));
        app.canvas.grammar_changed();
        app.canvas.request_fit();
        Self {
            ctx: egui::Context::default(),
            app,
            start: Instant::now(),
        }
    }

    /// One UI frame with `events` as its input.
    fn frame(&mut self, events: Vec<Event>) -> FrameTime {
        let input = RawInput {
            screen_rect: Some(Rect::from_min_size(Pos2::ZERO, WINDOW)),
            time: Some(self.start.elapsed().as_secs_f64()),
            predicted_dt: 1.0 / 60.0,
            events,
            ..Default::default()
        };
        let mut t = FrameTime::default();
        let app = &mut self.app;
        let begin = Instant::now();
        let output = self.ctx.run_ui(input, |ui| {
            let a = Instant::now();
            app.logic(&ui.ctx().clone());
            let b = Instant::now();
            app.ui(ui);
            t.logic = ms(b - a);
            t.ui = ms(b.elapsed());
        });
        let tess = Instant::now();
        let primitives = self.ctx.tessellate(output.shapes, output.pixels_per_point);
        let end = Instant::now();
        t.tessellate = ms(end - tess);
        t.total = ms(end - begin);
        t.vertices = primitives
            .iter()
            .map(|p| match &p.primitive {
                Primitive::Mesh(m) => m.vertices.len(),
                Primitive::Callback(_) => 0,
            })
            .sum();
        let sculpt = &self.app.sculpt;
        t.solver_frames = sculpt.frames_last_step;
        if t.solver_frames > 0
            && let Some(r) = sculpt.last_report()
        {
            t.pass1 = r.pass1_iterations;
            t.l2 = r.l2_iterations;
            t.complete = r.complete;
        }
        t
    }

    /// Steps until the solver has no work left; returns the frames and time it took, or
    /// `None` if it did not settle within [`SETTLE_LIMIT`].
    fn settle(&mut self) -> Option<(usize, Duration)> {
        let begin = Instant::now();
        let mut frames = 0;
        // The first frame fits the view, so it runs even on a model already at rest.
        loop {
            self.frame(Vec::new());
            frames += 1;
            if !self.app.sculpt.needs_work() {
                return Some((frames, begin.elapsed()));
            }
            if begin.elapsed() > SETTLE_LIMIT {
                return None;
            }
        }
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The part to drag, and the model's diagonal: on the city the part nearest the top-right
/// corner of the street grid (the wall lies below `y = 0`); on the walls the east end of the
/// middle row.
fn part_to_drag(app: &EditorApp, model: Model) -> Option<(usize, f64)> {
    let asm = app.sculpt.assembly();
    let (lo, hi) = asm.data().positions.iter().fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let target = match model {
        Model::City => asm
            .data()
            .positions
            .iter()
            .filter(|p| p.y >= 0.0)
            .fold(DVec2::splat(f64::MIN), |m, &p| m.max(p)),
        Model::Walls => {
            let rows = ((hi.y - lo.y) / 1.5).round() as usize + 1;
            DVec2::new(hi.x, 1.5 * (rows / 2) as f64 + 0.25)
        }
    };
    let part = asm.part_nearest(target)?;
    Some((part, (hi - lo).length()))
}

/// Drag latency: for each pointer move of the drag (frame `k`, its target `s[k]` along the
/// drag), the time from the start of frame `k` to the end of the first frame `j >= k` whose
/// drawn part has come within half a move (or `tol`) of that target (`shown[j]`); moves never
/// caught up with are left out and counted.
fn latencies(
    begin: &[Instant],
    end: &[Instant],
    target: &[f64],
    shown: &[f64],
    tol: f64,
) -> (Vec<f64>, usize) {
    let mut out = Vec::new();
    let mut missed = 0;
    for k in 1..target.len() {
        let slack = (0.5 * (target[k] - target[k - 1]).abs()).max(tol);
        match (k..shown.len()).find(|&j| shown[j] >= target[k] - slack) {
            Some(j) => out.push(ms(end[j] - begin[k])),
            None => missed += 1,
        }
    }
    out.sort_by(f64::total_cmp);
    (out, missed)
}

/// Nearest-rank percentile of sorted values.
fn percentile(sorted: &[f64], q: f64) -> f64 {
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[rank - 1]
}

fn median_of(frames: &[FrameTime], f: impl Fn(&FrameTime) -> f64) -> f64 {
    let mut v: Vec<f64> = frames.iter().map(f).collect();
    v.sort_by(f64::total_cmp);
    percentile(&v, 0.5)
}

fn row(parts: usize, scenario: &str, frames: &[FrameTime]) {
    if frames.is_empty() {
        return;
    }
    let mut totals: Vec<f64> = frames.iter().map(|f| f.total).collect();
    totals.sort_by(f64::total_cmp);
    let under = totals.iter().filter(|&&t| t < BUDGET_MS).count() as f64 / totals.len() as f64;
    let solver_frames: usize = frames.iter().map(|f| f.solver_frames).sum();
    let solving: Vec<&FrameTime> = frames.iter().filter(|f| f.solver_frames > 0).collect();
    let complete = solving.iter().filter(|f| f.complete).count();
    let mean = |f: fn(&FrameTime) -> usize| {
        if solving.is_empty() {
            0.0
        } else {
            solving.iter().map(|t| f(t)).sum::<usize>() as f64 / solving.len() as f64
        }
    };
    println!(
        "{parts:>6} {scenario:<6} {:>4} {:>7.2} {:>7.2} {:>7.2} {:>6.0}% | {:>6.2} {:>6.2} {:>6.2} | {:>5.2} {:>5}/{:<5} {:>5.1} {:>5.1} | {:>7}",
        frames.len(),
        percentile(&totals, 0.5),
        percentile(&totals, 0.9),
        totals[totals.len() - 1],
        under * 100.0,
        median_of(frames, |f| f.logic),
        median_of(frames, |f| f.ui),
        median_of(frames, |f| f.tessellate),
        solver_frames as f64 / frames.len() as f64,
        complete,
        solving.len(),
        mean(|f| f.pass1),
        mean(|f| f.l2),
        frames[frames.len() - 1].vertices,
    );
}

fn run(model: Model, parts: usize) {
    let name = model.name();
    let built = Instant::now();
    let mut w = Window::open(model, parts);
    let n = w.app.sculpt.data().parts.len();
    let build = built.elapsed();
    let Some((settle_frames, settle_time)) = w.settle() else {
        println!(
            "{parts:>6} {name} ({n} parts): did not settle within {} s; skipped",
            SETTLE_LIMIT.as_secs()
        );
        return;
    };
    eprintln!(
        "{name}({parts}): {n} parts, built in {:.0} ms, settled in {settle_frames} UI frames ({:.1} s)",
        ms(build),
        settle_time.as_secs_f64()
    );

    // Idle: the settled model redrawn with no input (what any repaint costs).
    let idle: Vec<FrameTime> = (0..FRAMES).map(|_| w.frame(Vec::new())).collect();

    let Some((part, diagonal)) = part_to_drag(&w.app, model) else {
        println!("{parts:>6} {name}: no part to drag");
        return;
    };
    let centre = w.app.sculpt.assembly().part_centroid(part);
    let from = w.app.canvas.to_screen(centre);
    // Outward and up from the corner, DRAG_FRACTION of the model's diagonal in all.
    let step = DVec2::new(0.8, 0.6) * diagonal * DRAG_FRACTION;
    let to = w.app.canvas.to_screen(centre + step);
    let dir = (to - from).normalized();

    // Hover: the pointer crosses the settled model without a button (picking every frame).
    let hover: Vec<FrameTime> = (0..FRAMES)
        .map(|k| {
            let at = from - dir * 60.0 + dir * 60.0 * (k as f32 / FRAMES as f32);
            w.frame(vec![Event::PointerMoved(at)])
        })
        .collect();
    w.frame(vec![Event::PointerMoved(from)]);

    // Drag: press, FRAMES moves, release; every frame of the gesture is measured.
    let button = |pressed| Event::PointerButton {
        pos: from,
        button: PointerButton::Primary,
        pressed,
        modifiers: Modifiers::NONE,
    };
    // The drag's UI frames are paced at 60 Hz, as vsync paces a window: a large model solves
    // on its own thread meanwhile, so how many solver frames land per UI frame depends on
    // real time, not on how fast the UI frames alone could run.
    let paced = |w: &mut Window, events: Vec<Event>| {
        let begin = Instant::now();
        let t = w.frame(events);
        if let Some(left) = Duration::from_micros(16_667).checked_sub(begin.elapsed()) {
            std::thread::sleep(left);
        }
        t
    };
    // Per frame of the gesture: when it began and ended, where the pointer's move puts the
    // part along the drag (world metres from its start), and where the drawn part is.
    let unit = (w.app.canvas.to_world(to) - w.app.canvas.to_world(from)).normalize_or_zero();
    let shown_at = |w: &Window| {
        let asm = w.app.sculpt.assembly();
        let c = if part < asm.data().parts.len() {
            asm.part_centroid(part)
        } else {
            centre
        };
        (c - centre).dot(unit)
    };
    let (mut begin, mut end, mut target, mut shown) = (vec![], vec![], vec![0.0], vec![0.0]);
    begin.push(Instant::now());
    let mut drag = vec![paced(&mut w, vec![button(true)])];
    end.push(Instant::now());
    let mut grabbed = None;
    let mut grab_frames = None;
    for k in 1..=FRAMES {
        let at = from + dir * DRAG_START_JUMP + (to - from) * (k as f32 / FRAMES as f32);
        target.push((w.app.canvas.to_world(at) - w.app.canvas.to_world(from)).dot(unit));
        begin.push(Instant::now());
        drag.push(paced(&mut w, vec![Event::PointerMoved(at)]));
        end.push(Instant::now());
        shown.push(shown_at(&w));
        grabbed = grabbed.or(w.app.sculpt.grabbed());
        if grab_frames.is_none() && grabbed.is_some() {
            grab_frames = Some(k);
        }
    }
    // Moves not caught up with by the release get a further second of frames (the pointer
    // still, at its last place) to be drawn.
    for _ in 0..60 {
        if shown.last() >= target.last() {
            break;
        }
        begin.push(Instant::now());
        paced(&mut w, Vec::new());
        end.push(Instant::now());
        shown.push(shown_at(&w));
    }
    let release = Event::PointerButton {
        pos: to + dir * DRAG_START_JUMP,
        button: PointerButton::Primary,
        pressed: false,
        modifiers: Modifiers::NONE,
    };
    drag.push(w.frame(vec![release]));
    let tol = 1e-3 * diagonal;
    let (lat, missed) = latencies(&begin, &end, &target, &shown, tol);
    let first_shown = (1..shown.len()).find(|&j| shown[j] > tol);
    if lat.is_empty() {
        println!("{parts:>6} {name}: the part never caught up with the pointer");
    } else {
        println!(
            "{parts:>6} {name:<6} drag latency (pointer move to the part drawn there): median \
             {:.1} ms, p95 {:.1} ms, max {:.1} ms over {} moves ({missed} never caught up); \
             grabbed in UI frame {} of the drag, part first drawn moved in frame {}",
            percentile(&lat, 0.5),
            percentile(&lat, 0.95),
            lat[lat.len() - 1],
            lat.len(),
            grab_frames.map_or("never".into(), |k| k.to_string()),
            first_shown.map_or("never".into(), |k| k.to_string()),
        );
    }
    let moved = w.app.sculpt.assembly().part_centroid(part) - centre;
    eprintln!(
        "{name}({parts}): dragged part {part} (grabbed {grabbed:?}) by {:.0} pt = {:.2} m \
         ({:.1}% of the {:.0} m model); it moved {:.2} m by the release",
        (to - from).length() + DRAG_START_JUMP,
        step.length(),
        DRAG_FRACTION * 100.0,
        diagonal,
        moved.length(),
    );
    if grabbed.is_none() {
        println!("{parts:>6} {name}: the drag grabbed no part; the drag row measures a pan");
    }

    // The canvas re-poses every instance whenever the solver moved the model; timed alone here
    // (warm tessellation cache) to show how much of the drag's `ui` time it is.
    let mut cache = TessellationCache::new();
    let sculpt = &w.app.sculpt;
    pose_assembly(sculpt.grammar(), sculpt.data(), &mut cache);
    let mut pose: Vec<f64> = (0..20)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(pose_assembly(sculpt.grammar(), sculpt.data(), &mut cache));
            ms(t.elapsed())
        })
        .collect();
    pose.sort_by(f64::total_cmp);
    eprintln!(
        "{name}({parts}): pose_assembly alone (in `ui` on every solver frame): median {:.2} ms",
        percentile(&pose, 0.5)
    );

    row(n, "idle", &idle);
    row(n, "hover", &hover);
    row(n, "drag", &drag);
}

fn main() {
    // `cargo bench` passes `--bench`; `city` and `walls` choose models, numbers part counts.
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut sizes: Vec<usize> = args
        .iter()
        .filter_map(|a| a.parse().ok())
        .filter(|&n| n >= 10)
        .collect();
    let mut models: Vec<Model> = [Model::City, Model::Walls]
        .into_iter()
        .filter(|m| args.iter().any(|a| a == m.name()))
        .collect();
    if models.is_empty() {
        models = vec![Model::City, Model::Walls];
    }
    let default_sizes = sizes.is_empty();
    println!(
        "UI frame time (ms, CPU: egui run_ui + tessellate; {BUDGET_MS:.1} ms = 60 fps), \
         {FRAMES} frames per scenario, window {}x{} pt",
        WINDOW.x, WINDOW.y
    );
    // Columns: frame time (run_ui + tessellate) median, 90th percentile, max, share under
    // 16.7 ms; medians of its parts (logic = solver, ui = egui app code, tess); solver frames
    // per UI frame, solving UI frames whose last solver frame was complete, mean pass-1 and
    // pass-2 iterations of those frames; tessellated vertices.
    println!(
        " parts scene     n  median     p90     max   <16.7 |  logic     ui   tess \
         | sf/UI   complete pass1    l2 |   verts"
    );
    for model in models {
        if default_sizes {
            sizes = match model {
                Model::City => vec![1_000, 10_000],
                Model::Walls => vec![1_000, 5_000, 10_000],
            };
        }
        for &parts in &sizes {
            run(model, parts);
        }
    }
}
