//! Replacement (paper 5.1, Fig. 7a): when a piece part's active rest state changes, its
//! instance shows that state's geometry. The solver's pass 1 decides the states (and already
//! copies them to the instances); this rule makes sure the instance follows and reports one
//! `replace` event per instance whose state changed this frame (not one per IRLS switch).

use std::collections::BTreeMap;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, PartKind};
use glam::DVec2;

use super::rewrite::{RuleEvent, RuleKind};
use crate::figure::rests_better;
use crate::solver::local::{Switching, VertexParts, judge};
use crate::solver::{Judged, StateSwitch};

/// Sets each piece part's instance to the part's active state and returns one event per
/// instance that ends the frame in a different state than it started. `switches` are the
/// solver's state switches of the frame (several per part are possible within one frame);
/// `decided` is the pose that decided them (pass 1's; the positions when empty), where the
/// event says how much nearer the new state is, as the solver judged it.
pub fn replacement_events(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    switches: &[StateSwitch],
    decided: &[DVec2],
) -> Vec<RuleEvent> {
    // First `from` per part: the state it had when the frame began.
    let mut began: BTreeMap<usize, usize> = BTreeMap::new();
    // What decided the part's last switch.
    let mut decided_by: BTreeMap<usize, Judged> = BTreeMap::new();
    for s in switches {
        began.entry(s.part).or_insert(s.from);
        decided_by.insert(s.part, s.judged);
    }
    let mut events = Vec::new();
    let pose = if decided.len() == data.positions.len() {
        decided
    } else {
        &data.positions[..]
    };
    let shared = (!began.is_empty()).then(|| VertexParts::build(&data.parts, pose.len()));
    for (&pi, &from) in &began {
        let Some(part) = data.parts.get(pi) else {
            continue;
        };
        let PartKind::Piece { instance } = part.kind else {
            continue;
        };
        let to = part.active;
        let Some(inst) = data.instances.get_mut(instance) else {
            continue;
        };
        inst.state = to;
        if from == to {
            continue;
        }
        let piece = &grammar.pieces[inst.piece];
        let name = |s: usize| piece.states.get(s).map_or("?", |st| st.name.as_str());
        let at = centroid(&data.positions, &data.instances[instance].vertices);
        let inst = &data.instances[instance];
        // How much nearer the new state is than the old one, as the solver's local step
        // judged them in the pose that decided (the hysteresis makes this at least its
        // share); a state a try changed for energy says its energies instead: the log says
        // why in the figures that decided it.
        let how = Switching {
            hysteresis: 0.0,
            stretch: &[],
            shared: shared.as_ref(),
        };
        let judged = judge(pi, part, pose, how);
        let misfit = |s: usize| judged.distances.get(s).copied().unwrap_or(f64::NAN);
        let better = 1.0 - misfit(to) / misfit(from);
        let why = match decided_by.get(&pi).copied().unwrap_or(Judged::Shape) {
            // a try's switch: the figures that decided it
            Judged::Energy([before, after]) => format!(": {}", rests_better(before, after)),
            // a proposal's: the session adds the energies that decided it
            Judged::Proposal => String::new(),
            // judged by the turn between its sites: the turns that decided
            Judged::Shape if let Some(turns) = by_turn(&judged.turns, to, from) => {
                format!(
                    ", its sites turn {:.1} degrees from `{}`'s, `{}` {:.1} and `{}` {:.1}",
                    turns[0],
                    name(0),
                    name(to),
                    turns[1],
                    name(from),
                    turns[2]
                )
            }
            Judged::Shape if better.is_finite() => {
                format!(", {:.0}% closer to its shape", 100.0 * better)
            }
            Judged::Shape => String::new(),
        };
        events.push(RuleEvent {
            kind: RuleKind::Replace,
            frame: 0,
            at,
            instances: vec![inst.id],
            detail: format!(
                "`{}` ({}) is now `{}` (was `{}`){why}",
                inst.name,
                piece.name,
                name(to),
                name(from)
            ),
        });
    }
    events
}

/// The pose's turn between a piece's sites and states `to`'s and `from`'s, when it is judged
/// by that turn and all three are finite.
fn by_turn(turns: &Option<(f64, Vec<f64>)>, to: usize, from: usize) -> Option<[f64; 3]> {
    let (turn, states) = turns.as_ref()?;
    let t = [*turn, *states.get(to)?, *states.get(from)?];
    t.iter().all(|x| x.is_finite()).then_some(t)
}

fn centroid(positions: &[DVec2], vertices: &[usize]) -> DVec2 {
    crate::plane::centroid(vertices.iter().map(|&v| positions[v])).unwrap_or(DVec2::ZERO)
}
