//! One true error per mistake (issue 18): a mistake in one declaration is not followed by
//! errors about names that exist, or about what depends on the failed declaration.

use clay_dsl::{CompileOptions, compile};

fn wall() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../grammars/wall.clay"
    ))
    .unwrap()
}

/// The codes and messages of a grammar that must not compile.
fn errors(source: &str) -> Vec<(String, String)> {
    compile(source, "wall.clay", &CompileOptions::default())
        .unwrap_err()
        .iter()
        .map(|d| (d.code.to_string(), d.message.clone()))
        .collect()
}

#[test]
fn a_site_type_typo_is_one_error_not_six() {
    let src = wall().replace("site west: joint", "site west: jiont");
    assert_ne!(src, wall(), "the fixture edit applies");
    let e = errors(&src);
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].0, "E011");
    assert!(e[0].1.contains("unknown site type `jiont`"), "{e:?}");
}

#[test]
fn a_failed_stretch_rule_does_not_add_no_axis_errors() {
    let src = wall().replace("min 2", "min 1");
    assert_ne!(src, wall(), "the fixture edit applies");
    let e = errors(&src);
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].0, "E013", "{e:?}");
}

#[test]
fn an_out_of_range_coordinate_is_one_error_wherever_it_is() {
    for (from, to) in [
        ("vertex ne (1, 0.5)", "vertex ne (1e10, 0.5)"),
        ("out (1, 0)", "out (1e10, 0)"),
        ("(0.97, 0.03) (0.97, 0.47)", "(1e10, 0.03) (0.97, 0.47)"),
        ("at (0, 0)", "at (0, 1e12)"),
    ] {
        let src = wall().replacen(from, to, 1);
        assert_ne!(src, wall(), "the edit `{to}` applies");
        let e = errors(&src);
        assert_eq!(e.len(), 1, "{to}: {e:?}");
        assert_eq!(e[0].0, "E013", "{to}: {e:?}");
    }
}

#[test]
fn a_failed_constant_in_a_stretch_piece_is_one_error() {
    // The constant is poisoned: the site it places has no centre, which is not a second
    // mistake ("no length along its stretch axis").
    let src = wall().replacen("vertex ne (1, 0.5)", "vertex ne (bad, 0.5)", 1);
    let src = format!("let bad = sqrt(-1)\n{src}");
    let e = errors(&src);
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].0, "E012", "{e:?}");
}

#[test]
fn a_shadowed_merge_rule_is_warned_but_not_one_with_another_reach() {
    let fixture = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/fixtures/invalid/W006-shadowed-merge.clay"
    ))
    .unwrap();
    let codes = |src: &str| -> Vec<&'static str> {
        compile(src, "m.clay", &CompileOptions::default())
            .unwrap()
            .warnings
            .iter()
            .map(|d| d.code)
            .collect()
    };
    assert_eq!(codes(&fixture), ["W006"]);
    // With its own `within` the later rule fires between the two reaches: no warning.
    let reach = fixture.replace("into tee.side", "into tee.side within 2");
    assert_ne!(reach, fixture);
    assert_eq!(codes(&reach), Vec::<&str>::new());
}

#[test]
fn a_frequency_out_of_range_is_one_error_not_also_a_wrong_sum() {
    let centipede = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../grammars/centipede.clay"
    ))
    .unwrap();
    let src = centipede.replace("seg_a 0.5, seg_b 0.3", "seg_a 1.5, seg_b 0.3");
    assert_ne!(src, centipede, "the fixture edit applies");
    let e = errors(&src);
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].0, "E013", "{e:?}");
}

/// The fixture `tests/fixtures/invalid/NAME.clay`.
fn fixture(name: &str) -> String {
    std::fs::read_to_string(format!(
        "{}/../tests/fixtures/invalid/{name}.clay",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

#[test]
fn a_misspelt_name_in_a_stretch_piece_is_one_error_not_also_a_variant_shape() {
    for (name, message) in [
        ("E011-variant-site-type", "unknown site type `rial`"),
        (
            "E011-variant-edge-vertex",
            "unknown vertex `tx` in piece `sleeper`",
        ),
    ] {
        let e = errors(&fixture(name));
        assert_eq!(e.len(), 1, "{name}: {e:?}");
        assert_eq!(e[0].0, "E011", "{name}: {e:?}");
        assert!(e[0].1.contains(message), "{name}: {e:?}");
    }
}

#[test]
fn a_misspelt_name_in_a_variant_is_one_error_not_also_a_variant_shape() {
    let src = fixture("E011-variant-site-type").replacen("rial", "rail", 1);
    // The same typo in the variant `worn` (its second `west` site line) instead.
    let at = src.find("piece worn").unwrap();
    let src = format!(
        "{}{}",
        &src[..at],
        src[at..].replacen("west: rail", "west: rial", 1)
    );
    let e = errors(&src);
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].0, "E011", "{e:?}");
    let src = fixture("E011-variant-edge-vertex").replacen("tx-ne", "sw-ne", 1);
    let at = src.find("piece worn").unwrap();
    let src = format!("{}{}", &src[..at], src[at..].replacen("sw-ne", "sw-tx", 1));
    let e = errors(&src);
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].0, "E011", "{e:?}");
}

#[test]
fn a_variant_of_another_shape_is_still_reported_when_its_piece_is_whole() {
    // The control: without the typo, an edge the variant lacks is E041.
    let src = fixture("E011-variant-edge-vertex").replacen("tx-ne", "sw-ne", 1);
    let at = src.find("piece worn").unwrap();
    let src = format!("{}{}", &src[..at], src[at..].replacen(", sw-ne", "", 1));
    let e = errors(&src);
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].0, "E041", "{e:?}");
    assert!(e[0].1.contains("variant `worn`"), "{e:?}");
}

#[test]
fn a_misspelt_vertex_in_edges_is_one_error_not_also_a_state_with_other_edges() {
    // A state restating the piece's edges, written right, and the piece's own line with a typo
    // (and the other way round): one E011, no E021.
    let state = "    state tall {\n        sw (0, 0) se (1, 0) ne (1, 1) nw (0, 1)\n        \
                 edges sw-se-ne-nw-sw, sw-ne\n    }\n}";
    let piece = fixture("E011-variant-edge-vertex");
    // The fixture's `sleeper` (with its typo) up to its closing brace, then the state.
    let body = &piece[piece.find("piece sleeper").unwrap()..piece.find("\n}\n").unwrap()];
    let one = format!("site type rail\n{body}\n{state}\n\nmodel {{\n    s = sleeper\n}}\n");
    let e = errors(&one);
    assert_eq!(e.len(), 1, "{one}\n{e:?}");
    assert_eq!(e[0].0, "E011", "{e:?}");
    let other = one.replacen("tx-ne", "sw-ne", 1).replacen(
        "edges sw-se-ne-nw-sw, sw-ne\n    }",
        "edges sw-se-ne-nw-sw, tx-ne\n    }",
        1,
    );
    assert_ne!(other, one);
    let e = errors(&other);
    assert_eq!(e.len(), 1, "{other}\n{e:?}");
    assert_eq!(e[0].0, "E011", "{e:?}");
}
