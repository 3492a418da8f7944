//! "Did you mean": a name with two letters swapped is one typo away, so the hint names the
//! intended declaration (issue 18: `stpe`, `sdie` got a list instead).

use clay_dsl::compile;

fn hints(source: &str) -> Vec<String> {
    let d = compile(source, "g.clay").unwrap_err();
    d.iter().flat_map(|d| d.hints.clone()).collect()
}

const GRAMMAR: &str = "site type joint\n\
piece step {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    vertex c (0, 1)\n    edges a-b-c-a\n\
    site side: joint [a, b] out (0, -1)\n}\nmodel {\n    s = PIECE\n}\n";

#[test]
fn a_piece_name_with_swapped_letters_is_suggested() {
    let h = hints(&GRAMMAR.replace("PIECE", "stpe"));
    assert!(
        h.iter().any(|h| h.contains("did you mean `step`?")),
        "{h:?}"
    );
}

#[test]
fn a_site_name_with_swapped_letters_is_suggested() {
    let src = GRAMMAR.replace("PIECE", "step\n    t = step").replace(
        "    t = step\n}",
        "    t = step\n    dock s.sdie to t.side\n}",
    );
    let h = hints(&src);
    assert!(
        h.iter().any(|h| h.contains("did you mean `side`?")),
        "{h:?}"
    );
}
