//! Behaviour of the mutable elastic solver on models built in code: rigid drags, rest-state
//! switching with hysteresis, sparse stretch under p = 0.5, and agreement of the solvers.

use std::sync::Arc;

use clay::assembly::{Assembly, Compass, HandleKind};
use clay::solver::{Solver, SolverConfig, SolverKind, edge_strains};
use clay::synthetic;
use glam::DVec2;

fn assembly(g: clay_dsl::CompiledGrammar) -> Assembly {
    let asm = Assembly::new(Arc::new(g));
    asm.validate().unwrap();
    asm
}

#[test]
fn dragging_one_part_with_nothing_pinned_moves_the_model_rigidly() {
    let mut asm = assembly(synthetic::wall(8));
    let start = asm.data.positions.clone();
    let mut solver = Solver::new(SolverConfig::default());
    let part = asm.part_extreme(Compass::East).unwrap();
    let h = asm.hold_part(part, HandleKind::Grab).unwrap();
    let shift = DVec2::new(3.0, -2.0);
    let frames = 20;
    let mut last = None;
    for k in 1..=frames {
        asm.handle_mut(h).unwrap().translation = shift * (k as f64 / frames as f64);
        last = Some(solver.frame(&mut asm).unwrap());
    }
    for _ in 0..5 {
        last = Some(solver.frame(&mut asm).unwrap());
    }
    let report = last.unwrap();
    assert!(report.energy < 1e-8, "energy {}", report.energy);
    for (p, q) in asm.data.positions.iter().zip(&start) {
        assert!((*p - (*q + shift)).length() < 1e-3, "{p} vs {}", *q + shift);
    }
    asm.validate().unwrap();
}
