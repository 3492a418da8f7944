//! Issue 47: a piece of 100,000 vertices took `check`, `build` and `render` 29 s each (every
//! vertex name, edge repeat and state position found by a scan of the piece's vertices or
//! edges); now by lookups (`compile/pieces.rs`). The lookups must find what the scans found:
//! a large piece compiles to the same indices, with its repeats and duplicates reported where
//! they are written. (Its time is in `benches/check.rs`, `large piece`.)

use clay_dsl::{CompileOptions, compile};

/// A ladder of `n` rungs: vertices `b0, t0, b1, t1, ...`, its outline and one diagonal per
/// bay, sites at either end, and a state `lifted` listing every vertex in reverse order,
/// each raised by 1.
fn ladder(n: usize, extra_vertex: &str, extra_edges: &str) -> String {
    let mut s = String::from("site type joint\n\npiece big {\n");
    for i in 0..n {
        s += &format!("    vertex b{i} ({i}, 0)\n    vertex t{i} ({i}, 1)\n");
    }
    s += extra_vertex;
    let bottom: Vec<String> = (0..n).map(|i| format!("b{i}")).collect();
    let top: Vec<String> = (0..n).rev().map(|i| format!("t{i}")).collect();
    s += &format!("    edges {}-{}-b0", bottom.join("-"), top.join("-"));
    for i in 0..n - 1 {
        s += &format!(", b{i}-t{}", i + 1);
    }
    s += extra_edges;
    s += "\n    site west: joint [t0, b0] out (-1, 0)\n";
    s += &format!("    site east: joint [b{0}, t{0}] out (1, 0)\n", n - 1);
    s += "    state lifted {\n";
    for i in (0..n).rev() {
        s += &format!("        t{i} ({i}, 2)\n        b{i} ({i}, 1)\n");
    }
    s += "    }\n}\n\nmodel {\n    a = big\n}\n";
    s
}

#[test]
fn a_large_piece_compiles_to_the_indices_its_names_give() {
    let n = 20_000;
    let out = compile(&ladder(n, "", ""), "big.clay", &CompileOptions::default()).unwrap();
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    let piece = &out.grammar.pieces[0];
    assert_eq!(piece.vertices.len(), 2 * n);
    assert_eq!(piece.edges.len(), 2 * n + (n - 1));
    // vertex `t{i}` is index 2i + 1; the east site is [b{n-1}, t{n-1}]
    assert_eq!(piece.vertices[2 * 7 + 1], "t7");
    assert_eq!(piece.sites[1].vertices, vec![2 * (n - 1), 2 * (n - 1) + 1]);
    // the diagonal b{i}-t{i+1} joins index 2i to 2i + 3
    assert!(piece.edges.contains(&[2 * 5, 2 * 6 + 1]));
    // the reversed state list lands on each vertex's own index
    let lifted = &piece.states[1].positions;
    assert_eq!(lifted[2 * 9 + 1].y, 2.0);
    assert_eq!(lifted[2 * 9].y, 1.0);
    assert_eq!(lifted[2 * 9].x, 9.0);
}

#[test]
fn a_large_piece_reports_its_repeats_where_they_are_written() {
    let n = 20_000;
    // a vertex declared twice, and an edge listed again the other way round
    let src = ladder(n, "    vertex t5 (5, 3)\n", ", t3-b2");
    let d = compile(&src, "big.clay", &CompileOptions::default()).unwrap_err();
    let dup: Vec<_> = d.iter().filter(|x| x.code == "E010").collect();
    assert_eq!(
        dup.len(),
        1,
        "{:?}",
        d.iter().map(|x| &x.message).collect::<Vec<_>>()
    );
    let at = dup[0].primary.span.start;
    assert!(src[at..].starts_with("t5 (5, 3)"), "{}", &src[at..at + 20]);
    let src = ladder(n, "", ", t3-b2");
    let out = compile(&src, "big.clay", &CompileOptions::default()).unwrap();
    let repeat: Vec<_> = out
        .warnings
        .iter()
        .filter(|x| x.message.contains("listed twice"))
        .collect();
    assert_eq!(repeat.len(), 1);
    let first = repeat[0].secondary[0].span;
    assert_eq!(&src[first.start..first.end], "b2-t3");
    let again = repeat[0].primary.span;
    assert_eq!(&src[again.start..again.end], "t3-b2");
}
