//! Nearest free docking sites for the merge rule: a uniform hash grid with cells as large as
//! the merge distance, so that a query looks at the 3 x 3 cells around a point only. Building
//! the grid is O(targets) and each query O(1) for bounded site density, so one frame's merge
//! check is O(free sites).

use std::collections::HashMap;

use clay_dsl::compiled::InstanceSite;
use glam::DVec2;

/// Free sites bucketed by position.
#[derive(Clone, Debug)]
pub struct SiteGrid {
    cell: f64,
    cells: HashMap<(i64, i64), Vec<(InstanceSite, DVec2)>>,
}

impl SiteGrid {
    /// A grid for queries of radius up to `cell` (non-positive or non-finite cells are
    /// clamped to a millimetre so that lookups stay finite).
    pub fn new(cell: f64) -> Self {
        let cell = if cell.is_finite() && cell > 1e-3 {
            cell
        } else {
            1e-3
        };
        Self {
            cell,
            cells: HashMap::new(),
        }
    }

    fn key(&self, p: DVec2) -> (i64, i64) {
        // Saturating float -> int casts keep far-away points from wrapping.
        (
            (p.x / self.cell).floor() as i64,
            (p.y / self.cell).floor() as i64,
        )
    }

    pub fn insert(&mut self, site: InstanceSite, at: DVec2) {
        if at.is_finite() {
            self.cells.entry(self.key(at)).or_default().push((site, at));
        }
    }

    /// The nearest site within `radius` (at most the cell size) of `at` that `accept`s,
    /// with its distance.
    pub fn nearest(
        &self,
        at: DVec2,
        radius: f64,
        mut accept: impl FnMut(InstanceSite) -> bool,
    ) -> Option<(InstanceSite, f64)> {
        if !at.is_finite() {
            return None;
        }
        let (cx, cy) = self.key(at);
        let mut best: Option<(InstanceSite, f64)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                let Some(list) = self
                    .cells
                    .get(&(cx.saturating_add(dx), cy.saturating_add(dy)))
                else {
                    continue;
                };
                for &(s, p) in list {
                    let d = p.distance(at);
                    if d <= radius && best.is_none_or(|(_, bd)| d < bd) && accept(s) {
                        best = Some((s, d));
                    }
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_nearest_site_within_the_radius_only() {
        let mut g = SiteGrid::new(0.5);
        let s = |i| InstanceSite {
            instance: i,
            site: 0,
        };
        g.insert(s(0), DVec2::new(0.0, 0.0));
        g.insert(s(1), DVec2::new(0.3, 0.0));
        g.insert(s(2), DVec2::new(5.0, 5.0));
        let hit = g.nearest(DVec2::new(0.4, 0.1), 0.5, |_| true).unwrap();
        assert_eq!(hit.0, s(1));
        let hit = g.nearest(DVec2::new(0.4, 0.1), 0.5, |x| x != s(1)).unwrap();
        assert_eq!(hit.0, s(0));
        assert!(g.nearest(DVec2::new(4.0, 4.0), 0.5, |_| true).is_none());
    }
}
