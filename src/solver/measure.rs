//! Measures of an assembly's pose that tests, summaries and benchmarks read: the elastic
//! energy (Eq. 4), edge strains, and bounding boxes.

use glam::DVec2;

use super::config::{SolverConfig, cone_cosine};
use super::local;
use crate::assembly::Assembly;

/// Length of the diagonal of the positions' bounding box (0 for no or non-finite positions).
pub fn bbox_diagonal(positions: &[DVec2]) -> f64 {
    match bbox(positions) {
        Some((lo, hi)) => (hi - lo).length(),
        None => 0.0,
    }
}

/// Bounding box `(min, max)` of the positions, `None` when there are none.
pub fn bbox(positions: &[DVec2]) -> Option<(DVec2, DVec2)> {
    let first = *positions.first()?;
    Some(
        positions
            .iter()
            .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
    )
}

/// Elastic energy (Eq. 4, unit weights) of the assembly's current positions and active states,
/// with each part's rotation fitted to the current pose.
pub fn elastic_energy(asm: &Assembly, config: &SolverConfig) -> f64 {
    let parts = &asm.data().parts;
    let f = &asm.data().positions;
    let rotations: Vec<DVec2> = parts.iter().map(|p| local::part_rotation(p, f)).collect();
    let vertex_parts = local::VertexParts::build(parts, f.len());
    let cos_cone = cone_cosine(config.rotation_cone_degrees);
    let mut energy = 0.0;
    for (pi, part) in parts.iter().enumerate() {
        let Some(rest) = part.states.get(part.active) else {
            continue;
        };
        for e in &part.edges {
            let (x, y) = (part.vertices[e[0]], part.vertices[e[1]]);
            let d0 = rest.positions[e[0]] - rest.positions[e[1]];
            let r = local::edge_rotation(&vertex_parts, &rotations, x, y, pi, cos_cone);
            energy += (r.rotate(d0) - (f[x] - f[y])).length_squared();
        }
    }
    energy
}

/// The strain of an edge: `length / rest - 1` (positive stretched, negative squeezed); `None`
/// for an edge of (near) zero rest length. The one definition the summaries, the claims suite
/// and the renderer's strain overlay share (a non-finite length gives a non-finite strain,
/// which summaries report and pictures skip).
pub fn edge_strain(rest: f64, length: f64) -> Option<f64> {
    (rest > 1e-12).then(|| length / rest - 1.0)
}

/// Largest `|length / rest length - 1|` over the edges of every part's active state (edges
/// of zero rest length are skipped).
pub fn max_edge_strain(asm: &Assembly) -> f64 {
    edge_strains(asm)
        .into_iter()
        .map(f64::abs)
        .fold(0.0, f64::max)
}

/// `length / rest length - 1` (signed) of every edge of every part's active state, part by
/// part; edges of zero rest length are skipped.
pub fn edge_strains(asm: &Assembly) -> Vec<f64> {
    let f = &asm.data().positions;
    let mut out = Vec::new();
    for part in &asm.data().parts {
        let Some(rest) = part.states.get(part.active) else {
            continue;
        };
        for e in &part.edges {
            let rest_len = (rest.positions[e[0]] - rest.positions[e[1]]).length();
            let len = (f[part.vertices[e[0]]] - f[part.vertices[e[1]]]).length();
            out.extend(edge_strain(rest_len, len));
        }
    }
    out
}
