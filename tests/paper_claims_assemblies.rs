//! The paper's claims over generated assemblies (issue 46): random piece graphs of rigid hubs
//! (towers, corners, tees, windows, posts) joined by stretch chains, bendable pieces and
//! windows, chains of turning elements (arcs), as trees, rectangles (castles), regular polygons
//! and rings (`tests/generated/assembly.rs`).
//! Each case is led from one rest configuration to another (other chain counts, other bend
//! states) along the way one morphs into the other; the oracles need no example: a rest
//! configuration exists there, counts from lengths, exact rigid motions.
//!
//! A failure shrinks towards fewer hubs and plainer links and prints the grammar and the
//! script that reproduce it (`clayc run generated.clay --script script.json`). The seeds are
//! fixed; `CLAY_CLAIMS_CASES=N` runs N cases of each property instead of the default.

mod generated;

use generated::assembly::{self, Morph, Recipe, claims};
use generated::{config, more, strategy};

use glam::DVec2;
use proptest::prelude::*;

/// A generated morph.
fn morphs() -> impl Strategy<Value = Morph> {
    (
        prop::collection::vec(any::<u16>(), 64),
        prop::collection::vec(0.0f64..1.0, 32),
    )
        .prop_map(|(picks, sizes)| assembly::build(&Recipe { picks, sizes }))
}

fn holds(result: Result<(), String>) -> Result<(), TestCaseError> {
    result.map_err(TestCaseError::fail)
}

proptest! {
    #![proptest_config(config(8, 22))]

    /// Fig. 8 on assemblies: the same held pose over 0, 5, 30 or 240 frames gives the same
    /// counts within one per chain.
    #[test]
    fn fig8_speed_on_assemblies(m in morphs()) {
        holds(claims::speed(&m))?;
    }
}

proptest! {
    #![proptest_config(config(24, 25))]

    /// Morph to a rest configuration (paper 4.2, 5.1): led from one rest configuration's held
    /// poses to another's (other chain counts, other bend states) over any number of frames
    /// and held, the model is at rest there, since a rest configuration exists; a chain whose
    /// count the held hubs fix has it within one.
    #[test]
    fn sec5_1_morph_to_a_rest_configuration(m in morphs(), frames in strategy::frames()) {
        holds(claims::morph_to_rest(&m, frames))?;
    }
}

proptest! {
    #![proptest_config(config(16, 26))]

    /// Round trip (paper 5.1): from rest, a hub pulled any way by up to three and a half
    /// elements over any number of frames and brought back: the links the held hubs fix are
    /// as long as at the start, at rest; rings of turning elements included (no count but
    /// the start's closes them).
    #[test]
    fn sec5_1_pulled_and_back(
        m in morphs(),
        degrees in -180.0f64..180.0,
        elements in 0.5f64..3.5,
        frames in strategy::frames(),
        back in strategy::frames(),
    ) {
        let by = DVec2::from_angle(strategy::round(degrees).to_radians())
            * strategy::round(elements)
            * m.graph.shortest();
        let by = DVec2::new(assembly::round9(by.x), assembly::round9(by.y));
        holds(claims::pulled_and_back(&m, by, frames, back))?;
    }
}

proptest! {
    #![proptest_config(config(16, 27))]

    /// Round trip (paper 5.1): led to another rest configuration over any number of frames,
    /// held, and led back over any number: at rest, with the start's lengths on every link
    /// the held hubs fix (loops of free hubs included).
    #[test]
    fn sec5_1_morphed_and_back(m in morphs(), frames in strategy::frames(), back in strategy::frames()) {
        holds(claims::round_trip(&m, frames, back))?;
    }
}

proptest! {
    #![proptest_config(config(16, 23))]

    /// Relaxation (paper 4, 5.1): released, an assembly (loops included) is at rest within
    /// 200 frames.
    #[test]
    fn sec5_1_relaxation_of_an_assembly(m in morphs(), frames in strategy::frames()) {
        holds(claims::relaxation(&m, frames))?;
    }
}

proptest! {
    #![proptest_config(config(16, 24))]

    /// Paper 4.2, 4.3: a piece takes a bent state only when the turn between its sites is
    /// nearer that state's angle than its current one's by the hysteresis margin, whatever
    /// its proportions: led to another configuration, then pushed and turned.
    #[test]
    fn sec4_3_states_follow_the_shape(
        m in morphs(),
        frames in 8u64..=240,
        push in (-1.0f64..1.0, -1.0f64..1.0),
        turn in -60.0f64..60.0,
    ) {
        let push = DVec2::new(strategy::round(push.0), strategy::round(push.1));
        holds(claims::states_follow_the_shape(&m, frames, push, strategy::round(turn)))?;
    }

    /// Paper 4.3: from rest, a handle moved by less than the hysteresis times the shortest
    /// element's length switches nothing (the fraction drawn below 0.999, so that rounded to
    /// three decimals it stays below 1: a move of exactly that length is not a small one).
    #[test]
    fn sec4_3_small_moves_switch_nothing(m in morphs(), fraction in 0.0f64..0.999, degrees in -180.0f64..180.0) {
        holds(claims::small_moves_switch_nothing(&m, strategy::round(fraction), strategy::round(degrees)))?;
    }

    /// Paper 4.1 on assemblies: with nothing pinned, grabbed by any hub and carried and
    /// turned, the model moves rigidly, at rest, and no rule fires.
    #[test]
    fn sec4_1_rigid_motion_of_an_assembly(
        m in morphs(),
        pick in 0usize..64,
        by in (-20.0f64..20.0, -20.0f64..20.0),
        degrees in prop_oneof![Just(0.0f64), -180.0f64..180.0],
        frames in 1u64..60,
    ) {
        let g = &m.graph;
        let node = pick % g.nodes.len();
        let at = g.centroid(node, g.poses(&g.start)[node]);
        let by = DVec2::new(strategy::round(by.0), strategy::round(by.1));
        holds(more::rigid(&g.text(), at, by, strategy::round(degrees), frames))?;
    }
}

proptest! {
    #![proptest_config(config(8, 27))]

    /// The same morph twice gives bit-identical positions and the same rule events.
    #[test]
    fn determinism_of_an_assembly(m in morphs(), frames in strategy::frames()) {
        holds(claims::deterministic(&m, frames))?;
    }

    /// A claim does not depend on how large the rest of the model is: a morph with a chain of
    /// elements ten times the longest part far away ends with the same elements and states.
    #[test]
    fn far_pieces_change_nothing_in_an_assembly(m in morphs(), frames in strategy::frames()) {
        holds(claims::far_pieces_change_nothing(&m, frames))?;
    }
}
