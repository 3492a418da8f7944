//! What is under a point of the picture: the part whose posed proxy geometry contains it, or
//! else whose edge is within a tolerance. The editor picks with it; it lives here because it
//! reads the posed meshes ([`WorldMesh`]) the renderer makes.

use clay_dsl::compiled::AssemblyData;
use glam::DVec2;

use super::pose::WorldMesh;
use crate::plane::{segment_distance, triangle_contains};

fn world_of([x, y]: [f32; 2]) -> DVec2 {
    DVec2::new(x as f64, y as f64)
}

/// The part under world point `w`: the part covering the top-most instance whose geometry
/// contains `w` (of several, the one whose centre is nearest), else the part with an edge
/// within `tolerance`.
pub fn part_at(
    w: DVec2,
    meshes: &[WorldMesh],
    data: &AssemblyData,
    tolerance: f64,
) -> Option<usize> {
    let centre = |part: &clay_dsl::compiled::Part| {
        let pts: Vec<DVec2> = part
            .vertices
            .iter()
            .filter_map(|&v| data.positions.get(v).copied())
            .collect();
        pts.iter().copied().sum::<DVec2>() / pts.len().max(1) as f64
    };
    let hit = meshes.iter().rev().find(|m| mesh_contains(m, w));
    if let Some(m) = hit {
        let best = data
            .parts
            .iter()
            .enumerate()
            .filter(|(i, _)| data.part_instances(*i).contains(&m.instance))
            .min_by(|a, b| {
                centre(a.1)
                    .distance_squared(w)
                    .total_cmp(&centre(b.1).distance_squared(w))
            });
        if let Some((i, _)) = best {
            return Some(i);
        }
    }
    let mut best: Option<(usize, f64)> = None;
    for (i, part) in data.parts.iter().enumerate() {
        for &[a, b] in &part.edges {
            let (Some(&va), Some(&vb)) = (part.vertices.get(a), part.vertices.get(b)) else {
                continue;
            };
            let (Some(&pa), Some(&pb)) = (data.positions.get(va), data.positions.get(vb)) else {
                continue;
            };
            let d = segment_distance(w, pa, pb);
            if d <= tolerance && best.is_none_or(|(_, bd)| d < bd) {
                best = Some((i, d));
            }
        }
    }
    best.map(|(i, _)| i)
}

fn mesh_contains(m: &WorldMesh, w: DVec2) -> bool {
    m.triangles.iter().any(|t| {
        let [a, b, c] = t.map(|i| m.positions.get(i as usize).map(|&p| world_of(p)));
        match (a, b, c) {
            (Some(a), Some(b), Some(c)) => triangle_contains(a, b, c, w),
            _ => false,
        }
    })
}
