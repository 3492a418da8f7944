//! What docs/editor.md says the editor draws and logs is what the library gives it (issue 40):
//! the strain ramp's colours at the strains it names, and the shape of the rule log's line for
//! a stretch, with the names it quotes.

use std::sync::Arc;

use clay::testing::strain_colour;
use clay::{Assembly, RuleKind, Script, SolverConfig};

/// docs/editor.md with every run of whitespace one space (its lines wrap anywhere).
fn editor_md() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/editor.md"))
        .unwrap()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// The colour's name by its hue: the ramp runs through these three.
fn hue_name(strain: f64) -> &'static str {
    let [r, g, b, _] = strain_colour(strain).0.map(i32::from);
    if g > r + 60 && g > b + 60 {
        "green"
    } else if r > 150 && g > 150 && b < 100 {
        "yellow"
    } else if r > g + 100 && r > b + 100 {
        "red"
    } else {
        "other"
    }
}

#[test]
fn the_strain_colours_are_those_docs_editor_md_names() {
    let doc = editor_md();
    let said = "(green at rest, yellow at 25%, red at 50% and beyond)";
    assert!(
        doc.contains(said),
        "docs/editor.md's strain sentence changed"
    );
    assert_eq!(hue_name(0.0), "green");
    assert_eq!(hue_name(0.25), "yellow");
    assert_eq!(hue_name(0.5), "red");
    assert_eq!(hue_name(2.0), "red");
    assert_eq!(strain_colour(0.5), strain_colour(2.0), "red from 50% on");
}

#[test]
fn the_rule_logs_stretch_line_has_the_shape_docs_editor_md_quotes() {
    let doc = editor_md();
    let quoted =
        "\"`wall[3]` and `wall[4]` became three bricks: `wall#9` inserted; `wall` has 9 now";
    assert!(
        doc.contains(quoted),
        "docs/editor.md's rule-log quote changed"
    );
    let dir = env!("CARGO_MANIFEST_DIR");
    let src = std::fs::read_to_string(format!("{dir}/grammars/wall.clay")).unwrap();
    let g = clay_dsl::compile(&src, "wall", &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar;
    let json = std::fs::read_to_string(format!("{dir}/grammars/wall.script.json")).unwrap();
    let script = Script::parse(&json).unwrap();
    let mut asm = Assembly::new(Arc::new(g.clone()));
    let mut session = clay::Session::new(SolverConfig::from_params(&g.solver));
    for (i, s) in script.steps.iter().enumerate() {
        session.step(&mut asm, i, s).unwrap();
    }
    let first = session
        .rule_log()
        .iter()
        .find(|e| e.kind == RuleKind::Stretch)
        .expect("the wall script stretches");
    // The first stretch of the grammar's wall: two of its bricks, one new brick.
    let d = &first.detail;
    let (pair, rest) = d.split_once(" became three bricks: `wall#").expect(d);
    let (a, b) = pair.split_once(" and ").expect(d);
    for name in [a, b] {
        let index = name
            .strip_prefix("`wall[")
            .and_then(|n| n.strip_suffix("]`"));
        assert!(index.is_some_and(|i| i.parse::<usize>().is_ok()), "{d}");
    }
    let (id, rest) = rest.split_once("` inserted; `wall` has ").expect(d);
    assert!(id.parse::<u64>().unwrap() >= 8, "{d}");
    assert_eq!(rest, "9 now", "{d}");
}
