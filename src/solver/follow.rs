//! Rigid following (paper 4.1: the energy is invariant under rigid motions): a connected
//! component whose held vertices all moved by one rigid motion since the last frame is moved by
//! that motion as a whole before the frame iterates. If the last frame was at rest for the old
//! targets, the moved pose is at rest for the new ones (same energy, same handle terms), so a
//! model turned or carried with one hand turns or moves rigidly at once, instead of waiting
//! for the local/global alternation to carry the rotation part by part through the model
//! (ARAP's slowest mode, hundreds of iterations on a castle's ring of walls). A component held
//! at places that move differently (a pin and a drag) is left alone: there the frame's
//! iterations find the deformation.

use clay_dsl::compiled::Part;
use glam::DVec2;

use crate::fit::{RigidMotion, rigid_motion};

/// The connected components of the vertex graph (parts sharing a vertex are connected),
/// built once per assembly generation.
#[derive(Clone, Debug, Default)]
pub struct Components {
    /// Per vertex, its component.
    of: Vec<u32>,
    count: usize,
    /// Per component, its vertices in ascending order (compressed: component `c`'s are
    /// `members[start[c]..start[c + 1]]`).
    start: Vec<u32>,
    members: Vec<u32>,
}

impl Components {
    pub fn build(parts: &[Part], vertex_count: usize) -> Self {
        let mut parent: Vec<usize> = (0..vertex_count).collect();
        fn root(parent: &mut [usize], mut x: usize) -> usize {
            while parent[x] != x {
                parent[x] = parent[parent[x]];
                x = parent[x];
            }
            x
        }
        for part in parts {
            let mut vs = part.vertices.iter().copied().filter(|&v| v < vertex_count);
            if let Some(first) = vs.next() {
                for v in vs {
                    let (a, b) = (root(&mut parent, first), root(&mut parent, v));
                    parent[a] = b;
                }
            }
        }
        let mut index = vec![u32::MAX; vertex_count];
        let mut of = Vec::with_capacity(vertex_count);
        let mut count = 0;
        for v in 0..vertex_count {
            let r = root(&mut parent, v);
            if index[r] == u32::MAX {
                index[r] = count as u32;
                count += 1;
            }
            of.push(index[r]);
        }
        let mut start = vec![0u32; count + 1];
        for &c in &of {
            start[c as usize + 1] += 1;
        }
        for c in 0..count {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut members = vec![0u32; vertex_count];
        for (v, &c) in of.iter().enumerate() {
            // the solver takes no model with more vertices than `u32` counts
            members[fill[c as usize] as usize] = v as u32;
            fill[c as usize] += 1;
        }
        Self {
            of,
            count,
            start,
            members,
        }
    }

    /// The vertices of component `c`, ascending.
    pub fn members(&self, c: usize) -> &[u32] {
        &self.members[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// The component of vertex `v`.
    pub fn of(&self, v: usize) -> usize {
        self.of[v] as usize
    }

    pub fn count(&self) -> usize {
        self.count
    }

    /// Into `free`, the components (ascending) with no vertex whose handle count is above 0
    /// (`handle_count` per vertex).
    pub fn free(&self, handle_count: &[f64], free: &mut Vec<usize>) {
        let mut held = vec![false; self.count];
        for (&c, &h) in self.of.iter().zip(handle_count) {
            if h > 0.0 {
                held[c as usize] = true;
            }
        }
        free.clear();
        free.extend((0..self.count).filter(|&c| !held[c]));
    }
}

/// Per component, the rigid motion taking its held vertices from `positions` onto their
/// targets (`target[v]` for every `v` with `held[v]`), when there is one within its
/// `tolerance(c)` (metres, the largest distance of a held vertex from the moved position) and
/// it moves something by more than that; `None` for components with nothing held, held at
/// places that moved differently, or not moved.
pub fn motions(
    components: &Components,
    positions: &[DVec2],
    held: &[bool],
    target: &[DVec2],
    tolerance: impl Fn(usize) -> f64,
) -> Vec<Option<RigidMotion>> {
    let mut from: Vec<Vec<DVec2>> = vec![Vec::new(); components.count()];
    let mut to: Vec<Vec<DVec2>> = vec![Vec::new(); components.count()];
    for (v, (&p, &h)) in positions.iter().zip(held).enumerate() {
        if h {
            let c = components.of(v);
            from[c].push(p);
            to[c].push(target[v]);
        }
    }
    from.iter()
        .zip(&to)
        .enumerate()
        .map(|(c, (from, to))| {
            let tolerance = tolerance(c);
            let motion = rigid_motion(from, to)?;
            let fits = from
                .iter()
                .zip(to)
                .all(|(&a, &b)| motion.apply(a).distance(b) <= tolerance);
            let moves = from
                .iter()
                .zip(to)
                .any(|(&a, &b)| a.distance(b) > tolerance);
            (fits && moves).then_some(motion)
        })
        .collect()
}

/// Moves every vertex of a component that has a motion by it.
pub fn move_points(components: &Components, motions: &[Option<RigidMotion>], points: &mut [DVec2]) {
    for (v, p) in points.iter_mut().enumerate() {
        if let Some(m) = &motions[components.of(v)] {
            *p = m.apply(*p);
        }
    }
}
