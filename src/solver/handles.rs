//! The handles as the frame uses them: their targets gathered per vertex, the components
//! they move rigidly ([`follow`]), the held vertices snapped to their targets where pass 1
//! starts, and the factors by which pass 1 weighs the stretch parts they hold as outliers.
//!
//! One job of the frame in its own `impl Solver` block, as `mod.rs` lists them.

use clay_dsl::compiled::{Part, PartKind};
use glam::DVec2;

use super::follow;
use super::state::Solver;
use crate::assembly::{Handle, HandleKind};

impl Solver {
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
