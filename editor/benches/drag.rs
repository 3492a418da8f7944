//! Measures the editor's UI frame time on a large synthetic city (`clay::synthetic::city`) while
//! a part near one corner is dragged with the mouse, and while the settled model is redrawn
//! idle or hovered, to check the claim that a 10k-part model still redraws at 60 frames per
//! second (issue 6).
//!
//! Run: `cargo bench -p clay-editor --bench drag` (1k and 10k parts), or
//! `cargo bench -p clay-editor --bench drag -- 2000 20000` for other sizes.
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

use clay::render::{TessellationCache, pose_assembly};
use clay::synthetic;
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

/// The editor inside a bare egui context, stepped one frame at a time.
struct Window {
    ctx: egui::Context,
    app: EditorApp,
    start: Instant,
}

impl Window {
    /// The editor on a city of about `parts` parts, fitted in the window.
    fn city(parts: usize) -> Self {
        let mut app = EditorApp::bundled();
        app.sculpt = Sculpt::new(Arc::new(synthetic::city(parts)));
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

/// The part nearest the top-right corner of the street grid (the wall lies below `y = 0`), and
/// the model's diagonal.
fn corner_part(app: &EditorApp) -> Option<(usize, f64)> {
    let asm = app.sculpt.assembly();
    let (lo, hi) = asm.data().positions.iter().fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let top = asm
        .data()
        .positions
        .iter()
        .filter(|p| p.y >= 0.0)
        .fold(DVec2::splat(f64::MIN), |m, &p| m.max(p));
    let part = asm.part_nearest(top)?;
    Some((part, (hi - lo).length()))
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

fn run(parts: usize) {
    let built = Instant::now();
    let mut w = Window::city(parts);
    let n = w.app.sculpt.data().parts.len();
    let build = built.elapsed();
    let Some((settle_frames, settle_time)) = w.settle() else {
        println!(
            "{parts:>6} city ({n} parts): did not settle within {} s; skipped",
            SETTLE_LIMIT.as_secs()
        );
        return;
    };
    eprintln!(
        "city({parts}): {n} parts, built in {:.0} ms, settled in {settle_frames} UI frames ({:.1} s)",
        ms(build),
        settle_time.as_secs_f64()
    );

    // Idle: the settled model redrawn with no input (what any repaint costs).
    let idle: Vec<FrameTime> = (0..FRAMES).map(|_| w.frame(Vec::new())).collect();

    let Some((part, diagonal)) = corner_part(&w.app) else {
        println!("{parts:>6} city: no part to drag");
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
    let mut drag = vec![paced(&mut w, vec![button(true)])];
    let mut grabbed = None;
    for k in 1..=FRAMES {
        let at = from + dir * DRAG_START_JUMP + (to - from) * (k as f32 / FRAMES as f32);
        drag.push(paced(&mut w, vec![Event::PointerMoved(at)]));
        grabbed = grabbed.or(w.app.sculpt.grabbed());
    }
    let release = Event::PointerButton {
        pos: to + dir * DRAG_START_JUMP,
        button: PointerButton::Primary,
        pressed: false,
        modifiers: Modifiers::NONE,
    };
    drag.push(w.frame(vec![release]));
    let moved = w.app.sculpt.assembly().part_centroid(part) - centre;
    eprintln!(
        "city({parts}): dragged part {part} (grabbed {grabbed:?}) by {:.0} pt = {:.2} m \
         ({:.1}% of the {:.0} m model); it moved {:.2} m by the release",
        (to - from).length() + DRAG_START_JUMP,
        step.length(),
        DRAG_FRACTION * 100.0,
        diagonal,
        moved.length(),
    );
    if grabbed.is_none() {
        println!("{parts:>6} city: the drag grabbed no part; the drag row measures a pan");
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
        "city({parts}): pose_assembly alone (in `ui` on every solver frame): median {:.2} ms",
        percentile(&pose, 0.5)
    );

    row(n, "idle", &idle);
    row(n, "hover", &hover);
    row(n, "drag", &drag);
}

fn main() {
    // `cargo bench` passes `--bench`; any number is a part count.
    let mut sizes: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .filter(|&n| n >= 10)
        .collect();
    if sizes.is_empty() {
        sizes = vec![1_000, 10_000];
    }
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
    for parts in sizes {
        run(parts);
    }
}
