//! How instances are named, as docs/language.md says (issue 40): the model's names (`wall[3]`,
//! element 3 of the chain `wall`) stay with their instances whatever the rules do; an instance
//! a rule puts in is `STEM#ID`, its id after the chain's name (stretch) or the new piece's name
//! (merge, cut). Driven by the demo scripts of wall.clay and junction.clay.

use std::collections::HashMap;
use std::sync::Arc;

use clay::{Assembly, Script, SolverConfig};
use clay_dsl::compiled::{AssemblyData, CompiledGrammar};

/// Replays `grammars/NAME.script.json`, calling `after` with the assembly after each step.
fn replay(name: &str, mut after: impl FnMut(usize, &CompiledGrammar, &AssemblyData)) {
    let dir = env!("CARGO_MANIFEST_DIR");
    let src = std::fs::read_to_string(format!("{dir}/grammars/{name}.clay")).unwrap();
    let g = clay_dsl::compile(&src, name, &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar;
    let json = std::fs::read_to_string(format!("{dir}/grammars/{name}.script.json")).unwrap();
    let script = Script::parse(&json).unwrap();
    let mut asm = Assembly::new(Arc::new(g.clone()));
    let mut session = clay::Session::new(SolverConfig::from_params(&g.solver));
    // An instance keeps its name as long as it exists: no rule renames one.
    let mut names: HashMap<u64, String> = HashMap::new();
    for (i, s) in script.steps.iter().enumerate() {
        session.step(&mut asm, i, s).unwrap();
        for inst in &asm.data().instances {
            let first = names.entry(inst.id).or_insert_with(|| inst.name.clone());
            assert_eq!(
                *first, inst.name,
                "instance {} renamed at step {i}",
                inst.id
            );
        }
        after(i, &g, asm.data());
    }
}

/// The instances named `STEM#ID`, as (stem, id) with their instance's id, checked equal.
fn generated(data: &AssemblyData) -> Vec<(String, u64)> {
    data.instances
        .iter()
        .filter_map(|i| {
            let (stem, id) = i.name.split_once('#')?;
            assert_eq!(id.parse::<u64>().ok(), Some(i.id), "{}", i.name);
            Some((stem.to_string(), i.id))
        })
        .collect()
}

#[test]
fn a_stretched_walls_inserted_bricks_are_wall_hash_id_and_the_placed_ones_keep_their_names() {
    let mut most = 0;
    replay("wall", |_, _, data| {
        // The grammar's bricks are `wall[0]` .. `wall[7]`, the inserted ones `wall#ID`; the
        // pinned end and the dragged end stay throughout.
        let placed: Vec<&str> = data
            .instances
            .iter()
            .map(|i| i.name.as_str())
            .filter(|n| !n.contains('#'))
            .collect();
        assert!(placed.iter().all(|n| n.starts_with("wall[")), "{placed:?}");
        assert!(placed.contains(&"wall[0]") && placed.contains(&"wall[7]"));
        let added = generated(data);
        assert!(added.iter().all(|(stem, id)| stem == "wall" && *id >= 8));
        assert_eq!(placed.len() + added.len(), data.instances.len());
        most = most.max(added.len());
    });
    assert!(most >= 4, "the drag inserted bricks ({most} at most)");
}

#[test]
fn a_merge_puts_in_a_tee_hash_id_and_its_cut_a_road_hash_id() {
    let (mut tee, mut road_after_cut) = (None, None);
    replay("junction", |_, g, data| {
        let piece = |name: &str| g.pieces.iter().position(|p| p.name == name).unwrap();
        for i in &data.instances {
            if i.piece == piece("tee") {
                assert_eq!(i.name, format!("tee#{}", i.id));
                tee.get_or_insert(i.id);
            }
        }
        if let Some(t) = tee
            && data.instances.iter().all(|i| i.id != t)
        {
            // The cut turned the tee back into a road, a new instance with a new id.
            let roads: Vec<(String, u64)> = generated(data)
                .into_iter()
                .filter(|(stem, id)| stem == "road" && *id > t)
                .collect();
            assert_eq!(roads.len(), 1, "{roads:?}");
            road_after_cut.get_or_insert(roads[0].1);
        }
    });
    assert!(tee.is_some(), "the script merges into a tee");
    assert!(road_after_cut.is_some(), "the script cuts it again");
}
