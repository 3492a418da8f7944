//! `extrude HEIGHT [above BASE]` on proxy geometry (issue 20): compiled heights, range checks,
//! and the formatter keeping it.

use clay_dsl::{CompileOptions, compile, format};

fn tower(extrude: &str) -> String {
    format!(
        "let h = 6\nsite type s\npiece tower {{\n    vertex a (0, 0)\n    vertex b (2, 0)\n    vertex c (1, 2)\n    \
         edges a-b-c-a\n    polygon fill #777777{extrude} {{\n        (0, 0) (2, 0) (1, 2)\n    }}\n}}\n\
         model {{\n    t = tower\n}}\n"
    )
}

#[test]
fn heights_compile_to_the_proxy() {
    let c = compile(
        &tower(" extrude h above h / 3"),
        "t.clay",
        &CompileOptions::default(),
    )
    .unwrap();
    let e = c.grammar.pieces[0].states[0].geometry[0]
        .extrude
        .expect("extruded");
    assert_eq!((e.height, e.base), (6.0, 2.0));
    let c = compile(&tower(" extrude 1.5"), "t.clay", &CompileOptions::default()).unwrap();
    let e = c.grammar.pieces[0].states[0].geometry[0].extrude.unwrap();
    assert_eq!((e.height, e.base), (1.5, 0.0));
    let flat = compile(&tower(""), "t.clay", &CompileOptions::default()).unwrap();
    assert_eq!(flat.grammar.pieces[0].states[0].geometry[0].extrude, None);
    // Flat geometry's compiled JSON has no `extrude` key (old readers and files agree).
    let json = serde_json::to_string(&flat.grammar).unwrap();
    assert!(!json.contains("extrude"));
}

#[test]
fn heights_out_of_range_are_one_error() {
    for bad in [
        " extrude 0",
        " extrude -1",
        " extrude 1e5",
        " extrude 1 above 1e6",
    ] {
        let d = compile(&tower(bad), "t.clay", &CompileOptions::default()).unwrap_err();
        assert_eq!(d.len(), 1, "{bad}: {:?}", d.items);
        assert_eq!(d.items[0].code, "E013", "{bad}");
    }
}

#[test]
fn the_formatter_keeps_extrude() {
    let source = tower("   extrude  h*2   above 1");
    let out = format(&source).unwrap();
    assert!(
        out.contains("polygon fill #777777 extrude h * 2 above 1 {"),
        "{out}"
    );
    assert_eq!(format(&out).unwrap(), out);
    assert_eq!(
        compile(&source, "t.clay", &CompileOptions::default())
            .unwrap()
            .grammar,
        compile(&out, "t.clay", &CompileOptions::default())
            .unwrap()
            .grammar
    );
}
