//! The rest layout of an assembly: every part in its active rest state, laid part by part
//! across shared vertices, each component then placed rigidly where its handles hold it (or
//! where it lies now). A start the solver can try when the local/global iteration has settled
//! into a fold it cannot leave (`docs/solver.md`, "Folds").

use std::collections::VecDeque;

use clay_dsl::compiled::Part;
use glam::DVec2;

use super::follow::Components;
use super::local::VertexParts;
use crate::fit::rigid_motion;

/// Every vertex of `parts` laid at rest: parts are visited breadth first across shared
/// vertices from the lowest-numbered part of each component, each placed by the rigid motion
/// that best takes its active rest positions onto its vertices laid so far (onto `pose` for a
/// component's first part); the vertices it brings are laid there. Each component is then
/// moved rigidly onto its held vertices' targets (`held[v] > 0`, target `target[v] /
/// held[v]`) when it has two or more, else onto `pose`. Vertices no part covers keep `pose`.
pub fn rest_layout(
    parts: &[Part],
    vertex_parts: &VertexParts,
    components: &Components,
    pose: &[DVec2],
    held: &[f64],
    target: &[DVec2],
) -> Vec<DVec2> {
    let mut laid = pose.to_vec();
    let mut placed = vec![false; pose.len()];
    let mut visited = vec![false; parts.len()];
    let mut queue = VecDeque::new();
    let (mut from, mut to) = (Vec::new(), Vec::new());
    for seed in 0..parts.len() {
        if visited[seed] {
            continue;
        }
        visited[seed] = true;
        queue.push_back(seed);
        while let Some(pi) = queue.pop_front() {
            let part = &parts[pi];
            let Some(rest) = part.states.get(part.active) else {
                continue;
            };
            let m = part.vertices.len().min(rest.positions.len());
            from.clear();
            to.clear();
            for k in 0..m {
                let v = part.vertices[k];
                if placed[v] {
                    from.push(rest.positions[k]);
                    to.push(laid[v]);
                }
            }
            // with one point laid the part hangs on it, turned as the pose has it
            let anchor = (from.len() == 1)
                .then(|| (0..m).find(|&k| placed[part.vertices[k]]))
                .flatten();
            if from.len() < 2 {
                from.clear();
                to.clear();
                for k in 0..m {
                    from.push(rest.positions[k]);
                    to.push(pose[part.vertices[k]]);
                }
            }
            if let Some(motion) = rigid_motion(&from, &to) {
                let shift = anchor.map_or(DVec2::ZERO, |k| {
                    laid[part.vertices[k]] - motion.apply(rest.positions[k])
                });
                for k in 0..m {
                    let v = part.vertices[k];
                    if !placed[v] {
                        laid[v] = motion.apply(rest.positions[k]) + shift;
                        placed[v] = true;
                    }
                }
            }
            for &v in &part.vertices[..m] {
                for &q in vertex_parts.of(v) {
                    if !visited[q] {
                        visited[q] = true;
                        queue.push_back(q);
                    }
                }
            }
        }
    }
    place_components(components, &placed, pose, held, target, &mut laid);
    laid
}

/// Moves each component of `laid` rigidly onto its held targets, or onto `pose`.
fn place_components(
    components: &Components,
    placed: &[bool],
    pose: &[DVec2],
    held: &[f64],
    target: &[DVec2],
    laid: &mut [DVec2],
) {
    let (mut from, mut to) = (Vec::new(), Vec::new());
    for c in 0..components.count() {
        let members = components.members(c);
        from.clear();
        to.clear();
        for &v in members {
            let v = v as usize;
            if placed[v] && held.get(v).is_some_and(|&h| h > 0.0) {
                from.push(laid[v]);
                to.push(target[v] / held[v]);
            }
        }
        if from.len() < 2 {
            from.clear();
            to.clear();
            for &v in members {
                let v = v as usize;
                if placed[v] {
                    from.push(laid[v]);
                    to.push(pose[v]);
                }
            }
        }
        let Some(motion) = rigid_motion(&from, &to) else {
            continue;
        };
        for &v in members {
            let v = v as usize;
            if placed[v] {
                laid[v] = motion.apply(laid[v]);
            }
        }
    }
}
