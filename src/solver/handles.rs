//! The handles as the frame uses them, and the pose each pass starts from: their targets
//! gathered per vertex, the displayed pose with the components they move rigidly moved
//! ([`follow`]; the frame's first step), the same again on the rules' layout when they
//! rewrote the structure, the held vertices snapped to their targets where pass 1 starts,
//! and the factors by which pass 1 weighs the stretch parts they hold as outliers.
//!
//! A file of its own because these are the frame's first step and its restart after the
//! rules: an `impl Solver` block over the state of `state.rs`, imported from that sibling
//! rather than from `mod.rs`, so no child imports its parent.

use clay_dsl::compiled::{Part, PartKind};
use glam::DVec2;

use super::follow;
use super::report::SolverError;
use super::state::Solver;
use crate::assembly::{Assembly, Handle, HandleKind};

impl Solver {
    /// The pose the frame starts from: the displayed one, every component whose held
    /// vertices all moved by one rigid motion moved by it ([`Solver::follow_handles`]), after
    /// the handles' targets are gathered, the free components found and the components'
    /// sizes measured; the last frame's evaluation ([`Start`](super::state::Start)) is kept
    /// only if it still holds for this pose.
    pub(super) fn warm_start(&mut self, asm: &Assembly) -> Result<Vec<DVec2>, SolverError> {
        let cfg = self.config;
        let n = asm.data().positions.len();
        self.gather_handles(asm.handles(), n);
        self.components
            .free(&self.work.handle_count, &mut self.free_components);
        // Position buffers live in `work` between frames (taken here, put back at the end; an
        // error path just drops them and the next frame reallocates).
        let mut warm = std::mem::take(&mut self.work.warm);
        warm.clear();
        warm.extend_from_slice(&asm.data().positions);
        if warm.iter().any(|p| !p.is_finite()) {
            return Err(SolverError(
                "the warm start has non-finite positions".into(),
            ));
        }
        self.units.measure(&self.components, &warm);
        self.follow_handles(&mut warm, cfg.tolerance);
        let generation = self.generation.unwrap_or(u64::MAX);
        let start_key = Some((generation, cfg, 0));
        if !self.work.start_holds(start_key, &warm, &asm.data().parts) {
            self.work.start.valid = None;
        }
        Ok(warm)
    }

    /// After the rules rewrote the structure between the passes: the state rebuilt for the
    /// new one ([`Solver::prepare`]), its handles' targets, free components and sizes, and
    /// `warm` the rules' layout, where pass 2 starts; no evaluation of it is kept.
    pub(super) fn restart(
        &mut self,
        asm: &Assembly,
        warm: &mut Vec<DVec2>,
    ) -> Result<(), SolverError> {
        self.prepare(asm)?;
        let n = asm.data().positions.len();
        self.gather_handles(asm.handles(), n);
        self.components
            .free(&self.work.handle_count, &mut self.free_components);
        warm.clear();
        warm.extend_from_slice(&asm.data().positions);
        if warm.iter().any(|p| !p.is_finite()) {
            return Err(SolverError("a rule laid out non-finite positions".into()));
        }
        self.units.measure(&self.components, warm);
        self.work.start.valid = None;
        Ok(())
    }

    /// Per part, the factor of its term in the sparse norm: for a stretch part holding a
    /// vertex of a grab, [`SolverConfig::handle_outlier`] to the power `2 - p`; of a pin only,
    /// the square root of that (the handle the user moves is the likelier place for the gap:
    /// with a pin at one end and a grab at the other, an evenly stretched chain would
    /// otherwise split its stretch between the two ends, where neither half switches); 1 for
    /// every other part.
    pub(super) fn outlier_factors(&mut self, parts: &[Part], handles: &[Handle]) {
        let cfg = self.config;
        let grab = cfg.handle_outlier.clamp(1e-3, 1.0).powf(2.0 - cfg.norm);
        let pin = grab.sqrt();
        let w = &mut self.work;
        // per vertex, the smallest factor of the handles holding it (the `rhs` buffer is
        // free until the first solve)
        let at = &mut w.rhs;
        at.clear();
        at.resize(w.handle_count.len(), 1.0);
        for h in handles {
            let factor = match h.kind {
                HandleKind::Grab => grab,
                HandleKind::Pin => pin,
            };
            for &v in &h.vertices {
                if let Some(a) = at.get_mut(v) {
                    *a = a.min(factor);
                }
            }
        }
        w.outlier.clear();
        w.outlier.extend(parts.iter().map(|part| {
            if matches!(part.kind, PartKind::Stretch { .. }) {
                part.vertices.iter().map(|&v| at[v]).fold(1.0, f64::min)
            } else {
                1.0
            }
        }));
    }

    /// Puts every held vertex of `pose` where its handles now want it (their mean target);
    /// notes the largest move in `work.snapped_moved`.
    pub(super) fn snap_held(&mut self, pose: &mut [DVec2]) {
        let w = &mut self.work;
        let mut moved: f64 = 0.0;
        for ((p, &count), &sum) in pose.iter_mut().zip(&w.handle_count).zip(&w.handle_sum) {
            if count > 0.0 {
                let t = sum / count;
                moved = moved.max((t - *p).length());
                *p = t;
            }
        }
        w.snapped_moved = moved;
    }

    /// Moves every component whose held vertices all moved by one rigid motion by that
    /// motion ([`follow`]): the displayed pose `warm`.
    pub(super) fn follow_handles(&mut self, warm: &mut [DVec2], tolerance: f64) {
        let w = &self.work;
        let held: Vec<bool> = w.handle_count.iter().map(|&c| c > 0.0).collect();
        if !held.iter().any(|&h| h) {
            return;
        }
        let target: Vec<DVec2> = w
            .handle_count
            .iter()
            .zip(&w.handle_sum)
            .map(|(&c, &s)| if c > 0.0 { s / c } else { DVec2::ZERO })
            .collect();
        let units = &self.units;
        let motions = follow::motions(&self.components, warm, &held, &target, |c| {
            tolerance * units.size(c)
        });
        if motions.iter().all(Option::is_none) {
            return;
        }
        follow::move_points(&self.components, &motions, warm);
    }

    pub(super) fn gather_handles(&mut self, handles: &[Handle], n: usize) {
        let w = &mut self.work;
        w.handle_count.clear();
        w.handle_count.resize(n, 0.0);
        w.handle_sum.clear();
        w.handle_sum.resize(n, DVec2::ZERO);
        for h in handles {
            for (k, &v) in h.vertices.iter().enumerate() {
                if v < n {
                    let t = h.target(k);
                    if t.is_finite() {
                        w.handle_count[v] += 1.0;
                        w.handle_sum[v] += t;
                    }
                }
            }
        }
    }
}
