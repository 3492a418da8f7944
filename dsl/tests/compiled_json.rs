//! The compiled grammar's JSON form (`clayc build`): the initial assembly's parts are left out
//! and rebuilt on reading, so every example reads back equal to what was compiled, a file that
//! still lists parts keeps them, and an assembly whose indices do not hold reads without a
//! panic (and without parts, which its check then reports).

use clay_dsl::CompiledGrammar;

fn examples() -> Vec<(String, CompiledGrammar)> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../grammars");
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.extension().is_some_and(|e| e == "clay") {
            let text = std::fs::read_to_string(&path).unwrap();
            let name = path.display().to_string();
            let compiled =
                clay_dsl::compile(&text, &name, &clay_dsl::CompileOptions::default()).unwrap();
            out.push((name, compiled.grammar));
        }
    }
    assert!(out.len() >= 5, "the example grammars are read");
    out
}

#[test]
fn every_example_reads_back_as_compiled_without_its_parts_written() {
    for (name, grammar) in examples() {
        assert!(!grammar.assembly.parts.is_empty(), "{name}");
        let json = serde_json::to_string(&grammar).unwrap();
        let value: serde_json::Value = serde_json::from_str(&json).unwrap();
        assert!(
            value["assembly"].get("parts").is_none(),
            "{name} wrote its parts"
        );
        let back: CompiledGrammar = serde_json::from_str(&json).unwrap();
        assert_eq!(back, grammar, "{name}");
    }
}

#[test]
fn a_file_that_lists_parts_keeps_them() {
    let (_, grammar) = examples().swap_remove(0);
    let mut value = serde_json::to_value(&grammar).unwrap();
    let mut parts = serde_json::to_value(&grammar.assembly.parts).unwrap();
    // a part marked as the file has it, not as the grammar would rebuild it
    parts[0]["active"] = serde_json::json!(0);
    value["assembly"]["parts"] = parts;
    let back: CompiledGrammar = serde_json::from_value(value).unwrap();
    assert_eq!(back.assembly.parts.len(), grammar.assembly.parts.len());
    assert_eq!(back.assembly.parts[0].active, 0);
}

#[test]
fn indices_that_do_not_hold_read_without_parts_and_without_a_panic() {
    for (name, grammar) in examples() {
        let value = serde_json::to_value(&grammar).unwrap();
        let breaks: [(&str, serde_json::Value); 3] = [
            (
                "/assembly/chains/0/instances/1",
                serde_json::json!(1_000_000),
            ),
            ("/assembly/chains/0/rule", serde_json::json!(99)),
            ("/assembly/instances/0/piece", serde_json::json!(99)),
        ];
        for (pointer, bad) in breaks {
            let mut broken = value.clone();
            let Some(slot) = broken.pointer_mut(pointer) else {
                continue;
            };
            *slot = bad;
            let back: CompiledGrammar = serde_json::from_value(broken).unwrap();
            assert!(back.assembly.parts.is_empty(), "{name} {pointer}");
        }
    }
}

#[test]
fn a_chain_whose_elements_are_not_docked_is_reported_either_way_round() {
    for (name, grammar) in examples() {
        let Some(chain) = grammar
            .assembly
            .chains
            .iter()
            .find(|c| c.instances.len() >= 2)
        else {
            continue;
        };
        let pair = [chain.instances[0], chain.instances[1]];
        assert!(grammar.assembly.problems(&grammar).is_empty(), "{name}");
        // the dock between the first two elements, written the other way round: still docked
        let mut turned = grammar.clone();
        for d in &mut turned.assembly.docks {
            if pair.contains(&d.a.instance) && pair.contains(&d.b.instance) {
                std::mem::swap(&mut d.a, &mut d.b);
            }
        }
        assert!(turned.assembly.problems(&turned).is_empty(), "{name}");
        // and taken away: the chain is reported
        let mut broken = grammar.clone();
        broken
            .assembly
            .docks
            .retain(|d| !(pair.contains(&d.a.instance) && pair.contains(&d.b.instance)));
        let problems = broken.assembly.problems(&broken);
        assert!(
            problems.iter().any(|p| p.contains("are not docked")),
            "{name}: {problems:?}"
        );
    }
}
