//! The solver's local step runs over fixed chunks of parts on as many threads as configured
//! (`src/solver/chunks.rs`): one thread and two must compute the same frames bit for bit.

use std::sync::Arc;

use clay::{Assembly, FrameReport, HandleKind, Solver, SolverConfig, synthetic};
use glam::DVec2;

/// A synthetic city of about `parts` parts, pinned at one corner and dragged at the other
/// for `frames` frames; returns every frame's report and the final positions and states.
fn drag(parts: usize, frames: usize, config: SolverConfig) -> (Vec<FrameReport>, Assembly) {
    let mut asm = Assembly::new(Arc::new(synthetic::city(parts)));
    let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
    for p in asm.data().positions.iter().filter(|p| p.y >= 0.0) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let pin = asm.part_nearest(lo).unwrap();
    asm.hold_part(pin, HandleKind::Pin);
    let grab = asm.part_nearest(hi).unwrap();
    let h = asm.hold_part(grab, HandleKind::Grab).unwrap();
    let offset = DVec2::new(0.3, 0.2) * (hi - lo).length();
    let mut solver = Solver::new(config);
    let mut reports = Vec::new();
    for k in 1..=frames {
        asm.move_handle(h, offset * (k as f64 / 10.0), 0.0);
        reports.push(solver.frame(&mut asm).unwrap());
    }
    (reports, asm)
}

fn bits(p: &[DVec2]) -> Vec<[u64; 2]> {
    p.iter().map(|q| [q.x.to_bits(), q.y.to_bits()]).collect()
}

/// Runs the drag on one thread and on two and compares positions, rotations, active states,
/// energies and switches exactly.
fn same_on_one_and_two_threads(config: SolverConfig) {
    // enough parts for many chunks, so two threads really share the step
    let parts = 10_000;
    let one = drag(
        parts,
        4,
        SolverConfig {
            threads: 1,
            ..config
        },
    );
    let two = drag(
        parts,
        4,
        SolverConfig {
            threads: 2,
            ..config
        },
    );
    assert!(
        one.1.data().parts.len() > 8_000,
        "the model is large enough to split"
    );
    for (k, (a, b)) in one.0.iter().zip(&two.0).enumerate() {
        assert_eq!(a.energy.to_bits(), b.energy.to_bits(), "frame {k} energy");
        assert_eq!(
            a.objective.to_bits(),
            b.objective.to_bits(),
            "frame {k} objective"
        );
        assert_eq!(a.switches, b.switches, "frame {k} switches");
        assert_eq!(a.pass1_iterations, b.pass1_iterations, "frame {k}");
        assert_eq!(a.l2_iterations, b.l2_iterations, "frame {k}");
    }
    assert!(
        bits(one.1.rotations()) == bits(two.1.rotations()),
        "rotations differ"
    );
    let (a, b) = (one.1.data(), two.1.data());
    assert!(bits(&a.positions) == bits(&b.positions), "positions differ");
    let states = |d: &clay_dsl::compiled::AssemblyData| -> Vec<usize> {
        d.parts.iter().map(|p| p.active).collect()
    };
    assert_eq!(states(a), states(b));
}

#[test]
fn irls_frames_are_the_same_on_one_and_two_threads() {
    same_on_one_and_two_threads(SolverConfig::default());
}

#[test]
fn frames_with_a_rotation_cone_are_the_same_on_one_and_two_threads() {
    // the cone makes the local step run in two halves (rotations, then targets)
    same_on_one_and_two_threads(SolverConfig {
        rotation_cone_degrees: 20.0,
        ..SolverConfig::default()
    });
}
