//! Each connected component's own units: of length, its mean rest edge (fixed per assembly
//! generation) and its size (the diagonal of its bounding box, measured per frame); of
//! stiffness, its parts' mean IRLS weight (per iteration). The solver's tolerances are
//! fractions of the lengths, judged vertex by vertex against the vertex's own component, and
//! a handle's weight is a multiple of its component's mean weight, so a claim about one part of a model does not depend on how large, or how
//! far away, the rest of the model is (a chain 700 m away with elements ten times as long
//! loosened pass 1's tolerance for a 13-brick wall and left it with 6 bricks instead of 5).

use clay_dsl::compiled::Part;
use glam::DVec2;

use super::follow::Components;

/// Per component, its units of length (see the module doc).
#[derive(Clone, Debug, Default)]
pub struct Units {
    /// Per component, the mean length of its parts' edges in their active rest states.
    edge: Vec<f64>,
    /// Per component, its bounding box's diagonal in the last measured pose.
    size: Vec<f64>,
    /// Per part, its component (its first vertex's).
    part_component: Vec<u32>,
    /// Per component, the mean weight of its edges ([`Units::weigh`]).
    weight: Vec<f64>,
}

/// What a unit is when a component has nothing to measure (no edges, or a single point).
const FALLBACK: f64 = 1.0;
/// The smallest size a component is given (a component at a point still has a unit).
const SMALLEST_SIZE: f64 = 1e-9;

impl Units {
    /// The mean rest edge of every component of `components` (its parts' edges in their
    /// active states; a part belongs to its first vertex's component).
    pub fn build(parts: &[Part], components: &Components) -> Self {
        let mut sums = vec![(0.0f64, 0usize); components.count()];
        let part_component = parts
            .iter()
            .map(|p| p.vertices.first().map_or(0, |&v| components.of(v) as u32))
            .collect();
        for part in parts {
            let (Some(rest), Some(&first)) = (part.states.get(part.active), part.vertices.first())
            else {
                continue;
            };
            let Some(slot) = sums.get_mut(components.of(first)) else {
                continue;
            };
            for e in &part.edges {
                if let (Some(a), Some(b)) = (rest.positions.get(e[0]), rest.positions.get(e[1])) {
                    slot.0 += (*a - *b).length();
                    slot.1 += 1;
                }
            }
        }
        let edge = sums
            .iter()
            .map(|&(sum, count)| {
                let mean = sum / count.max(1) as f64;
                if mean.is_finite() && mean > 0.0 {
                    mean
                } else {
                    FALLBACK
                }
            })
            .collect();
        Self {
            edge,
            size: vec![FALLBACK; components.count()],
            part_component,
            weight: vec![FALLBACK; components.count()],
        }
    }

    /// Measures every component's size in `pose` (one position per vertex).
    pub fn measure(&mut self, components: &Components, pose: &[DVec2]) {
        let count = components.count();
        let mut lo = vec![DVec2::splat(f64::INFINITY); count];
        let mut hi = vec![DVec2::splat(f64::NEG_INFINITY); count];
        for (v, p) in pose.iter().enumerate() {
            let c = components.of(v);
            lo[c] = lo[c].min(*p);
            hi[c] = hi[c].max(*p);
        }
        self.size.clear();
        self.size.extend(lo.iter().zip(&hi).map(|(lo, hi)| {
            let d = (*hi - *lo).length();
            if d.is_finite() {
                d.max(SMALLEST_SIZE)
            } else {
                FALLBACK
            }
        }));
    }

    /// The smallest component's mean rest edge: the unit of a judgement made of the whole
    /// model at once (whether its energy is at rest), taken where it is strictest.
    pub fn smallest_edge(&self) -> f64 {
        let m = self.edge.iter().copied().fold(f64::INFINITY, f64::min);
        if m.is_finite() { m } else { FALLBACK }
    }

    /// The largest move from `a` to `b` of any vertex, in its component's rest edges.
    pub fn max_move_in_edges(&self, components: &Components, a: &[DVec2], b: &[DVec2]) -> f64 {
        max_scaled_move(components, &self.edge, a, b)
    }

    /// The largest move from `a` to `b` of any vertex, in its component's sizes (as last
    /// [`Units::measure`]d).
    pub fn max_move_in_sizes(&self, components: &Components, a: &[DVec2], b: &[DVec2]) -> f64 {
        max_scaled_move(components, &self.size, a, b)
    }

    /// Takes every component's mean edge weight from the parts' weights (`part_weights`, one
    /// per part, counted once per edge of the part: `part_edges`), each sum made in part and
    /// edge order (the same bits on any thread count).
    pub fn weigh(&mut self, part_edges: &[usize], part_weights: &[f64]) {
        let mut sums = vec![(0.0f64, 0usize); self.weight.len()];
        for ((&n, &w), &c) in part_edges
            .iter()
            .zip(part_weights)
            .zip(&self.part_component)
        {
            if let Some(slot) = sums.get_mut(c as usize) {
                for _ in 0..n {
                    slot.0 += w;
                }
                slot.1 += n;
            }
        }
        for (weight, (sum, count)) in self.weight.iter_mut().zip(sums) {
            let m = sum / count.max(1) as f64;
            *weight = if count > 0 && m.is_finite() && m > 0.0 {
                m
            } else {
                FALLBACK
            };
        }
    }

    /// Component `c`'s mean edge weight (as last [`Units::weigh`]ed).
    pub fn weight(&self, c: usize) -> f64 {
        self.weight.get(c).copied().unwrap_or(FALLBACK)
    }

    /// Component `c`'s size (as last [`Units::measure`]d).
    pub fn size(&self, c: usize) -> f64 {
        self.size.get(c).copied().unwrap_or(FALLBACK)
    }
}

fn max_scaled_move(components: &Components, unit: &[f64], a: &[DVec2], b: &[DVec2]) -> f64 {
    a.iter()
        .zip(b)
        .enumerate()
        .map(|(v, (p, q))| {
            let u = unit.get(components.of(v)).copied().unwrap_or(FALLBACK);
            p.distance(*q) / u
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clay_dsl::compiled::{PartKind, PartState};

    fn part(vertices: Vec<usize>, rest: Vec<DVec2>) -> Part {
        let edges = (0..vertices.len() - 1).map(|k| [k, k + 1]).collect();
        Part {
            kind: PartKind::Piece { instance: 0 },
            vertices,
            edges,
            states: vec![PartState {
                name: "rest".into(),
                positions: rest,
            }],
            active: 0,
        }
    }

    #[test]
    fn each_component_is_measured_in_its_own_units() {
        // a unit square's edge (component 0) and a 10 m bar far away (component 1)
        let parts = vec![
            part(vec![0, 1], vec![DVec2::ZERO, DVec2::X]),
            part(vec![2, 3], vec![DVec2::ZERO, DVec2::X * 10.0]),
        ];
        let pose = [
            DVec2::ZERO,
            DVec2::X,
            DVec2::new(700.0, 0.0),
            DVec2::new(710.0, 0.0),
        ];
        let components = Components::build(&parts, 4);
        let mut units = Units::build(&parts, &components);
        units.measure(&components, &pose);
        assert_eq!(units.smallest_edge(), 1.0);
        assert_eq!((units.size(0), units.size(1)), (1.0, 10.0));
        let mut moved = pose;
        moved[1].y += 0.5;
        moved[3].y += 1.0;
        // 0.5 of a 1 m edge beats 1 of a 10 m one
        assert_eq!(units.max_move_in_edges(&components, &pose, &moved), 0.5);
        assert_eq!(units.max_move_in_sizes(&components, &pose, &moved), 0.5);
    }
}
