//! Cutting (paper 5.1, Fig. 7d): the user points at a connection and it comes apart. A junction
//! cut at a site its cut rule names turns back into the rule's `into` piece (placed over it,
//! taking over its other docks) and lets go of the other side; a plain dock is separated by
//! giving one side its own copies of the shared vertices. Chains split or rejoin as the docks
//! now say.

use std::collections::HashSet;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, InstanceSite};
use glam::DVec2;

use super::merge::take_over;
use super::rewrite::{
    PartsBefore, Rewrite, RuleEvent, RuleKind, derive_chains, finish, remove_instances, transaction,
};
use super::sites::site_centre;

/// How far (metres) from the nearest docked site's centre a cut may point; at least this,
/// or twice the grammar's merge distance if that is larger.
pub const CUT_REACH: f64 = 1.0;

/// The dock nearest `point` (by the docked site's centre) and its distance.
pub fn nearest_dock(
    grammar: &CompiledGrammar,
    data: &AssemblyData,
    point: DVec2,
) -> Option<(usize, f64)> {
    data.docks
        .iter()
        .enumerate()
        .filter_map(|(i, d)| Some((i, site_centre(grammar, data, d.a)?.distance(point))))
        .filter(|(_, d)| d.is_finite())
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// Cuts the dock nearest `point`. Errors (nothing changed) when no dock is within reach or the
/// result would break the assembly.
pub fn cut_at(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    point: DVec2,
) -> Result<Rewrite, String> {
    if !point.is_finite() {
        return Err("the cut point is not finite".into());
    }
    let reach = CUT_REACH.max(2.0 * grammar.solver.merge_distance);
    let (di, dist) = nearest_dock(grammar, data, point)
        .ok_or_else(|| "nothing to cut: the assembly has no docked sites".to_string())?;
    if dist > reach {
        return Err(format!(
            "nothing to cut near ({:.3}, {:.3}): the nearest connection is {dist:.3} m away (reach {reach} m)",
            point.x, point.y
        ));
    }
    cut_dock(grammar, data, di)
}

/// Cuts dock `di`.
pub fn cut_dock(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    di: usize,
) -> Result<Rewrite, String> {
    let before = PartsBefore::record(data);
    transaction(grammar, data, |data| {
        let dock = *data.docks.get(di).ok_or("no such dock")?;
        let at = site_centre(grammar, data, dock.a).unwrap_or(DVec2::ZERO);
        // A side that is a junction with a cut rule at this site.
        let rule_for = |s: InstanceSite| {
            let piece = data.instances[s.instance].piece;
            grammar
                .cut_rules
                .iter()
                .find(|r| r.junction.piece == piece && r.junction.site == s.site)
        };
        let junction = [(dock.a, dock.b), (dock.b, dock.a)]
            .into_iter()
            .find_map(|(x, y)| rule_for(x).map(|r| (x, y, r.into)));
        data.docks.remove(di);
        let name = |data: &AssemblyData, s: InstanceSite| data.instances[s.instance].name.clone();
        let (ids, touched, detail) = match junction {
            Some((x, y, into)) => {
                let (xid, yid) = (data.instances[x.instance].id, data.instances[y.instance].id);
                let (xn, yn) = (name(data, x), name(data, y));
                // The other side keeps the stem's vertices as its own: the junction goes.
                let ni = take_over(grammar, data, x.instance, into)?;
                let nid = data.instances[ni].id;
                let nn = data.instances[ni].name.clone();
                remove_instances(data, &HashSet::from([x.instance]));
                (
                    vec![xid, yid, nid],
                    HashSet::from([xid, yid, nid]),
                    format!("`{yn}` cut from `{xn}`; `{xn}` turned back into `{nn}`"),
                )
            }
            None => {
                let (a, b) = (dock.a, dock.b);
                let (aid, bid) = (data.instances[a.instance].id, data.instances[b.instance].id);
                let shared = data
                    .site_vertices(grammar, b)
                    .ok_or("the docked site does not exist")?;
                // Side b gets its own copies of the shared vertices.
                let copies: Vec<usize> = shared
                    .iter()
                    .map(|&v| {
                        data.positions.push(data.positions[v]);
                        data.positions.len() - 1
                    })
                    .collect();
                for v in &mut data.instances[b.instance].vertices {
                    if let Some(i) = shared.iter().position(|x| x == v) {
                        *v = copies[i];
                    }
                }
                (
                    vec![aid, bid],
                    HashSet::from([aid, bid]),
                    format!("`{}` cut from `{}`", name(data, b), name(data, a)),
                )
            }
        };
        derive_chains(grammar, data);
        let event = RuleEvent {
            kind: RuleKind::Cut,
            frame: 0,
            at,
            instances: ids,
            detail,
        };
        Ok(finish(grammar, data, &before, &touched, event))
    })
}
