//! Property tests of the solver over random chain, street and grid models and random drags:
//! positions stay finite, every linear solve is accurate, and a frame never ends with a higher
//! pass-2 objective than its warm start.

use std::sync::Arc;

use clay::{Assembly, Compass, HandleKind, Solver, SolverConfig, synthetic};
use glam::DVec2;
use proptest::prelude::*;

fn model(kind: u8, size: usize) -> Assembly {
    let g = match kind % 3 {
        0 => synthetic::wall(size + 2),
        1 => synthetic::street(size + 1),
        _ => synthetic::arap_grid(size.min(8) + 2),
    };
    Assembly::new(Arc::new(g))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn random_drags_stay_finite_accurate_and_never_worse_than_the_warm_start(
        kind in 0u8..3,
        size in 1usize..12,
        pin in any::<bool>(),
        by in (-6.0f64..6.0, -6.0f64..6.0),
        angle in -3.5f64..3.5,
        frames in 1usize..5,
        norm in prop_oneof![Just(0.5f64), Just(1.0), Just(2.0)],
    ) {
        let mut asm = model(kind, size);
        let mut config = SolverConfig::from_params(&asm.grammar().solver);
        config.norm = norm;
        config.measure_residual = true;
        let mut solver = Solver::new(config);
        if pin {
            let west = asm.part_extreme(Compass::West).unwrap();
            asm.hold_part(west, HandleKind::Pin).unwrap();
        }
        let east = asm.part_extreme(Compass::East).unwrap();
        let h = asm.hold_part(east, HandleKind::Grab).unwrap();
        for k in 1..=frames + 2 {
            let s = k.min(frames) as f64 / frames as f64;
            asm.move_handle(h, DVec2::new(by.0, by.1) * s, angle * s);
            let r = solver.frame(&mut asm).unwrap();
            prop_assert!(asm.data().positions.iter().all(|p| p.is_finite()));
            let residual = r.linear_residual.unwrap();
            prop_assert!(residual < 1e-9, "relative residual {residual}");
            prop_assert!(
                r.objective <= r.warm_objective * (1.0 + 1e-9) + 1e-12,
                "objective {} above warm start {}", r.objective, r.warm_objective
            );
            prop_assert!(r.energy.is_finite() && r.energy >= 0.0);
        }
        prop_assert!(asm.validate().is_ok());
    }
}
