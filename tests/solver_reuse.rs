//! Pass 2 reuses the local step already done at the pose it starts from (the previous
//! frame's accepted iterate, `docs/solver.md`): a frame after the active states or the
//! positions were changed from outside must be the frame a fresh solver computes.

use std::sync::Arc;

use clay::{Assembly, HandleKind, Solver, SolverConfig, synthetic};
use glam::DVec2;

/// Least squares only, so the start pose's evaluation comes from the previous frame.
fn config() -> SolverConfig {
    SolverConfig {
        irls_iterations: 0,
        ..SolverConfig::default()
    }
}

fn dragged() -> (Assembly, Solver) {
    let mut asm = Assembly::new(Arc::new(synthetic::city(300)));
    asm.hold_part(0, HandleKind::Pin);
    let last = asm.data().parts.len() - 1;
    let h = asm.hold_part(last, HandleKind::Grab).unwrap();
    asm.move_handle(h, DVec2::new(3.0, 1.0), 0.0);
    let mut solver = Solver::new(config());
    solver.frame(&mut asm).unwrap();
    (asm, solver)
}

fn bits(p: &[DVec2]) -> Vec<[u64; 2]> {
    p.iter().map(|q| [q.x.to_bits(), q.y.to_bits()]).collect()
}

/// Runs one more frame with the kept solver and with a fresh one on a copy.
fn same_as_fresh(asm: Assembly, mut solver: Solver) {
    let mut copy = asm.clone();
    let mut asm = asm;
    let kept = solver.frame(&mut asm).unwrap();
    let fresh = Solver::new(config()).frame(&mut copy).unwrap();
    assert_eq!(
        kept.warm_objective.to_bits(),
        fresh.warm_objective.to_bits()
    );
    assert_eq!(kept.energy.to_bits(), fresh.energy.to_bits());
    assert!(bits(&asm.data().positions) == bits(&copy.data().positions));
}

#[test]
fn a_state_set_between_frames_is_not_read_from_the_kept_step() {
    let (mut asm, solver) = dragged();
    let part = (asm.data().parts.iter())
        .position(|p| p.states.len() > 1)
        .expect("the city has parts with two rest states");
    let other = (asm.data().parts[part].active + 1) % asm.data().parts[part].states.len();
    assert!(asm.set_active_state(part, other));
    same_as_fresh(asm, solver);
}

#[test]
fn positions_moved_between_frames_are_evaluated_afresh() {
    let (mut asm, solver) = dragged();
    asm.positions_mut()[5] += DVec2::new(0.25, -0.5);
    same_as_fresh(asm, solver);
}

#[test]
fn an_unchanged_model_continues_as_a_fresh_solver_would() {
    let (asm, solver) = dragged();
    same_as_fresh(asm, solver);
}
