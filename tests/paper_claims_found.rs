//! Cases the long generated claims run (`CLAY_CLAIMS_CASES=10000`, `paper_claims_generated`)
//! found, each kept as its shrunk grammar and script (`tests/fixtures/found/`) so the default
//! run holds them too. Each test states the claim the case broke.

mod generated;

use generated::{Run, check, step};
use glam::DVec2;

use clay::RuleKind;

fn fixture(name: &str) -> String {
    let dir = format!("{}/tests/fixtures/found", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(format!("{dir}/{name}")).unwrap()
}

/// Replays `tests/fixtures/found/<name>.clay` under `<name>.json`'s steps.
fn replay(name: &str) -> Run {
    replay_text(&fixture(&format!("{name}.clay")), name)
}

/// Replays `text` under `tests/fixtures/found/<script>.json`'s steps.
fn replay_text(text: &str, script: &str) -> Run {
    let script = fixture(&format!("{script}.json"));
    let script: serde_json::Value = serde_json::from_str(&script).unwrap();
    let mut run = Run::new(text);
    for step in script["steps"].as_array().unwrap() {
        run.step(&step.to_string());
    }
    run
}

/// Paper 5.1, relaxation: six thin bricks (`min 6`) pushed to 0.22 of their length fold two
/// ways, three onto three; let go and unpinned, the chain comes to rest (it stayed folded at
/// energy 1.48: a fixed point of the local/global iteration).
#[test]
fn a_chain_folded_by_a_push_below_its_min_comes_to_rest_when_let_go() {
    let run = replay("folded_chain");
    assert_at_rest(&run);
    assert_eq!(run.count("brick"), 6, "{}", run.repro());
}

/// At rest (energy within a millionth of the model's size squared).
fn assert_at_rest(run: &Run) {
    let size = run.size();
    assert!(
        run.energy() <= 1e-6 * size * size,
        "energy {:.3e}, max strain {:.4}\n{}",
        run.energy(),
        run.max_strain(),
        run.repro()
    );
}

/// Paper 5.1, relaxation: 85 thin bricks (`min 71`) pushed to 0.2 of their length shrink to
/// 71 and buckle; let go, the long chain unbent by 2% of its energy a frame (energy 4.5e-4
/// after 200 frames) and a stretch fired on the way in.
#[test]
fn a_long_buckled_chain_let_go_comes_to_rest_without_growing() {
    let run = replay("long_chain_let_go");
    assert_at_rest(&run);
    assert_eq!(run.fired(RuleKind::Stretch), 0, "{}", run.repro());
    assert_eq!(run.count("brick"), 71, "{}", run.repro());
}

/// Paper 5.1, a round trip: 67 bricks (`min 67`) pushed to 0.38x buckle; brought back to
/// where they started they are the 67 (it ended with 98: the buckled chain, pulled straight,
/// read as stretched; then 68).
#[test]
fn a_chain_pushed_past_its_min_and_brought_back_has_its_elements_back() {
    let run = replay("round_trip_after_buckle");
    assert_eq!(run.count("brick"), 67, "{}", run.repro());
    assert_at_rest(&run);
}

/// Paper 5.1, a round trip: 64 bricks (`min 49`) pushed to 0.35x shrink to 49; brought back
/// in a single frame they are the 64 again, at rest (a second stretch made 65: the chain,
/// laid out anew and not yet straight, read as longer along its path than its ends are apart).
#[test]
fn a_chain_let_out_of_a_squeeze_in_one_frame_has_its_elements_back() {
    let run = replay("release_from_squeeze");
    assert_eq!(run.count("brick"), 64, "{}", run.repro());
    assert_at_rest(&run);
}

/// Paper 5.1, fill: 105 bricks (`min 85`) pushed to 0.28x shrink and never grow (one stretch
/// fired among the shrinks).
#[test]
fn a_push_below_the_min_inserts_nothing() {
    let run = replay("push_below_min");
    assert_eq!(run.fired(RuleKind::Stretch), 0, "{}", run.repro());
    assert_eq!(run.count("brick"), 85, "{}", run.repro());
}

/// A claim does not depend on the rest of the model: 82 bricks (`min 70`) pushed to 0.51x
/// end with as many bricks with a chain 1,700 m away as without it (70 and 71).
#[test]
fn a_far_chain_changes_nothing_of_a_buckled_one() {
    let text = fixture("far_chain.clay");
    let alone: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("far = "))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_ne!(alone, text);
    let with_far = replay_text(&text, "far_chain").count("brick");
    let without = replay_text(&alone, "far_chain").count("brick");
    assert_eq!(with_far, without);
    assert_eq!(without, 70);
}

/// The limit of the squeeze rule the cases above brought: a wall (`min 8`) pinned with its ends
/// pushed 2 m together, then pulled out 4 m in the middle, grows (it kept its 8 at strain 1.3:
/// the chain's ends were still closer than at rest, and that alone made growing unavailable).
/// No count rests there (the three held bricks are level, so the wall bends at each); the V
/// through its ends and the grab spans ten bricks, and held, the relaxation (`docs/solver.md`)
/// finds that eleven rest better: energy 14.5 against 20.0 with ten.
#[test]
fn a_squeezed_wall_pulled_out_in_the_middle_grows() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/grammars/wall.clay");
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("min 2", "min 8");
    let mut run = Run::new(&text);
    run.step(&step::pin_at(DVec2::new(0.5, 0.25)))
        .step(&step::grab_at(DVec2::new(7.5, 0.25)))
        .step(&step::drag(DVec2::new(-2.0, 0.0), 30))
        .step(&step::hold(30));
    assert_eq!(run.count("brick"), 8, "{}", run.repro());
    run.step(&step::pin_at(DVec2::new(5.5, 0.25)))
        .step(&step::release())
        .step(&step::grab_at(DVec2::new(3.0, 0.25)))
        .step(&step::drag(DVec2::new(0.0, 4.0), 30))
        .step(&step::hold(60));
    assert_eq!(run.count("brick"), 11, "{}", run.repro());
}

/// Far pieces change nothing (issue 36): 13 bricks of 0.3 m pushed to 0.42x have 5 alone and
/// had 6 with a chain of 3 m elements 700 m away (pass 1's tolerance was the whole model's
/// mean edge, which the long elements raised; it is now each component's own).
#[test]
fn a_far_chain_of_long_elements_changes_nothing() {
    let text = fixture("far_chain_borderline.clay");
    let alone: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("far = "))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_ne!(alone, text);
    let with_far = replay_text(&text, "far_chain_borderline").count("brick");
    let without = replay_text(&alone, "far_chain_borderline").count("brick");
    assert_eq!((with_far, without), (5, 5));
}

/// Paper 4.3, states follow the shape whatever the proportions (issue 46): a fence corner post
/// 0.2 m deep with quarter-turn states, the fence pushed in 0.3 m (a squeeze, no turn) keeps
/// the post straight, as it keeps a post 1 m deep. Judged on its sites' vertices alone, the
/// thin post's squeeze read as nearer its bent state (whose sites are closer) and it flipped
/// between `right` and `base` 151 times in 330 frames. Its sites were then judged spread to
/// the part's size; now a piece whose states differ in the turn between its sites is judged by
/// that turn (`solver::local::SiteTurns`).
#[test]
fn a_thin_corner_pushed_gently_stays_straight() {
    let thin = fixture("thin_corner.clay");
    // the post's half-depth 0.1 -> 0.5 and the bars' depth 0.2 -> 1 (their sites dock)
    let deep = thin
        .replace(", 0.1)", ", 0.5)")
        .replace(", -0.1)", ", -0.5)")
        .replace(", 0.2)", ", 1)");
    assert_ne!(deep, thin);
    for text in [thin, deep] {
        let run = replay_text(&text, "thin_corner");
        assert_eq!(run.fired(RuleKind::Replace), 0, "{}", run.repro());
        assert_eq!(run.states("post"), ["base"], "{}", run.repro());
    }
}

/// Replays `tests/fixtures/found/<name>` (a frame a step) and says which switches of a piece
/// with `west` and `east` sites the turn between them in the frame's pass-1 pose does not call
/// for (`claims::switches_against_the_turn`).
fn switches_against_the_turn(name: &str) -> (Run, Vec<String>) {
    let script = fixture(&format!("{name}.json"));
    let script: serde_json::Value = serde_json::from_str(&script).unwrap();
    let steps: Vec<String> = (script["steps"].as_array().unwrap().iter())
        .map(|s| s.to_string())
        .collect();
    let mut run = Run::new(&fixture(&format!("{name}.clay")));
    let why = generated::assembly::claims::switches_against_the_turn(&mut run, &steps);
    (run, why)
}

/// Paper 4.3, states follow the shape whatever the proportions (issue 46; generated states
/// case 1452): a bend piece 3.62 m long and 1.01 m deep, squeezed in a model strained at 0.48,
/// took its -75-degree state with its sites turned 1.9 degrees, then its -20, then `base` (three
/// replacements, each "closer to its shape": its squeezed sites were nearer the bent states'
/// shorter chord). A piece whose states differ in the turn between its sites is now judged by
/// that turn (`solver::local::SiteTurns`).
#[test]
fn a_deep_bend_piece_squeezed_keeps_its_state() {
    let (run, why) = switches_against_the_turn("deep_bend_squeezed");
    assert!(why.is_empty(), "{why:?}\n{}", run.repro());
}

/// Paper 4.3 in the pose that decides (generated states case 2477): a bend piece switched to
/// its 20-degree state at an iterate of pass 1 where its sites turned just over the margin,
/// and pass 1 ended with them at 9.95 degrees, nearer `base`. A piece's switch in pass 1 now
/// stands only if the pose the pass ends in still calls for it (`Solver::confirm_switches`).
#[test]
fn a_bend_switched_within_pass_1_holds_only_where_the_pass_ends() {
    let (run, why) = switches_against_the_turn("bend_switched_mid_pass");
    assert!(why.is_empty(), "{why:?}\n{}", run.repro());
}

/// Paper 4.3, 5.1, round trip (generated round case 8649): two hubs joined by a run of six
/// bricks, a small free hub and six more, then a bend piece to a third hub, which is turned
/// 60 degrees and led back. Out, the bend took its 60-degree state and the run lost three
/// bricks; back, the bend went straight by its turn, and in every frame after, pass 1 flipped
/// it to its mirrored state and back within its iterations. The flip stayed in the frame's
/// switches, so no frame counted as still: the held model tried nothing and was never
/// relaxed, its hubs stretched to strain 2.5 for 240 frames. A part that ends pass 1 in the
/// state it began it in switched nothing (`Solver::confirm_switches`).
#[test]
fn a_bend_flipped_there_and_back_in_pass_1_lets_the_held_model_rest() {
    let run = replay("bend_flipped_and_back");
    assert_eq!(run.count("e0"), 12, "{}", run.repro());
    assert_eq!(run.states("k0"), ["base"], "{}", run.repro());
    assert_at_rest(&run);
}

/// Paper 4.2, 5.1, morph to a rest configuration (generated morph case 7384): a tree whose
/// held path runs through a straight chain, an arc of four 45-degree elements (`min 2`) and
/// a bend piece; its far hub teleported and turned 225 degrees, where the arc of nine rests
/// with the bend straight. The bend took 60 degrees and the arc shrank to two, 15 degrees
/// short (energy 0.014). The turn proposals (`turns.rs`, `splits`) take a piece's other state
/// with one arc taking up the rest of the turn, the fewest elements that do: the bend
/// straight and the arc one element fewer, below its `min`, which was then dropped, and with
/// it the whole turn more (seven elements) that fits within the rule.
#[test]
fn a_bend_given_back_to_an_arc_at_its_min_takes_a_whole_turn_more() {
    let run = replay("bend_back_to_an_arc_at_its_min");
    assert_eq!(run.chain_count("l0x1"), 9, "{}", run.repro());
    assert_eq!(run.chain_count("l0x0"), 8, "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.3 (generated states case 1111): a tree dragged slowly, a bend piece on a path with
/// an arc. The relaxation proposed new arc counts together with the bend at -10 degrees,
/// read in the relaxed pose where least squares spread the turn; settled with the new counts
/// the model did not bend it (its sites turned 0.0 degrees), and the next pass 1 switched it
/// back, twice. A proposal whose settled model would switch one of its pieces again is tried
/// without that piece's state (`Session::try_proposals`, `Solver::switched_again`).
#[test]
fn a_proposed_bend_the_settled_model_does_not_take_is_not_proposed() {
    let (run, why) = switches_against_the_turn("proposed_bend_switched_back");
    assert!(why.is_empty(), "{why:?}\n{}", run.repro());
}

/// Paper 5.1, Fig. 9 (issue 46, the hero example): the castle, its south-west tower pinned and
/// the north-east one dragged to 1.5x and to 0.75x its size, grows and shrinks its walls to the
/// counts a rectangle of rest walls has there (counts from lengths: 18 m x 12 m between tower
/// centres is 14 + gate + 10 + 16 + 10 walls; 9 m x 6 m is 5 + gate + 4 + 7 + 4) and comes to rest.
/// It sheared into a parallelogram at 36 walls (energy 1.46), and kept 30 at 0.75x (0.62).
#[test]
fn the_castle_dragged_by_one_tower_grows_and_shrinks_its_walls() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/grammars/castle.clay");
    let text = std::fs::read_to_string(path).unwrap();
    for (by, walls) in [(DVec2::new(6.0, 4.0), 50), (DVec2::new(-3.0, -2.0), 20)] {
        let mut run = Run::new(&text);
        run.step(&step::pin_at(DVec2::new(0.0, 0.0)))
            .step(&step::grab_at(DVec2::new(12.0, 8.0)))
            .step(&step::drag(by, 120))
            .step(&step::hold(120));
        assert_eq!(run.count("wall"), walls, "{}", run.repro());
        assert_at_rest(&run);
    }
}

/// Paper 5.1 and Fig. 8 on assemblies (issue 46): five bricks, a rigid corner, four bricks, the
/// west end pinned and the tip of the second wall dragged 3 m outward grows that wall to 7
/// bricks at rest, over 30 frames as in one (over 30 it kept 9 in all at energy 1.27).
#[test]
fn a_pull_past_a_free_corner_grows_the_wall_whatever_its_speed() {
    let text = fixture("corner_walls.clay");
    for frames in [30, 1] {
        let mut run = Run::new(&text);
        run.step(r#"{"pin": {"extreme": "west"}}"#)
            .step(r#"{"grab": {"extreme": "north"}}"#)
            .step(&step::drag(DVec2::new(0.0, 3.0), frames))
            .step(&step::hold(300));
        assert_eq!(run.chain_count("b"), 7, "{}", run.repro());
        assert_eq!(run.chain_count("a"), 5, "{}", run.repro());
        assert_at_rest(&run);
    }
}

/// Paper 5.1 (issue 46): a facade of 4 bricks, a 1.5 m window and 4 bricks pushed in 3 m
/// drops three bricks across the window and rests (it kept 6, 4 and 2, at energy 0.92).
#[test]
fn a_facade_pushed_in_drops_bricks_across_its_window() {
    let mut run = Run::new(&fixture("facade.clay"));
    run.step(r#"{"pin": {"extreme": "west"}}"#)
        .step(r#"{"grab": {"extreme": "east"}}"#)
        .step(&step::drag(DVec2::new(-3.0, 0.0), 30))
        .step(&step::hold(300));
    assert_eq!(run.count("brick"), 5, "{}", run.repro());
    assert_at_rest(&run);
}

/// Paper 4.2, 5.1 (issue 46): a ring of twelve 30-degree wedges (a stretch chain closed on
/// itself) pulled out 2 m over 30 frames and brought back: twelve again, at rest, since no
/// other count near it closes the ring (counts from turns, `solver/turns.rs`). It kept 13
/// (energy 2.2: the relaxation judged counts by length, which a squeezed 13 keeps).
#[test]
fn a_ring_of_wedges_pulled_out_and_back_closes_with_twelve() {
    let run = replay("ring_of_wedges");
    assert_eq!(run.chain_count("w"), 12, "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 5.1 (issue 46): three 30-degree wedges between two posts, the second post led
/// round the wedges' circle and turned with it to where six put it: six wedges, at rest. It
/// ended with four (energy 1.2): the chain's count from its length alone.
#[test]
fn an_arc_between_posts_led_round_its_circle_grows_to_the_turn() {
    let run = replay("arc_between_posts");
    assert_eq!(run.chain_count("w"), 6, "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.3 (issue 46): a state a held model's try chose by energy holds while the handles
/// stay. A tree with bendable pieces, a hub pulled and brought back, then held: pass 1 (by
/// shape) switched a piece to its mirrored bend, the try (by energy) switched it back, and so
/// on: 73 replacements in 232 held frames, each logged "-345% closer to its shape". Now
/// every piece switches at most twice (out and back), each switch logs the figures that
/// decided it (a try's: its energies, lower after), and the model comes to rest.
#[test]
fn a_state_a_try_chose_holds_while_the_handles_stay() {
    let run = replay("held_flip");
    let log = run.session.rule_log();
    let replaced: Vec<&clay::RuleEvent> =
        log.iter().filter(|e| e.kind == RuleKind::Replace).collect();
    for e in &replaced {
        let switches = replaced
            .iter()
            .filter(|x| x.instances == e.instances)
            .count();
        assert!(
            switches <= 2,
            "{} switches of {:?}\n{}",
            switches,
            e.instances,
            run.repro()
        );
        assert!(
            !e.detail.contains(", -"),
            "a switch against its own figure: {}",
            e.detail
        );
        if let Some(energies) = e.detail.split("(energy ").nth(1) {
            let figures: Vec<f64> = (energies.trim_end_matches(')').split(" -> "))
                .map(|x| x.parse().unwrap())
                .collect();
            assert!(figures[1] < figures[0], "{}", e.detail);
        }
    }
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 5.1, counts from lengths (issue 46): a pinned hub whose two sites face opposite
/// ways, a free chain of 0.358 m elements on one side, and on the other 3 of them and 7 of
/// 0.982 m in series to a grabbed hub, led to where 6 and 8 fit (10.004 m; 3 and 9 leave
/// 9.912 m). The relaxation took the pinned hub for a window in one run with the free
/// chain and moved elements into it (8, 3, 8: energy 0.615, not kept), so the model stayed
/// at 3 and 9 (strain 0.032). A held piece now ends a run: 5, 6, 8, at rest.
#[test]
fn a_held_hub_ends_a_run_of_chains() {
    let run = replay("held_through_hub");
    let counts = [
        run.chain_count("l1x0"),
        run.chain_count("l0x0"),
        run.chain_count("l0x1"),
    ];
    assert_eq!(counts, [5, 6, 8], "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 5.1 (issue 46): the turn a chain of turning elements is held to runs between
/// held pieces, through free ones. An arc from a pinned hub to a free hub, walls and a second
/// arc on to two held hubs, one of them turned so that the first arc rests with 7 elements:
/// it ended with 6 (strain 0.051), because the relaxed pose spread the missing 20 degrees over
/// both arcs (each read half an element off, and neither was proposed a count).
#[test]
fn an_arc_through_a_free_hub_takes_the_turn_between_the_holds() {
    let run = replay("arc_through_free_hub");
    let counts = [run.chain_count("l0x0"), run.chain_count("l1x1")];
    assert_eq!(counts, [7, 7], "{}", run.repro());
    assert_eq!(run.chain_count("l2x0"), 5, "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 5.1 (issue 46): a count a turn asks for is judged with the lengths it then asks
/// for. A slow pull grew an arc of 15-degree elements from 2 to 9 (a loop and more) while its
/// walls stayed 6 and 2 where 7 and 5 rest: energy 0.74, strain 0.34. The arc's turn asks for
/// 2 again, but 2 alone settles at energy 35 (its walls far too short); with the walls
/// re-counted after it, the model rests.
#[test]
fn an_arc_grown_a_loop_too_many_goes_back_with_its_walls() {
    let run = replay("arc_a_loop_too_many");
    assert_eq!(run.chain_count("l0x0"), 2, "{}", run.repro());
    let walls = [run.chain_count("l1x0"), run.chain_count("l1x1")];
    assert_eq!(walls, [7, 5], "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 5.1, relaxation (issue 46): a held model that creeps tries other rest states. A
/// tree of hubs, walls and arcs, pinned at both ends and turned round by the far end (the
/// arcs must take more elements): held still afterwards it crept towards a strained pose
/// (energy 1.44, strain 0.15 after 142 frames) and never stopped, so it never tried, where a
/// model with nothing held would have. Trying while it creeps, it rests.
#[test]
fn a_held_tree_that_creeps_tries_and_rests() {
    let run = replay("held_tree_turned");
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 5.1 (issue 46): the turn between two holds fixes how many elements' turns the
/// path between them takes, not how its arcs share them. A tree whose arcs of 10-degree
/// elements, 3 then 2, meet at a free hub, its far hub led to where 2 then 3 rest: it stayed
/// 3 and 2 at strain 0.03 (the same turn, the free hub elsewhere), and nothing was proposed,
/// since neither arc's count misses the turn. The script leads the small move first and the
/// 3.6 m one last: the case as found ended with a 0.20 m move from a rest, less than the
/// hysteresis times its shortest element (0.27 m), which the small-moves property rightly
/// answers elastically (docs/solver.md, "A held model moved little from rest").
#[test]
fn arcs_through_a_free_hub_share_the_turn_as_the_holds_ask() {
    let run = replay("arcs_share_a_turn");
    let arcs = [run.chain_count("l2x0"), run.chain_count("l3x0")];
    assert_eq!(arcs, [2, 3], "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 5.1: a pentagon of free hubs (two held) whose sides of 7 are led in one frame to
/// where sides of 3 rest. The free hubs' loop has a family of relaxed lengths (the far three
/// sides 3 + t, 3 - 0.618 t, 3 + t all close), and the relaxation stopped at t = 2: sides 5,
/// 1.76 and 5, which round to 5, 2 and 5 and rest strained (energy 2.7e-3, strain 0.023).
/// The counts that close the loop (`solver/closure.rs`) are 3, 3 and 3.
#[test]
fn a_pentagon_shrunk_in_one_frame_closes_with_the_counts_that_fit() {
    let run = replay("pentagon_shrunk");
    let sides: Vec<usize> = (0..5)
        .map(|l| run.chain_count(&format!("l{l}x0")))
        .collect();
    assert_eq!(sides, [3, 3, 3, 3, 3], "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4, 5.1, relaxation: a stadium of two hubs, each side an arc of four 45-degree
/// elements and a straight wall of six, pulled out to walls of eleven (the arcs grew to 17
/// with the pull) and let go. Relaxed, it kept arcs of 4 and 3: seven elements turn by 315
/// degrees, which no lengths close, and the loop rested strained (energy 0.18, strain 0.22).
/// A loop no held piece is on turns by a whole turn, so its arcs' counts are proposed
/// together from the loop's turn (`closure.rs::free_loops`, `turns.rs`): eight arc elements.
#[test]
fn a_stadium_let_go_closes_its_turn_with_eight_arc_elements() {
    let run = replay("stadium_let_go");
    let arcs = run.chain_count("l0x0") + run.chain_count("l1x0");
    assert_eq!(arcs, 8, "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 5.1: a tree whose far hub is led to where its last link (a bendable piece
/// alone) rests bent by 10 degrees and its middle link (6, straight, 7) as 3, straight, 7.
/// The bend was taken by the middle link's piece instead, and with counts free every such
/// assignment closes, so the relaxation kept the first it found, whose whole counts did not
/// close (9 and 2: strain 0.04, energy 2.8e-3; generated morph case 658). A bent piece
/// handing its state to another is now relaxed too, and the assignment whose whole counts
/// close best is proposed: here the middle piece bent the other way, 8 and 2, a rest
/// configuration as good as the one led to.
#[test]
fn a_bend_taken_by_the_wrong_piece_is_handed_to_the_one_whose_counts_close() {
    let run = replay("bend_handed_on");
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.3, 5.1: an arc of six 10-degree elements between two hubs, the far hub led to
/// where five rest (turned 10 degrees about the near one). The count whose turn matches,
/// five, and five and a whole turn, 41, end their chains where the holds are alike; the
/// choice between them compared their turns and chords rounded to a millionth, and an
/// element's turn read from a grammar's nine digits makes 36 a whole turn only to 1e-7:
/// 41 won by a rounding, rested far worse than six, and the arc stayed at six (energy
/// 1.65, strain 0.2; generated morph case 3563 of 10,000). Counts whose turns and chords
/// miss alike within tolerances now go to the fewest elements.
#[test]
fn an_arc_led_one_element_shorter_loses_it_not_a_whole_turn_more() {
    let run = replay("arc_one_shorter");
    assert_eq!(run.chain_count("l0x0"), 5, "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 5.1: a tree whose far hub is led to where its arc of 20-degree elements rests
/// as four and the bend piece on the next link bent 10 degrees. The relaxation left the arc
/// at five and mirrored the bend: the same turn between the holds, and lengths that nearly
/// fit (strain 0.025, energy 6.2e-3; generated morph case 334). The turn between two holds
/// fixes how much the path turns, not how its arcs and pieces share it, so an arc's count
/// is proposed together with another state of a piece on the path (`turns.rs::splits`).
#[test]
fn a_turn_shared_by_an_arc_and_a_bend_is_shared_as_the_counts_close() {
    let run = replay("turn_handed_to_an_arc");
    assert_eq!(run.chain_count("l0x1"), 4, "{}", run.repro());
    assert!(run.max_strain() <= 1e-3, "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 5.1: a tree led to where a 20-degree bend and an arc of ten 15-degree elements
/// rest; the bend took its 45-degree state and the arc eight (165 degrees where 170 rest),
/// strained by 0.023 at an energy within a millionth of the size squared (generated morph
/// case 437). A piece's other state is proposed with the arc's count that takes up the rest
/// of the turn, however many elements that is.
#[test]
fn a_bend_handed_to_an_arc_takes_as_many_elements_as_the_turn_asks() {
    let run = replay("bend_handed_to_arc_elements");
    assert!(run.max_strain() <= 1e-3, "{}", run.repro());
    check::at_rest(&run, 1e-8).unwrap();
}

/// Paper 4.2, 5.1: a tree of straight chains whose far hub is led to where its two bend
/// pieces rest bent 75 degrees either way; they took their 50-degree states instead, turning
/// the path as far (strain 0.042, energy 8.4e-3; generated morph case 857). Two pieces on a
/// held path taking other states together are proposed when they keep its turn.
#[test]
fn two_bends_that_turn_alike_are_swapped_for_the_pair_whose_counts_close() {
    let run = replay("bends_swapped");
    assert!(run.max_strain() <= 1e-3, "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 4.3, Fig. 4 (issue 46: several bend angles): a street of six segments, each
/// with a 15-degree and a 45-degree bend state, its east end led along the path its third
/// segment's 45-degree bend takes it: one segment in `l45` and the others straight, at rest,
/// as without the `l15` state. Pass 1 bent three segments to `l15` on the way (45 degrees
/// too) and the model rested there at strain 0.031 (energy 0.012): the turn between the
/// holds was matched, but no proposal changed more than two pieces' states.
#[test]
fn a_street_led_to_a_45_degree_bend_takes_its_45_degree_state() {
    let text = fixture("street_two_bends.clay");
    let without = text.replace("    state l15 bend 15\n", "");
    assert_ne!(without, text);
    for grammar in [text, without] {
        let run = replay_text(&grammar, "street_two_bends");
        let mut states = run.states("road");
        states.sort();
        assert_eq!(
            states,
            ["base", "base", "base", "base", "base", "l45"],
            "{}",
            run.repro()
        );
        check::at_rest(&run, 1e-6).unwrap();
    }
}

/// Paper 5.1, round trip (issue 46): two towers joined by a wall of six bricks, one tower
/// turned 60 degrees about the other over 30 frames and back over 30, then held: six bricks
/// again, at rest. The issue measured seven at energy 0.93 (strain 0.23) on its towers; on
/// these (2 m towers, 1 m bricks), turned over 1, 3, 10 or 30 frames with the tower turning or
/// not, `8507bbe` and `07d2799` keep six too: not reproduced, so this guards the round trip.
#[test]
fn towers_turned_about_each_other_and_back_keep_their_wall() {
    let run = replay("towers_wall");
    assert_eq!(run.chain_count("w"), 6, "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 5.1, pulled and back: two hubs joined by two straight chains in series, six of
/// a 0.78 m element and seven of a 1.705 m one, pulled 0.42 m over 112 frames (12 and 4 fit
/// there) and let back in one. The run's length, 16.615 m, is six and seven exactly and 17 and
/// two to 5.5 cm; the rounding took the fewest changes among fits within a tenth of an
/// element, 17 and two, and the model kept the misfit as strain (0.0067, energy 5.8e-4;
/// generated pulled case 748). The best fit wins now, the fewest changes only among equals.
#[test]
fn chains_in_series_pulled_and_back_take_the_counts_that_fit_exactly() {
    let run = replay("chains_in_series");
    assert_eq!(run.chain_count("l0x0"), 6, "{}", run.repro());
    assert_eq!(run.chain_count("l0x1"), 7, "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 5.1, round trip: a tree whose two far hubs are led apart in alternating small
/// steps and back. On the way back one run of chains in series (seven of a 0.866 m element,
/// two of a 2.132 m one) was squeezed to its `min` of two and the other grew; relaxed, two and
/// four fit its length to 6.6 cm, within the tenth of an element the rounding took as exact,
/// and the model kept the misfit (strain 0.012, energy 1.3e-3; generated round case 497).
/// A fit is exact now within a thousandth of an element; otherwise every count is searched.
#[test]
fn a_run_squeezed_to_its_min_and_back_takes_its_counts_again() {
    let run = replay("series_scaled_and_back");
    assert_eq!(run.chain_count("l2x0"), 7, "{}", run.repro());
    assert_eq!(run.chain_count("l2x1"), 2, "{}", run.repro());
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 4.3: a rectangle of four hubs, one pinned and one led so that two opposite
/// sides (each two chains either side of a window) change their counts and the other two,
/// each a chain of six and one of seven of another element, keep theirs. Strained on the
/// way, the relaxation proposed those counts and another pair that also rests (three and
/// eight); the session kept the lower energy, 6e-17 against 1.5e-16, a difference of
/// rounding that a far chain added to the model reversed (found by
/// `far_pieces_change_nothing_in_an_assembly`, case 15 of seed 4242). Of proposals that rest,
/// the one that changes fewest elements and states is kept.
#[test]
fn sides_a_morph_leaves_alone_keep_their_counts() {
    let run = replay("rectangle_sides_kept");
    for (stem, want) in [("l1x0", 6), ("l1x1", 7), ("l3x0", 6), ("l3x1", 7)] {
        assert_eq!(run.chain_count(stem), want, "{stem}\n{}", run.repro());
    }
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.3 and locality: an arc of seven 45-degree elements between two hubs, its far hub
/// led round to where nine rest, with a chain of 16 m elements far away. The small-move
/// gate measured the shortest element over straight stretch elements only: the arc's were
/// left out, the far chain's 16 m made the 1 m lead a small move, and nothing was tried
/// (seven elements at strain 0.45, energy 0.92; alone, nine at rest; found by
/// `far_pieces_change_nothing_in_an_assembly`, case 261 of seed 4242). An element that
/// turns measures its chord.
#[test]
fn an_arc_led_round_grows_whatever_lies_far_away() {
    let run = replay("arc_beside_a_far_chain");
    assert_eq!(run.chain_count("l0x0"), 9, "{}", run.repro());
    assert!(run.max_strain() <= 1e-3, "{}", run.repro());
}

/// Fig. 8 (speed): a ring of two hubs, each link an arc of four 45-degree elements and a
/// straight chain of five, its far hub pulled out over 240 frames to where the straight
/// chains rest at nine. Pass 1 judged the arc's parts by their length like a straight
/// chain's: pulled straighter they stretched, and each element inserted turned the arc
/// further, until one arc had 12 (a whole turn more, at rest); pulled in 0, 5 or 30 frames
/// it kept four (generated speed case 134 of 1,000, seed 4242). An arc is counted by its turn.
#[test]
fn a_ring_pulled_slowly_keeps_its_arcs() {
    let run = replay("ring_arc_pulled_slowly");
    for (stem, want) in [("l0x0", 4), ("l1x0", 4), ("l0x1", 9), ("l1x1", 9)] {
        assert_eq!(run.chain_count(stem), want, "{stem}\n{}", run.repro());
    }
    check::at_rest(&run, 1e-6).unwrap();
}

/// Paper 4.2, 5.1: a tree whose two far hubs are led to where its arcs of 12-degree elements
/// through a free hub rest as seven and five. The relaxation proposed the seventh element,
/// but the rules lay an inserted element out along its chain, and least squares settled
/// that layout into a fold (energy 0.011 where the counts rest); the model as it was, six
/// and five, settled lower and stayed (strain 0.11, energy 4.8e-3; generated morph case 825
/// of 1,000, seed 4242). A proposal still strained is settled from its rest layout too.
#[test]
fn an_arc_element_inserted_into_a_fold_is_judged_from_its_rest_layout() {
    let run = replay("arc_inserted_folded");
    for (stem, want) in [("l0x0", 8), ("l0x1", 7), ("l1x0", 7), ("l2x0", 5)] {
        assert_eq!(run.chain_count(stem), want, "{stem}\n{}", run.repro());
    }
    check::at_rest(&run, 1e-6).unwrap();
}
