//! Where a site is and which way it faces in the current pose: the geometry the merge and
//! cut rules (and the session's dock centres) read.

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, InstanceSite};
use glam::DVec2;

use crate::fit;

/// Centre of an instance site's current vertex positions.
pub fn site_centre(
    grammar: &CompiledGrammar,
    data: &AssemblyData,
    s: InstanceSite,
) -> Option<DVec2> {
    let vs = data.site_vertices(grammar, s)?;
    if vs.is_empty() {
        return None;
    }
    Some(vs.iter().map(|&v| data.positions[v]).sum::<DVec2>() / vs.len() as f64)
}

/// The current outward direction of an instance site (unit length): the site's `out` (given in
/// its piece's base-state coordinates) turned by the best rigid motion of the site's own vertices
/// from the base state to their current positions. Fitting the site's vertices, not the whole
/// instance, follows the site through its piece's rest state and deformation: the east end of a
/// road bent a quarter turn left faces north, not north-east as a fit of all its vertices would
/// say. A site of one vertex (or whose vertices coincide in the base state) has no direction of
/// its own, so its edge neighbours in the piece join the fit. `None` when the site does not exist,
/// a position is not finite, or the fit gives no rotation (its vertices collapsed onto a point).
pub fn site_out(grammar: &CompiledGrammar, data: &AssemblyData, s: InstanceSite) -> Option<DVec2> {
    let inst = data.instances.get(s.instance)?;
    let piece = grammar.pieces.get(inst.piece)?;
    let site = piece.sites.get(s.site)?;
    let base = &piece.states.first()?.positions;
    let first = *base.get(*site.vertices.first()?)?;
    let mut local = site.vertices.clone();
    if local.iter().all(|&v| base.get(v) == Some(&first)) {
        for e in &piece.edges {
            for (a, b) in [(e[0], e[1]), (e[1], e[0])] {
                if site.vertices.contains(&a) && !local.contains(&b) {
                    local.push(b);
                }
            }
        }
    }
    let from: Vec<DVec2> = local
        .iter()
        .map(|&v| base.get(v).copied())
        .collect::<Option<_>>()?;
    let to: Vec<DVec2> = local
        .iter()
        .map(|&v| data.positions.get(*inst.vertices.get(v)?).copied())
        .collect::<Option<_>>()?;
    fit::rigid_rotation(&from, &to)?
        .rotate(site.out)
        .try_normalize()
}
