//! Generated grammars and gestures for `tests/paper_claims_generated.rs` (issue 36): the
//! grammar families the paper's claims are stated over, written as `.clay` text (a failing
//! case prints the grammar and the script that reproduce it), and a headless session that
//! replays script steps and measures what the claims need.
//!
//! The oracles are independent of any example: element counts from lengths, energy at rest,
//! exact rigid motions.

#![allow(dead_code)]

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::sync::Arc;

pub mod assembly;

use clay::testing::{bbox, bbox_diagonal, edge_strains};
use clay::{Assembly, RuleKind, Script, SolverConfig};
use clay_dsl::compiled::CompiledGrammar;
use glam::DVec2;

/// A rectangular element `length` long (along +x, its axis) and `height` high, cut into
/// `bays` bays by rungs, every bay braced by crossed diagonals (so a stretched element stays
/// square-on); its end sites have 2 vertices, or 3 with `mid_sites` (a vertex half-way up
/// each end, braced into the first and last bay).
#[derive(Clone, Debug, PartialEq)]
pub struct Element {
    pub length: f64,
    pub height: f64,
    pub bays: usize,
    pub mid_sites: bool,
}

impl Element {
    /// The piece's statements (vertices, edges, sites, skinned proxy), named `name`.
    pub fn piece(&self, name: &str, site_type: &str, extra: &str) -> String {
        let (l, h, b) = (self.length, self.height, self.bays);
        let mut s = format!("piece {name} {{\n");
        for i in 0..=b {
            let x = l * i as f64 / b as f64;
            let _ = writeln!(s, "    vertex b{i} ({x}, 0)");
            let _ = writeln!(s, "    vertex t{i} ({x}, {h})");
        }
        if self.mid_sites {
            let _ = writeln!(s, "    vertex m0 (0, {})", h / 2.0);
            let _ = writeln!(s, "    vertex m{b} ({l}, {})", h / 2.0);
        }
        // the outline, counter-clockwise
        let bottom: Vec<String> = (0..=b).map(|i| format!("b{i}")).collect();
        let top: Vec<String> = (0..=b).rev().map(|i| format!("t{i}")).collect();
        let mut outline = bottom.join("-");
        if self.mid_sites {
            let _ = write!(outline, "-m{b}");
        }
        let _ = write!(outline, "-{}", top.join("-"));
        if self.mid_sites {
            outline.push_str("-m0");
        }
        outline.push_str("-b0");
        let mut edges = vec![outline];
        for i in 1..b {
            edges.push(format!("b{i}-t{i}"));
        }
        for i in 0..b {
            edges.push(format!("b{i}-t{}", i + 1));
            edges.push(format!("b{}-t{i}", i + 1));
        }
        if self.mid_sites {
            edges.push(if b > 1 {
                "m0-b1, m0-t1".into()
            } else {
                "m0-t1".into()
            });
            edges.push(if b > 1 {
                format!("m{b}-b{}, m{b}-t{}", b - 1, b - 1)
            } else {
                format!("m{b}-b0")
            });
        }
        let _ = writeln!(s, "    edges {}", edges.join(", "));
        let (west, east) = if self.mid_sites {
            ("t0, m0, b0".to_string(), format!("b{b}, m{b}, t{b}"))
        } else {
            ("t0, b0".to_string(), format!("b{b}, t{b}"))
        };
        let _ = writeln!(s, "    site west: {site_type} [{west}] out (-1, 0)");
        let _ = writeln!(s, "    site east: {site_type} [{east}] out (1, 0)");
        let _ = writeln!(
            s,
            "    polygon skinned fill #b5651d {{ (0, 0) ({l}, 0) ({l}, {h}) (0, {h}) }}"
        );
        s.push_str(extra);
        s.push_str("}\n");
        s
    }
}

/// One stretchable chain (paper 5.1): `count` elements along a line at `angle` degrees from
/// `origin`, under `stretch` with `min` (and `max`).
#[derive(Clone, Debug, PartialEq)]
pub struct ChainGrammar {
    pub element: Element,
    pub count: usize,
    pub min: usize,
    pub max: Option<usize>,
    pub angle: f64,
    pub origin: DVec2,
    pub norm: f64,
    pub hysteresis: f64,
}

impl ChainGrammar {
    pub fn text(&self) -> String {
        let mut s = format!(
            "solver {{\n    hysteresis = {}\n    norm = {}\n}}\n\nsite type joint\n\n",
            self.hysteresis, self.norm
        );
        s.push_str(&self.element.piece("brick", "joint", ""));
        let max = self.max.map(|m| format!(" max {m}")).unwrap_or_default();
        let _ = writeln!(
            s,
            "\nstretch brick from west to east {{ min {}{max} }}\n",
            self.min
        );
        let _ = writeln!(
            s,
            "model {{\n    wall = chain brick x {} at ({}, {}) rotate {}\n}}",
            self.count, self.origin.x, self.origin.y, self.angle
        );
        s
    }

    /// The chain's direction.
    pub fn axis(&self) -> DVec2 {
        DVec2::from_angle(self.angle.to_radians())
    }

    /// Where element `k`'s centroid is at rest.
    pub fn centre(&self, k: usize) -> DVec2 {
        let e = &self.element;
        let local = DVec2::new((k as f64 + 0.5) * e.length, e.height / 2.0);
        self.origin + self.axis().rotate(local)
    }

    /// The chain's rest length.
    pub fn length(&self) -> f64 {
        self.count as f64 * self.element.length
    }

    /// The element count a chain held at `factor` times its rest length should have: the
    /// nearest whole number within the rule's `min` and `max`.
    pub fn fits(&self, length: f64) -> f64 {
        length / self.element.length
    }
}

/// Script steps, written as the JSON of `docs/scripts.md`.
pub mod step {
    use glam::DVec2;

    pub fn pin_at(p: DVec2) -> String {
        format!(r#"{{"pin": {{"at": [{}, {}]}}}}"#, p.x, p.y)
    }
    pub fn unpin_at(p: DVec2) -> String {
        format!(r#"{{"unpin": {{"at": [{}, {}]}}}}"#, p.x, p.y)
    }
    pub fn grab_at(p: DVec2) -> String {
        format!(r#"{{"grab": {{"at": [{}, {}]}}}}"#, p.x, p.y)
    }
    pub fn drag(by: DVec2, frames: u64) -> String {
        format!(
            r#"{{"drag": {{"by": [{}, {}], "frames": {frames}}}}}"#,
            by.x, by.y
        )
    }
    pub fn drag_to(p: DVec2, frames: u64) -> String {
        format!(
            r#"{{"drag": {{"to": [{}, {}], "frames": {frames}}}}}"#,
            p.x, p.y
        )
    }
    pub fn rotate(degrees: f64, frames: u64) -> String {
        format!(r#"{{"rotate": {{"degrees": {degrees}, "frames": {frames}}}}}"#)
    }
    pub fn hold(frames: u64) -> String {
        format!(r#"{{"hold": {{"frames": {frames}}}}}"#)
    }
    pub fn release() -> String {
        r#"{"release": {}}"#.to_string()
    }
    pub fn cut_at(p: DVec2) -> String {
        format!(r#"{{"cut": {{"at": [{}, {}]}}}}"#, p.x, p.y)
    }
}

/// `cases` cases (or `CLAY_CLAIMS_CASES`), from a fixed seed per property, shrinking a
/// failure to a minimal grammar and script.
pub fn config(cases: u32, seed: u64) -> proptest::test_runner::Config {
    let cases = std::env::var("CLAY_CLAIMS_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(cases);
    proptest::test_runner::Config {
        cases,
        rng_seed: proptest::test_runner::RngSeed::Fixed(seed),
        failure_persistence: None,
        max_shrink_iters: 256,
        ..proptest::test_runner::Config::default()
    }
}

/// A headless session over a generated grammar, with the rules; it records every step it ran
/// so a failure can print the script that reproduces it.
pub struct Run {
    pub text: String,
    pub grammar: Arc<CompiledGrammar>,
    pub asm: Assembly,
    pub session: clay::Session,
    pub steps: Vec<String>,
    count: usize,
}

impl Run {
    pub fn new(text: &str) -> Self {
        Self::with(text, |_| {})
    }

    pub fn with(text: &str, tune: impl FnOnce(&mut SolverConfig)) -> Self {
        let grammar =
            match clay_dsl::compile(text, "generated.clay", &clay_dsl::CompileOptions::default()) {
                Ok(c) => Arc::new(c.grammar),
                Err(e) => panic!("the generated grammar does not compile: {e:?}\n{text}"),
            };
        let mut config = SolverConfig::from_params(&grammar.solver);
        tune(&mut config);
        Self {
            text: text.to_string(),
            asm: Assembly::new(grammar.clone()),
            grammar,
            session: clay::Session::new(config),
            steps: Vec::new(),
            count: 0,
        }
    }

    /// Runs one script step.
    pub fn step(&mut self, step: &str) -> &mut Self {
        let script = Script::parse(&format!(r#"{{"steps": [{step}]}}"#))
            .unwrap_or_else(|e| panic!("bad generated step {step}: {e}"));
        for s in &script.steps {
            if let Err(e) = self.session.step(&mut self.asm, self.count, s) {
                panic!("step {step} failed: {e}\n{}", self.repro());
            }
            self.count += 1;
        }
        self.steps.push(step.to_string());
        self
    }

    pub fn steps(&mut self, steps: &[String]) -> &mut Self {
        for s in steps {
            self.step(s);
        }
        self
    }

    /// The grammar text and the script, as a failure prints them.
    pub fn repro(&self) -> String {
        format!(
            "--- generated.clay ---\n{}--- script.json ---\n{{\"steps\": [\n  {}\n]}}\n",
            self.text,
            self.steps.join(",\n  ")
        )
    }

    pub fn count(&self, piece: &str) -> usize {
        self.states(piece).len()
    }

    /// The elements of the chain whose instances are named `stem[k]` or `stem#id` (a chain
    /// of the model and the elements rules put in after its elements).
    pub fn chain_count(&self, stem: &str) -> usize {
        let of = |name: &str| name.split(['[', '#']).next() == Some(stem);
        (self.asm.data().instances.iter())
            .filter(|i| of(&i.name))
            .count()
    }

    pub fn instances(&self) -> usize {
        self.asm.data().instances.len()
    }

    pub fn fired(&self, kind: RuleKind) -> usize {
        self.session.rules_fired().get(&kind).copied().unwrap_or(0)
    }

    pub fn events(&self) -> usize {
        self.session.rules_fired().values().sum()
    }

    pub fn energy(&self) -> f64 {
        self.session.summary(&self.asm).energy
    }

    pub fn max_strain(&self) -> f64 {
        edge_strains(&self.asm)
            .into_iter()
            .map(f64::abs)
            .fold(0.0, f64::max)
    }

    /// The model's bounding box diagonal.
    pub fn size(&self) -> f64 {
        bbox_diagonal(&self.asm.data().positions)
    }

    pub fn bbox(&self) -> [f64; 4] {
        let (lo, hi) = bbox(&self.asm.data().positions).unwrap_or_default();
        [lo.x, lo.y, hi.x, hi.y]
    }

    /// The active states of every instance of `piece`, by name.
    pub fn states(&self, piece: &str) -> Vec<String> {
        let g = &self.grammar;
        self.asm
            .data()
            .instances
            .iter()
            .filter(|i| g.pieces[i.piece].name == piece)
            .map(|i| g.pieces[i.piece].states[i.state].name.clone())
            .collect()
    }

    /// Per element of the first chain that no handle holds: its length (from its `west`
    /// site's centre to its `east` site's) over its rest length, less one.
    pub fn element_strains(&self, rest: f64) -> Vec<f64> {
        let data = self.asm.data();
        let held: Vec<u64> = (self.asm.handles().iter())
            .filter_map(|h| h.held_instance())
            .collect();
        let Some(chain) = data.chains.first() else {
            return Vec::new();
        };
        chain
            .instances
            .iter()
            .filter(|&&i| !held.contains(&data.instances[i].id))
            .map(|&i| {
                let inst = &data.instances[i];
                let piece = &self.grammar.pieces[inst.piece];
                let centre = |site: usize| {
                    let vs = &piece.sites[site].vertices;
                    vs.iter()
                        .map(|&k| data.positions[inst.vertices[k]])
                        .sum::<DVec2>()
                        / vs.len() as f64
                };
                (centre(1) - centre(0)).length() / rest - 1.0
            })
            .collect()
    }

    pub fn figures(&self) -> String {
        let fired: BTreeMap<&str, usize> = self
            .session
            .rules_fired()
            .iter()
            .filter(|(_, n)| **n > 0)
            .map(|(k, &n)| (k.name(), n))
            .collect();
        format!(
            "instances {}, max |strain| {:.4}, energy {:.3e}, size {:.3}, fired {fired:?}",
            self.instances(),
            self.max_strain(),
            self.energy(),
            self.size()
        )
    }
}

/// Proptest strategies for the grammar families and their gestures.
pub mod strategy {
    use super::*;
    use proptest::prelude::*;

    /// An element of varied proportions and vertex counts.
    pub fn element() -> impl Strategy<Value = Element> {
        (0.3f64..3.0, 0.15f64..1.5, 1usize..=3, any::<bool>()).prop_map(
            |(length, ratio, bays, mid_sites)| Element {
                length: round(length),
                height: round(length * ratio),
                bays,
                mid_sites,
            },
        )
    }

    /// A chain of `counts` elements in any orientation and place, with the paper's norm and
    /// hysteresis, `min` from 2 up to its count (a few at the count) and sometimes a `max`.
    pub fn chain(counts: impl Strategy<Value = usize>) -> impl Strategy<Value = ChainGrammar> {
        (
            element(),
            counts,
            -180.0f64..180.0,
            (-50.0f64..50.0, -50.0f64..50.0),
        )
            .prop_flat_map(|(element, count, angle, (x, y))| {
                let min = prop_oneof![4 => Just(2usize), 1 => 2..=count.max(2)];
                let max = prop_oneof![3 => Just(None), 1 => (count..=4 * count).prop_map(Some)];
                (
                    Just(element),
                    Just(count),
                    min,
                    max,
                    Just(angle),
                    Just((x, y)),
                )
            })
            .prop_map(|(element, count, min, max, angle, (x, y))| ChainGrammar {
                element,
                count,
                min,
                max: max.map(|m| m.max(min)),
                angle: round(angle),
                origin: DVec2::new(round(x), round(y)),
                norm: 0.5,
                hysteresis: 0.15,
            })
    }

    /// Chain lengths from 2 to 200, most of them short.
    pub fn counts() -> impl Strategy<Value = usize> {
        prop_oneof![3 => 2usize..12, 2 => 12usize..60, 1 => 60usize..=200]
    }

    /// A stretch factor from 0.2 to 10, spread evenly in its logarithm.
    pub fn factor() -> impl Strategy<Value = f64> {
        (0.2f64.ln()..10.0f64.ln()).prop_map(|l| round(l.exp()))
    }

    /// Frames a gesture takes: 0 (a jump) to 480.
    pub fn frames() -> impl Strategy<Value = u64> {
        prop_oneof![1 => Just(0u64), 1 => 1u64..8, 2 => 8u64..120, 1 => 120u64..=480]
    }

    /// Three decimals: what the grammar text and the scripts print is what ran.
    pub fn round(x: f64) -> f64 {
        (x * 1000.0).round() / 1000.0
    }

    /// Six decimals, for derived coordinates.
    pub fn round6(x: f64) -> f64 {
        (x * 1e6).round() / 1e6
    }
}

/// A chain held at `factor` times its length: one end pinned, the other dragged along the
/// chain over `frames` frames (0: a jump), then held.
#[derive(Clone, Debug)]
pub struct Pull {
    pub grammar: ChainGrammar,
    pub factor: f64,
    pub frames: u64,
    /// Drag the chain's first element (the last pinned) instead of its last.
    pub reversed: bool,
}

impl Pull {
    /// The element count the chain should have at `factor`: `factor x count`, within the
    /// rule's `min` and `max`.
    pub fn expected(&self, factor: f64) -> f64 {
        let g = &self.grammar;
        let k = factor * g.count as f64;
        let k = k.max(g.min as f64);
        match g.max {
            Some(m) => k.min(m as f64),
            None => k,
        }
    }

    /// Whether the rule's `min` or `max` holds the count at `factor`.
    pub fn clamped(&self, factor: f64) -> bool {
        self.expected(factor) != factor * self.grammar.count as f64
    }

    /// (pinned, grabbed) element centres and the drag direction.
    pub fn ends(&self) -> (DVec2, DVec2, DVec2) {
        let g = &self.grammar;
        let (first, last) = (g.centre(0), g.centre(g.count - 1));
        if self.reversed {
            (last, first, -g.axis())
        } else {
            (first, last, g.axis())
        }
    }

    /// A run with the pin and the grab in place.
    pub fn start(&self) -> Run {
        let mut run = Run::new(&self.grammar.text());
        let (pinned, grabbed, _) = self.ends();
        run.step(&step::pin_at(pinned))
            .step(&step::grab_at(grabbed));
        run
    }

    /// The drag from `from` to `to` times the rest length.
    pub fn drag(&self, from: f64, to: f64, frames: u64) -> String {
        let (_, _, dir) = self.ends();
        step::drag(dir * (to - from) * self.grammar.length(), frames)
    }

    /// Frames to hold after reaching `factor` from a count of `from` elements: time for the
    /// solver to settle and for the rules to add or drop the elements one a frame.
    pub fn settle(&self, from: f64, factor: f64) -> u64 {
        60 + (self.expected(factor) - from).abs().ceil() as u64
    }
}

/// The paper's claims as checks on a finished run: `Err` says what failed.
pub mod check {
    use super::*;

    /// Fill (paper 5.1, Fig. 8): held at `factor`, the chain has the count its length calls
    /// for (|k - f n| < 1, or the rule's bound exactly), the length left over spread evenly
    /// (every element's strain at most 0.6 / k + 0.01), and a pull removed nothing, a push
    /// inserted nothing.
    ///
    /// The strain is each element's own (its end sites' distance over its rest length) and k
    /// counts the elements no handle holds: a handle holds its element's every vertex where
    /// it put it (paper Eq. 3), so the leftover spreads over the others, and within an element
    /// its bays share its strain by their stiffness (a bay braced into a three-vertex site
    /// less than the bay beside it), which is the element's build, not the spreading.
    pub fn fill(pull: &Pull, run: &Run, factor: f64) -> Result<(), String> {
        let k = run.count("brick") as f64;
        let want = pull.expected(factor);
        let strains = run.element_strains(pull.grammar.element.length);
        let strain = strains.iter().map(|s| s.abs()).fold(0.0, f64::max);
        let bound = 0.6 / strains.len().max(1) as f64 + 0.01;
        let count_ok = if pull.clamped(factor) {
            k == want
        } else {
            (k - want).abs() < 1.0
        };
        let mut why = Vec::new();
        if !count_ok {
            why.push(format!("{k} elements, want {want:.3}"));
        }
        if !pull.clamped(factor) && strain > bound {
            why.push(format!("an element's |strain| {strain:.4} > {bound:.4}"));
        }
        if factor > 1.0 && run.fired(RuleKind::Shrink) > 0 {
            why.push(format!("a pull removed {}", run.fired(RuleKind::Shrink)));
        }
        if factor < 1.0 && run.fired(RuleKind::Stretch) > 0 {
            why.push(format!("a push inserted {}", run.fired(RuleKind::Stretch)));
        }
        verdict(why, run)
    }

    /// At rest: the energy at most `1e-6 x size^2`.
    pub fn at_rest(run: &Run, tolerance: f64) -> Result<(), String> {
        let (e, size) = (run.energy(), run.size());
        if e <= tolerance * size * size {
            Ok(())
        } else {
            verdict(
                vec![format!(
                    "energy {e:.3e} > {tolerance:e} x size^2 ({size:.3} m)"
                )],
                run,
            )
        }
    }

    pub fn verdict(why: Vec<String>, run: &Run) -> Result<(), String> {
        if why.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "{}; {}\n{}",
                why.join("; "),
                run.figures(),
                run.repro()
            ))
        }
    }
}

/// The claims as functions of a generated case (the tests assert them; a probe can count).
pub mod claims {
    use super::*;

    /// Fill: pulled or pushed to `pull.factor` and held.
    pub fn fill(pull: &Pull) -> Result<(), String> {
        let mut run = pull.start();
        run.step(&pull.drag(1.0, pull.factor, pull.frames));
        run.step(&step::hold(
            pull.settle(pull.grammar.count as f64, pull.factor),
        ));
        check::fill(pull, &run, pull.factor)
    }

    /// Round trip: pulled or pushed to `pull.factor`, held, brought back over `back` frames
    /// and held: exactly the elements it had, at rest.
    pub fn round_trip(pull: &Pull, back: u64) -> Result<(), String> {
        let mut run = pull.start();
        let n = pull.grammar.count as f64;
        run.step(&pull.drag(1.0, pull.factor, pull.frames));
        run.step(&step::hold(pull.settle(n, pull.factor)));
        run.step(&pull.drag(pull.factor, 1.0, back));
        let k = run.count("brick") as f64;
        run.step(&step::hold(pull.settle(k, 1.0)));
        let k = run.count("brick");
        if k != pull.grammar.count {
            return check::verdict(
                vec![format!("{k} elements, want {}", pull.grammar.count)],
                &run,
            );
        }
        check::at_rest(&run, 1e-6)
    }

    /// Speed: the same held pose reached over 0, 5, 30 and 240 frames gives counts within
    /// one of each other.
    pub fn speed(pull: &Pull) -> Result<(), String> {
        let mut counts = Vec::new();
        let mut last = None;
        for frames in [0, 5, 30, 240] {
            let mut run = pull.start();
            run.step(&pull.drag(1.0, pull.factor, frames));
            run.step(&step::hold(
                pull.settle(pull.grammar.count as f64, pull.factor),
            ));
            counts.push(run.count("brick"));
            last = Some(run);
        }
        let (lo, hi) = (counts.iter().min().unwrap(), counts.iter().max().unwrap());
        if hi - lo <= 1 {
            Ok(())
        } else {
            let run = last.unwrap();
            check::verdict(
                vec![format!(
                    "counts {counts:?} over 0, 5, 30, 240 frames (last run below)"
                )],
                &run,
            )
        }
    }

    /// Relaxation: after the pull, let go of everything: at rest within 200 frames.
    pub fn relaxation(pull: &Pull) -> Result<(), String> {
        let mut run = pull.start();
        run.step(&pull.drag(1.0, pull.factor, pull.frames));
        run.step(&step::hold(10));
        run.step(&step::release());
        let (pinned, _, _) = pull.ends();
        // the pin holds the instance nearest its element's rest centre
        let pinned_now = run.asm.handles().iter().find_map(|h| {
            let id = h.held_instance()?;
            let i = run.asm.data().instances.iter().position(|x| x.id == id)?;
            run.asm.instance_centroid(i)
        });
        run.step(&step::unpin_at(pinned_now.unwrap_or(pinned)));
        run.step(&step::hold(200));
        if !run.asm.handles().is_empty() {
            return check::verdict(vec!["something is still held".into()], &run);
        }
        check::at_rest(&run, 1e-6)
    }
}

/// A street of `count` segments (an unstretchable chain, `along west -> east`) whose piece has
/// the rest states `bent` (`bend angle`) and `mirrored` (`mirror bent`): paper 4.2's
/// replacement, Fig. 4.
#[derive(Clone, Debug, PartialEq)]
pub struct BendGrammar {
    /// The segment: its length along the axis and its width (`height`), `bays` bays.
    pub segment: Element,
    pub count: usize,
    /// `bent`'s angle in degrees (10 to 90, to the left).
    pub angle: f64,
    /// Where the street starts and its direction in degrees.
    pub origin: DVec2,
    pub heading: f64,
}

impl BendGrammar {
    pub fn text(&self) -> String {
        let s = &self.segment;
        // the segment centred on its axis: y from -height/2 to height/2
        let shifted = Element {
            length: s.length,
            height: s.height,
            bays: s.bays,
            mid_sites: s.mid_sites,
        };
        let extra = format!(
            "    axis west -> east\n    state bent bend {}\n    state mirrored mirror bent\n",
            self.angle
        );
        let piece = shifted.piece("road", "lane", &extra);
        // move every point down by half the height so the axis is y = 0
        let h = s.height / 2.0;
        let piece = shift_piece_y(&piece, -h, strategy::round6);
        format!(
            "site type lane\n\n{piece}\nmodel {{\n    street = chain road x {} along west -> east at ({}, {}) rotate {}\n}}\n",
            self.count, self.origin.x, self.origin.y, self.heading
        )
    }

    fn direction(&self, turn: f64) -> DVec2 {
        DVec2::from_angle(self.heading.to_radians() + turn)
    }

    /// Segment `k`'s centroid at rest.
    pub fn centre(&self, k: usize) -> DVec2 {
        self.origin + self.direction(0.0) * (k as f64 + 0.5) * self.segment.length
    }

    /// Where segment `k` starts and its heading (radians, absolute) when the segments before
    /// it bend by `turns` (segment index, radians) and the rest are straight.
    pub fn start_of(&self, k: usize, turns: &[(usize, f64)]) -> (DVec2, f64) {
        let l = self.segment.length;
        let mut p = self.origin;
        let mut heading = self.heading.to_radians();
        for i in 0..k {
            let theta = turns.iter().find(|t| t.0 == i).map_or(0.0, |t| t.1);
            p = arc_end(p, heading, l, theta);
            heading += theta;
        }
        (p, heading)
    }

    /// The centroid of the last segment (the grab) when segment `k` bends evenly by `theta`
    /// from `before` (its start and heading) and the segments after it are straight.
    pub fn handle_at(&self, k: usize, theta: f64, before: (DVec2, f64)) -> (DVec2, f64) {
        let l = self.segment.length;
        let (start, heading) = before;
        let end = arc_end(start, heading, l, theta);
        let after = heading + theta;
        let straight = l * (self.count as f64 - k as f64 - 1.5);
        (end + DVec2::from_angle(after) * straight, after)
    }

    /// Script steps that bend segment `k` from `before` by `degrees` (either way) in steps of
    /// at most 3 degrees: turn the handle, then drag its centroid onto the path over 3 frames.
    pub fn bend_steps(&self, k: usize, degrees: f64, before: (DVec2, f64)) -> Vec<String> {
        let n = (degrees.abs() / 3.0).ceil().max(1.0) as usize;
        let mut steps = Vec::new();
        for i in 1..=n {
            let theta = (degrees * i as f64 / n as f64).to_radians();
            let (p, _) = self.handle_at(k, theta, before);
            steps.push(step::rotate(degrees / n as f64, 0));
            steps.push(step::drag_to(p, 3));
        }
        steps
    }
}

/// Where an axis of length `l` starting at `p` heading `heading` ends when bent evenly by
/// `theta` radians (a circular arc).
pub fn arc_end(p: DVec2, heading: f64, l: f64, theta: f64) -> DVec2 {
    let t = DVec2::from_angle(heading);
    if theta.abs() < 1e-12 {
        return p + t * l;
    }
    let r = l / theta;
    p + t * (r * theta.sin()) + t.perp() * (r * (1.0 - theta.cos()))
}

/// A piece's text with every `(x, y)` point's y moved by `dy` (vertices, proxy points; not
/// `out` directions), each new y rounded by `round_y`.
pub fn shift_piece_y(piece: &str, dy: f64, round_y: impl Fn(f64) -> f64) -> String {
    let mut out = String::new();
    let mut rest = piece;
    while let Some(open) = rest.find('(') {
        out.push_str(&rest[..open]);
        let close = open + rest[open..].find(')').unwrap_or(0);
        let inside = &rest[open + 1..close];
        let direction = out.ends_with("out ");
        let point = inside.split_once(',').and_then(|(x, y)| {
            let y = y.trim().parse::<f64>().ok()?;
            x.trim().parse::<f64>().is_ok().then_some((x.trim(), y))
        });
        match point {
            Some((x, y)) if !direction => {
                let _ = write!(out, "({x}, {})", round_y(y + dy));
            }
            _ => out.push_str(&rest[open..=close]),
        }
        rest = &rest[close + 1..];
    }
    out.push_str(rest);
    out
}

/// A main street (a stretchable chain of road segments with a `north_side` site) and a side
/// street hanging above it, whose free end welds onto the main street's side through a `tee`
/// (paper 5.1: merging, Fig. 7c) and is parted by a cut (Fig. 7d).
#[derive(Clone, Debug, PartialEq)]
pub struct JunctionGrammar {
    /// A segment's length and width.
    pub length: f64,
    pub width: f64,
    pub main: usize,
    pub side: usize,
    pub merge_distance: f64,
    /// Which main segment the side street is above, and how far above the main street's
    /// north edge its free end stops (more than the merge distance).
    pub target: usize,
    pub gap: f64,
}

impl JunctionGrammar {
    pub fn text(&self) -> String {
        let (l, w) = (self.length, self.width);
        // the north side is as wide as a street's end, centred on the segment
        let (a, b) = (
            strategy::round6((l - w) / 2.0),
            strategy::round6((l + w) / 2.0),
        );
        let h = w / 2.0;
        let stem = w / 2.0;
        let x = self.side_x();
        let top = self.top();
        format!(
            "solver {{\n    merge_distance = {md}\n}}\n\nsite type road_end\nsite type road_side docks road_end\n\n\
piece road {{\n    vertex s0 (0, {nh})\n    vertex s1 ({a}, {nh})\n    vertex s2 ({b}, {nh})\n    vertex s3 ({l}, {nh})\n\
    vertex n0 (0, {h})\n    vertex n1 ({a}, {h})\n    vertex n2 ({b}, {h})\n    vertex n3 ({l}, {h})\n\
    edges s0-s1-s2-s3-n3-n2-n1-n0-s0, n1-s1, n2-s2, s0-n1, s1-n2, s2-n3\n\
    site west: road_end [n0, s0] out (-1, 0)\n    site east: road_end [s3, n3] out (1, 0)\n\
    site north_side: road_side [n2, n1] out (0, 1)\n\
    polygon skinned fill #4b4f56 {{ (0, {nh}) ({l}, {nh}) ({l}, {h}) (0, {h}) }}\n}}\n\n\
piece tee extends road {{\n    vertex u_w ({a}, {th})\n    vertex u_e ({b}, {th})\n    edges n1-u_w-u_e-n2, n1-u_e\n\
    site north: road_end [u_e, u_w] out (0, 1)\n    axis west -> east\n}}\n\n\
stretch road from west to east {{ min 2 }}\n\nmerge road.east onto road.north_side into tee.north\n\n\
model {{\n    main = chain road x {main} at (0, 0)\n    side = chain road x {side} at ({x}, {top}) rotate -90\n}}\n",
            md = self.merge_distance,
            nh = -h,
            th = h + stem,
            main = self.main,
            side = self.side,
            x = strategy::round6(x),
        )
    }

    /// The main street's north edge (y).
    pub fn main_north(&self) -> f64 {
        self.width / 2.0
    }

    /// The x of the middle of the target segment's north side (where the side street's end
    /// must come down).
    pub fn side_x(&self) -> f64 {
        (self.target as f64 + 0.5) * self.length
    }

    /// The side street's top: its first segment's `west` end (rotated -90 degrees, element
    /// k spans y from top - (k + 1) l to top - k l, centred on `side_x`).
    pub fn top(&self) -> f64 {
        self.main_north() + self.gap + self.side as f64 * self.length
    }

    /// The side street's free end segment's centroid at rest.
    pub fn free_end(&self) -> DVec2 {
        DVec2::new(
            self.side_x(),
            self.top() - (self.side as f64 - 0.5) * self.length,
        )
    }

    /// Main segment `k`'s centroid at rest.
    pub fn main_centre(&self, k: usize) -> DVec2 {
        DVec2::new((k as f64 + 0.5) * self.length, 0.0)
    }

    /// Where the weld is once made: the tee's stem site.
    pub fn weld(&self) -> DVec2 {
        DVec2::new(self.side_x(), self.main_north() + self.width / 2.0)
    }
}

/// Proptest strategies for the bend and junction families.
pub mod family {
    use super::strategy::round;
    use super::*;
    use proptest::prelude::*;

    /// A street of 3 to 8 segments with a bent state of 10 to 90 degrees.
    pub fn bend() -> impl Strategy<Value = BendGrammar> {
        (
            (0.8f64..4.0, 0.25f64..0.7, 1usize..=3, any::<bool>()),
            3usize..=8,
            10.0f64..=90.0,
            (-30.0f64..30.0, -30.0f64..30.0),
            -180.0f64..180.0,
        )
            .prop_map(
                |((length, ratio, bays, mid_sites), count, angle, (x, y), heading)| BendGrammar {
                    segment: Element {
                        length: round(length),
                        height: round(length * ratio),
                        bays,
                        mid_sites,
                    },
                    count,
                    angle: round(angle),
                    origin: DVec2::new(round(x), round(y)),
                    heading: round(heading),
                },
            )
    }

    /// A main street and a side street above one of its segments.
    pub fn junction() -> impl Strategy<Value = JunctionGrammar> {
        (
            1.0f64..3.0,
            1.5f64..3.0,
            3usize..=10,
            2usize..=5,
            0.3f64..0.8,
            0.3f64..2.0,
        )
            .prop_flat_map(|(width, ratio, main, side, md, gap)| {
                (Just((width, ratio, main, side, md, gap)), 1..main - 1)
            })
            .prop_map(|((width, ratio, main, side, md, gap), target)| {
                let width = round(width);
                let merge_distance = round(md * width);
                JunctionGrammar {
                    length: round(width * ratio),
                    width,
                    main,
                    side,
                    merge_distance,
                    target,
                    gap: round(merge_distance + gap * width),
                }
            })
    }
}

/// More claims, on every family.
pub mod more {
    use super::*;

    /// Relaxation: a street bent and turned by its end, then let go of: at rest within 200
    /// frames.
    pub fn bend_relaxation(
        g: &BendGrammar,
        by: DVec2,
        degrees: f64,
        frames: u64,
    ) -> Result<(), String> {
        let mut run = Run::new(&g.text());
        let last = g.count - 1;
        run.step(&step::pin_at(g.centre(0)))
            .step(&step::grab_at(g.centre(last)));
        run.step(&step::drag(by, frames))
            .step(&step::rotate(degrees, frames));
        run.step(&step::hold(10)).step(&step::release());
        let pinned = held_centre(&run).unwrap_or(g.centre(0));
        run.step(&step::unpin_at(pinned)).step(&step::hold(200));
        check::at_rest(&run, 1e-6)
    }

    /// The centroid of the first instance some handle holds.
    pub fn held_centre(run: &Run) -> Option<DVec2> {
        run.asm.handles().iter().find_map(|h| {
            let id = h.held_instance()?;
            let i = run.asm.data().instances.iter().position(|x| x.id == id)?;
            run.asm.instance_centroid(i)
        })
    }

    /// One or two segments of a street (not its ends, which are held) and the way each bends.
    pub fn turns(g: &BendGrammar, picks: (usize, usize, bool, bool, bool)) -> Vec<(usize, f64)> {
        let (a, b, two, left_a, left_b) = picks;
        let inner = g.count - 2;
        let first = 1 + a % inner;
        let angle = |left: bool| if left { g.angle } else { -g.angle };
        if two && first < inner {
            let second = first + 1 + b % (inner - first);
            vec![(first, angle(left_a)), (second, angle(left_b))]
        } else {
            vec![(first, angle(left_a))]
        }
    }

    /// The script of [`reachability`]: the street's first segment pinned, its last grabbed,
    /// each of `turns` bent in turn (held 30 frames after each), then held 60 frames.
    pub fn reach_script(g: &BendGrammar, turns: &[(usize, f64)]) -> Vec<String> {
        let mut steps = vec![
            step::pin_at(g.centre(0)),
            step::grab_at(g.centre(g.count - 1)),
        ];
        let mut done: Vec<(usize, f64)> = Vec::new();
        for &(k, degrees) in turns {
            let before = g.start_of(k, &done);
            steps.extend(g.bend_steps(k, degrees, before));
            steps.push(step::hold(30));
            done.push((k, degrees.to_radians()));
        }
        steps.push(step::hold(60));
        steps
    }

    /// Reachability (Fig. 4): segment `turns[0].0` led along the path on which it bends evenly
    /// by `turns[0].1` degrees, then (if any) `turns[1]` from where the first left the street:
    /// held, the model is at rest in some assignment of states (energy at most
    /// 1e-4 x size^2, max |strain| at most 0.02).
    pub fn reachability(g: &BendGrammar, turns: &[(usize, f64)]) -> Result<(), String> {
        let mut run = Run::new(&g.text());
        run.steps(&reach_script(g, turns));
        let (e, size, strain) = (run.energy(), run.size(), run.max_strain());
        if e <= 1e-4 * size * size && strain <= 0.02 {
            Ok(())
        } else {
            check::verdict(
                vec![format!(
                    "states {:?} after bending {turns:?}: energy {e:.3e} (want <= {:.3e}), max |strain| {strain:.4} (want <= 0.02)",
                    run.states("road"),
                    1e-4 * size * size
                )],
                &run,
            )
        }
    }

    /// Rigid motion (paper 4.1): with nothing pinned, the model grabbed by one instance and
    /// moved by `by`, turned by `degrees` about the grab: it ends as its rest pose moved
    /// rigidly, at rest, and no rule fires.
    pub fn rigid(
        text: &str,
        grab: DVec2,
        by: DVec2,
        degrees: f64,
        frames: u64,
    ) -> Result<(), String> {
        let mut run = Run::new(text);
        run.step(&step::grab_at(grab));
        let handle = run
            .session
            .grabbed()
            .and_then(|h| run.asm.handle(h))
            .cloned();
        let Some(handle) = handle else {
            return check::verdict(vec!["nothing to grab".into()], &run);
        };
        let centre = handle.target_centre();
        let turn = DVec2::from_angle(degrees.to_radians());
        let want: Vec<DVec2> = (run.asm.data().positions.iter())
            .map(|&p| centre + by + turn.rotate(p - centre))
            .collect();
        run.step(&step::drag(by, frames))
            .step(&step::rotate(degrees, frames));
        run.step(&step::hold(60));
        let got = &run.asm.data().positions;
        let size = run.size();
        let off = (got.iter().zip(&want))
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f64::max);
        let (e, events) = (run.energy(), run.events());
        // a rotation converges to its rest over the held frames; a translation is exact
        let (off_bound, e_bound) = if degrees == 0.0 {
            (1e-9 * size, 1e-12 * size * size)
        } else {
            (1e-3 * size, 1e-6 * size * size)
        };
        if off <= off_bound && e <= e_bound && events == 0 {
            Ok(())
        } else {
            check::verdict(
                vec![format!(
                    "moved by {by:?} and turned {degrees} degrees: a vertex {off:.3e} off the rigid motion (want <= {off_bound:.1e}), energy {e:.3e} (want <= {e_bound:.1e}), {events} rule events"
                )],
                &run,
            )
        }
    }

    /// Hysteresis (paper 4.3): held at `factor`, a hand that wavers by `amplitude` (in the
    /// chain's direction) adds at most 2 rule events to those of a steady hand.
    pub fn hysteresis(pull: &Pull, amplitude: f64) -> Result<(), String> {
        let session = |jitter: bool| {
            let mut run = pull.start();
            run.step(&pull.drag(1.0, pull.factor, 60))
                .step(&step::hold(30));
            let (_, _, dir) = pull.ends();
            if jitter {
                for _ in 0..50 {
                    run.step(&step::drag(dir * amplitude, 2));
                    run.step(&step::drag(-dir * amplitude, 2));
                }
            } else {
                run.step(&step::hold(200));
            }
            run
        };
        let (plain, jittered) = (session(false), session(true));
        if jittered.events() <= plain.events() + 2 {
            Ok(())
        } else {
            check::verdict(
                vec![format!(
                    "{} events with a hand wavering by {amplitude:.3} m, {} steady",
                    jittered.events(),
                    plain.events()
                )],
                &jittered,
            )
        }
    }

    /// Merge and cut (paper 5.1, Fig. 7c, 7d): the side street's end brought onto the main
    /// street welds (one merge); cut, it stays cut while its sites stay near; parted beyond the
    /// merge distance and brought back, it welds again.
    pub fn merge_and_cut(j: &JunctionGrammar) -> Result<(), String> {
        let mut run = Run::new(&j.text());
        let last = j.main - 1;
        run.step(&step::pin_at(j.main_centre(0)))
            .step(&step::pin_at(j.main_centre(last)))
            .step(&step::grab_at(j.free_end()));
        run.step(&step::drag(DVec2::new(0.0, -j.gap), 40))
            .step(&step::hold(10));
        let mut why = Vec::new();
        if run.fired(RuleKind::Merge) != 1 {
            why.push(format!(
                "{} merges when brought onto the main street (want 1)",
                run.fired(RuleKind::Merge)
            ));
        }
        run.step(&step::cut_at(j.weld())).step(&step::hold(30));
        if run.fired(RuleKind::Cut) != 1 {
            why.push(format!(
                "{} cuts at the weld (want 1)",
                run.fired(RuleKind::Cut)
            ));
        }
        if run.fired(RuleKind::Merge) != 1 {
            why.push("welded again right after the cut".into());
        }
        let part = j.merge_distance + j.width;
        run.step(&step::drag(DVec2::new(0.0, part), 20))
            .step(&step::hold(5));
        run.step(&step::drag(DVec2::new(0.0, -part), 20))
            .step(&step::hold(10));
        if run.fired(RuleKind::Merge) != 2 {
            why.push(format!(
                "{} merges after parting and coming back (want 2)",
                run.fired(RuleKind::Merge)
            ));
        }
        check::verdict(why, &run)
    }

    /// The same script twice gives the same positions, bit for bit, and the same events.
    pub fn deterministic(text: &str, steps: &[String]) -> Result<(), String> {
        let mut a = Run::new(text);
        let mut b = Run::new(text);
        a.steps(steps);
        b.steps(steps);
        let same = (a.asm.data().positions.iter().zip(&b.asm.data().positions))
            .all(|(p, q)| p.x.to_bits() == q.x.to_bits() && p.y.to_bits() == q.y.to_bits())
            && a.asm.data().positions.len() == b.asm.data().positions.len()
            && a.session.rule_log() == b.session.rule_log();
        if same {
            Ok(())
        } else {
            check::verdict(vec!["two runs of one script differ".into()], &a)
        }
    }
}

/// Paper 5.2's claims on the norm.
pub mod norm {
    use super::*;

    /// With p = 0.5, a chain pulled steadily (over `frames`) to one element longer than at
    /// rest has inserted an element by the time it gets there (least squares needs about 1.5
    /// times the length, the paper says).
    pub fn sub_l1_inserts_early(g: &ChainGrammar, frames: u64) -> Result<(), String> {
        let n = g.count as f64;
        let pull = Pull {
            // the property is the norm's: no `max` to stop the insertion
            grammar: ChainGrammar {
                norm: 0.5,
                max: None,
                ..g.clone()
            },
            factor: (n + 1.0) / n,
            frames,
            reversed: false,
        };
        let mut run = pull.start();
        run.step(&pull.drag(1.0, pull.factor, frames));
        let inserted = run.fired(RuleKind::Stretch);
        if inserted >= 1 {
            Ok(())
        } else {
            check::verdict(
                vec![format!("no element inserted at {n} + 1 elements' length")],
                &run,
            )
        }
    }

    /// With p = 1, the first gap opens next to a handle: the element that stretches first
    /// (one of the two the first stretch rewrites) is held or beside a held one.
    pub fn l1_gap_opens_next_to_a_handle(g: &ChainGrammar, reversed: bool) -> Result<(), String> {
        let pull = Pull {
            grammar: ChainGrammar {
                norm: 1.0,
                max: None,
                ..g.clone()
            },
            factor: 2.0,
            frames: 120,
            reversed,
        };
        let mut run = pull.start();
        let held: Vec<u64> = (run.asm.handles().iter())
            .filter_map(|h| h.held_instance())
            .collect();
        // the chain's element ids in order, before anything is inserted
        let data = run.asm.data();
        let order: Vec<u64> = data.chains[0]
            .instances
            .iter()
            .map(|&i| data.instances[i].id)
            .collect();
        let index = |id: &u64| order.iter().position(|x| x == id);
        let held_at: Vec<usize> = held.iter().filter_map(index).collect();
        run.step(&pull.drag(1.0, pull.factor, pull.frames));
        let first = run
            .session
            .rule_log()
            .iter()
            .find(|e| e.kind == RuleKind::Stretch);
        let beside =
            |id: &u64| index(id).is_some_and(|k| held_at.iter().any(|&h| h.abs_diff(k) <= 1));
        match first {
            Some(e) if e.instances.iter().take(2).any(beside) => Ok(()),
            Some(e) => check::verdict(
                vec![format!(
                    "the first gap opened between elements {:?}, the held ones are {held_at:?}: {}",
                    e.instances
                        .iter()
                        .take(2)
                        .filter_map(index)
                        .collect::<Vec<_>>(),
                    e.detail
                )],
                &run,
            ),
            None => check::verdict(vec!["no element inserted at twice the length".into()], &run),
        }
    }
}
