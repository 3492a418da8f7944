//! No input makes the compiler panic or hang: random mutations of valid grammars, truncations,
//! binary junk, absurd numbers and nesting. Every error comes with spans inside the source.

use clay_dsl::{CompileOptions, Diagnostics, compile, decode_utf8, render};

const EMBEDDED: &str = r#"
solver { merge_distance = 0.3 hysteresis = 0.2 }
site type joint
site type plug docks joint
piece brick {
    vertex sw (0, 0)
    vertex se (1, 0)
    vertex ne (1, 0.5)
    vertex nw (0, 0.5)
    edges sw-se-ne-nw-sw, sw-ne
    site west: joint [nw, sw] out (-1, 0)
    site east: joint [se, ne] out (1, 0)
    polygon skinned fill #b5651d { (0.03, 0.03) (0.97, 0.03) (0.97, 0.47) (0.03, 0.47) hole { (0.4, 0.2) (0.6, 0.2) (0.5, 0.3) } }
}
piece tower {
    vertex a (-1, -1) vertex b (1, -1) vertex c (1, 1) vertex d (-1, 1)
    vertex p (-0.25, 1) vertex q (0.25, 1)
    edges a-b-c-q-p-d-a, a-c
    site north: plug [q, p] out (0, 1)
    state squat { a (-1, -1) b (1, -1) c (1, 0.5) d (-1, 0.5) p (-0.25, 0.5) q (0.25, 0.5) polyline width 0.1 fill #00000080 { (0, 0) (1, 0.4) } }
    axis north -> north
}
stretch brick from west to east { min 2 variants { brick 1 } }
merge brick.east onto brick.west within 0.4
model {
    wall = chain brick x 5 at (0, 0) rotate 30
    t = tower
    dock wall[0].west to t.north
}
"#;

/// A tiny deterministic generator (xorshift64*), so failures reproduce.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const TOKENS: &[&str] = &[
    "(", ")", "{", "}", "[", "]", ",", ".", "-", "->", ":", "=", "#", "#fff", "0", "-1", "1e400",
    "1e308", "9999999", "0.5", "brick", "piece", "site", "model", "stretch", "merge", "cut",
    "chain", "x", "dock", "state", "edges", "vertex", "wall[0]", "last", "/*", "*/", "//", "\n",
    " ", "é", "\u{0}", "skinned", "rigid", "at", "rotate", "+", "*", "/", "let", "w", "sin(", "pi",
    "1 / 0", "sqrt(-1)", "max()", "bend", "mirror", "base", "360", "-90",
];

fn mutate(rng: &mut Rng, src: &str) -> String {
    let mut s = src.to_string();
    for _ in 0..1 + rng.below(3) {
        let mut at = rng.below(s.len() + 1);
        while !s.is_char_boundary(at) {
            at -= 1;
        }
        match rng.below(6) {
            0 => {
                let mut end = (at + rng.below(20)).min(s.len());
                while !s.is_char_boundary(end) {
                    end += 1;
                }
                s.replace_range(at..end, "");
            }
            1 | 2 => s.insert_str(at, TOKENS[rng.below(TOKENS.len())]),
            3 => s.truncate(at),
            4 => {
                // Duplicate a line elsewhere (duplicate names, docks, blocks).
                let lines: Vec<&str> = s.lines().collect();
                let line = lines[rng.below(lines.len())].to_string();
                s.insert_str(at, &format!("\n{line}\n"));
            }
            _ => {
                // Replace a digit run with something extreme.
                if let Some(d) = s[at..].find(|c: char| c.is_ascii_digit()) {
                    let start = at + d;
                    let end = start
                        + s[start..]
                            .find(|c: char| !c.is_ascii_digit())
                            .unwrap_or(s.len() - start);
                    let repl =
                        ["0", "-0", "1e400", "100000000", "3", "1e-300", "2.5"][rng.below(7)];
                    s.replace_range(start..end, repl);
                }
            }
        }
    }
    s
}

fn assert_spans_valid(diags: &Diagnostics, src: &str, what: &str) {
    assert!(!diags.is_empty(), "{what}: Err without diagnostics");
    assert!(diags.has_errors(), "{what}: Err without an error");
    for d in diags {
        for l in std::iter::once(&d.primary).chain(&d.secondary) {
            assert!(
                l.span.start <= l.span.end && l.span.end <= src.len(),
                "{what}: {} span {:?} outside 0..{}",
                d.code,
                l.span,
                src.len()
            );
        }
        assert!(!d.message.is_empty());
    }
}

fn check(src: &str, what: &str) {
    match compile(src, "fuzz.clay", &CompileOptions::default()) {
        Ok(c) => {
            for d in &c.warnings {
                assert!(d.primary.span.end <= src.len(), "{what}");
            }
            assert!(
                c.grammar.assembly.positions.iter().all(|p| p.is_finite()),
                "{what}: non-finite output"
            );
        }
        Err(d) => {
            assert_spans_valid(&d, src, what);
            let _ = render(&d, src, "fuzz.clay", false);
        }
    }
}

fn bases() -> Vec<(String, String)> {
    let mut out = vec![("embedded".to_string(), EMBEDDED.to_string())];
    if let Ok(entries) = std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../grammars")) {
        for e in entries.flatten() {
            let p = e.path();
            if p.extension().is_some_and(|x| x == "clay")
                && let Ok(s) = std::fs::read_to_string(&p)
            {
                out.push((p.display().to_string(), s));
            }
        }
    }
    out
}

#[test]
fn the_embedded_grammar_is_valid() {
    let c = compile(EMBEDDED, "e.clay", &CompileOptions::default())
        .map_err(|d| render(&d, EMBEDDED, "e.clay", false));
    // The tower's axis names one site twice, which is an error: make sure the fuzz base is
    // interesting (errors and successes both get mutated), and that the message is the one
    // expected.
    let err = c.expect_err("axis north -> north is not two opposite sites");
    assert!(err.contains("E040"), "{err}");
    let fixed = EMBEDDED.replace("    axis north -> north\n", "");
    compile(&fixed, "e.clay", &CompileOptions::default())
        .map_err(|d| render(&d, &fixed, "e.clay", false))
        .unwrap();
}

#[test]
fn thousands_of_mutations_never_panic() {
    let mut rng = Rng(0x5eed_c1a7);
    let mut bases = bases();
    bases.push((
        "embedded-fixed".into(),
        EMBEDDED.replace("    axis north -> north\n", ""),
    ));
    let per_base = 3000 / bases.len() + 1;
    let (mut oks, mut errs) = (0, 0);
    for (name, src) in &bases {
        for k in 0..per_base {
            let m = mutate(&mut rng, src);
            let what = format!("{name} mutation {k}");
            check(&m, &what);
            if compile(&m, "f", &CompileOptions::default()).is_ok() {
                oks += 1;
            } else {
                errs += 1;
            }
        }
    }
    // Both outcomes occur, so the mutations exercise the compiler beyond the parser.
    assert!(oks > 50 && errs > 50, "ok {oks}, err {errs}");
}

#[test]
fn every_truncation_of_a_grammar_returns() {
    for end in 0..=EMBEDDED.len() {
        if EMBEDDED.is_char_boundary(end) {
            check(&EMBEDDED[..end], &format!("prefix {end}"));
        }
    }
}

#[test]
fn binary_and_non_utf8_input_is_reported() {
    let mut rng = Rng(42);
    for _ in 0..200 {
        let bytes: Vec<u8> = (0..rng.below(300)).map(|_| rng.next() as u8).collect();
        match decode_utf8(&bytes).and_then(|s| compile(s, "bin.clay", &CompileOptions::default())) {
            Ok(_) => {}
            Err(d) => assert_spans_valid(&d, &String::from_utf8_lossy(&bytes), "binary"),
        }
    }
    let d = decode_utf8(b"site type j\n\xff\xfe")
        .and_then(|s| compile(s, "x.clay", &CompileOptions::default()))
        .unwrap_err();
    assert_eq!(d.items[0].code, "E003");
    assert_eq!(d.items[0].primary.span.start, 12);
}

#[test]
fn deep_nesting_is_rejected_before_parsing() {
    for src in [
        "(".repeat(10_000),
        "/*".repeat(10_000),
        format!("model {{ a = b at {} }}", "[".repeat(100_000)),
    ] {
        let d = compile(&src, "deep.clay", &CompileOptions::default()).unwrap_err();
        assert_eq!(d.items[0].code, "E002");
        assert_spans_valid(&d, &src, "deep");
    }
    // Nesting within the limit is an ordinary syntax error.
    let d = compile(&"(".repeat(200), "x", &CompileOptions::default()).unwrap_err();
    assert_eq!(d.items[0].code, "E001");
}

#[test]
fn deep_and_absurd_expressions_are_diagnosed_not_crashed() {
    let base = EMBEDDED.replace("    axis north -> north\n", "");
    let cases = [
        format!("({}1{}, 0)", "(".repeat(250), ")".repeat(250)),
        format!("({}1, 0)", "-".repeat(100_000)),
        format!("({}, 0)", vec!["1"; 100_000].join("*")),
        format!("(sin({}1{}), 0)", "cos(".repeat(200), ")".repeat(200)),
        "(1e308 * 1e308 * 0, 0)".to_string(),
        "(1e-320 / 1e-320 / 0, 0)".to_string(),
        "(max(1e308, 1e308) + 1e308, 0)".to_string(),
    ];
    for case in cases {
        let src = base.replacen("(1, 0)", &case, 1);
        assert_ne!(src, base);
        let d = compile(&src, "x", &CompileOptions::default()).unwrap_err();
        assert_spans_valid(&d, &src, "expression");
        let codes: Vec<&str> = d.iter().map(|d| d.code).collect();
        assert_eq!(codes.len(), 1, "{}: {codes:?}", &case[..case.len().min(40)]);
    }
}

#[test]
fn absurd_numbers_are_diagnosed() {
    let base = EMBEDDED.replace("    axis north -> north\n", "");
    let d = compile(
        &base.replace("x 5", "x 100000000"),
        "x",
        &CompileOptions::default(),
    )
    .unwrap_err();
    assert!(d.iter().any(|d| d.code == "E014"));
    let d = compile(
        &base.replace("(1, 0)", "(1e400, 0)"),
        "x",
        &CompileOptions::default(),
    )
    .unwrap_err();
    assert!(d.iter().any(|d| d.code == "E012"));
    let d = compile(
        &base.replace("(1, 0)", "(1e300, 0)"),
        "x",
        &CompileOptions::default(),
    )
    .unwrap_err();
    assert!(d.iter().any(|d| d.code == "E013"));
    let d = compile(
        &base.replace("wall[0].west", "wall[99999999999999999999999].west"),
        "x",
        &CompileOptions::default(),
    )
    .unwrap_err();
    assert!(d.iter().any(|d| d.code == "E015"));
}

#[test]
fn a_model_at_the_instance_limit_compiles_and_one_more_is_e014() {
    let base = EMBEDDED.replace("    axis north -> north\n", "");
    let limit = clay_dsl::MAX_MODEL_INSTANCES;
    // the embedded model holds one instance besides the chain
    let at = base.replace("x 5", &format!("x {}", limit - 1));
    let c = compile(&at, "big.clay", &CompileOptions::default()).unwrap();
    assert_eq!(c.grammar.assembly.instances.len(), limit);
    let over = base.replace("x 5", &format!("x {limit}"));
    let d = compile(&over, "big.clay", &CompileOptions::default()).unwrap_err();
    assert_eq!(d.iter().map(|d| d.code).collect::<Vec<_>>(), ["E014"]);
}

/// Serves `lib.clay` from memory.
struct OneLib(Vec<u8>);

impl clay_dsl::Loader for OneLib {
    fn load(&self, path: &str) -> std::io::Result<Vec<u8>> {
        match path {
            "lib.clay" => Ok(self.0.clone()),
            _ => Err(std::io::ErrorKind::NotFound.into()),
        }
    }
}

/// Every label lies inside the main file or inside one imported file, and renders.
fn check_imported(main: &str, d: &Diagnostics, what: &str) {
    for diag in d {
        for l in std::iter::once(&diag.primary).chain(&diag.secondary) {
            let in_main = l.span.end <= main.len();
            let in_lib = d
                .sources
                .files
                .iter()
                .any(|f| f.base <= l.span.start && l.span.end <= f.end());
            assert!(in_main || in_lib, "{what}: {} span {:?}", diag.code, l.span);
        }
    }
    let _ = render(d, main, "main.clay", false);
    let _ = clay_dsl::to_json(d, main, "main.clay");
}

#[test]
fn imports_of_itself_of_a_missing_file_and_of_a_binary_file_are_diagnosed() {
    let d = compile(
        "import \"me.clay\"\n",
        "me.clay",
        &CompileOptions::default(),
    )
    .unwrap_err();
    assert_eq!(d.items[0].code, "E061");
    assert_spans_valid(&d, "import \"me.clay\"\n", "self");
    let d = compile(
        "import \"no/such/file.clay\"",
        "x.clay",
        &CompileOptions::default(),
    )
    .unwrap_err();
    assert_eq!(d.items[0].code, "E060");
    let d = compile("import \"\"", "x.clay", &CompileOptions::default()).unwrap_err();
    assert_eq!(d.items[0].code, "E060", "a folder is not a file");
    let mut rng = Rng(7);
    for _ in 0..50 {
        let bytes: Vec<u8> = (0..rng.below(300)).map(|_| rng.next() as u8).collect();
        let main = "import \"lib.clay\"\nmodel { }";
        match clay_dsl::compile(
            main,
            "main.clay",
            &clay_dsl::CompileOptions::with_loader(&OneLib(bytes)),
        ) {
            Ok(c) => check_imported(main, &c.warnings, "binary lib"),
            Err(d) => check_imported(main, &d, "binary lib"),
        }
    }
}

#[test]
fn mutated_libraries_and_children_never_panic_and_point_into_their_files() {
    let mut rng = Rng(0x1a2b);
    let lib = EMBEDDED.replace("    axis north -> north\n", "");
    let lib = lib[..lib.find("model {").unwrap()].to_string();
    let main = "import \"lib.clay\"
piece brick2 extends brick { polygon fill #ff0000 { (0, 0) (1, 0) (1, 0.5) } }
piece tower2 extends tower { vertex top (0, 2) edges p-top-q }
model { w = chain brick x 3  t = tower2 at (0, 5)  b = brick2 at (0, 9) }";
    for k in 0..600 {
        let (m, l) = if k % 2 == 0 {
            (mutate(&mut rng, main), lib.clone())
        } else {
            (main.to_string(), mutate(&mut rng, &lib))
        };
        let what = format!("mutation {k}");
        match clay_dsl::compile(
            &m,
            "main.clay",
            &clay_dsl::CompileOptions::with_loader(&OneLib(l.into_bytes())),
        ) {
            Ok(c) => check_imported(&m, &c.warnings, &what),
            Err(d) => {
                assert!(d.has_errors(), "{what}");
                check_imported(&m, &d, &what);
            }
        }
    }
}

/// How long the 10,000-deep chain takes is timed by `benches/dsl.rs` (`dsl/extends_chain`).
#[test]
fn deep_and_cyclic_extends_chains_give_one_error() {
    let base = "piece p0 { vertex a (0, 0) vertex b (1, 0) edges a-b }\n";
    for n in [100, 10_000] {
        let mut src = base.to_string();
        for i in 1..n {
            src += &format!("piece p{i} extends p{} {{ vertex v{i} ({i}, 1) }}\n", i - 1);
        }
        src += &format!("model {{ x = p{} }}", n - 1);
        let d = compile(&src, "deep.clay", &CompileOptions::default()).unwrap_err();
        assert_eq!(d.items.iter().filter(|d| d.is_error()).count(), 1, "{n}");
        assert_eq!(d.items[0].code, "E063");
        assert_spans_valid(&d, &src, "deep extends");
    }
    // One long cycle: one error, every piece silent.
    let mut src = String::new();
    for i in 0..5000 {
        src += &format!("piece p{i} extends p{} {{ }}\n", (i + 1) % 5000);
    }
    let d = compile(&src, "cycle.clay", &CompileOptions::default()).unwrap_err();
    assert_eq!(d.error_count(), 1);
    let e = d.items.iter().find(|d| d.is_error()).unwrap();
    assert_eq!(e.code, "E062");
    assert!(e.message.contains("(5000 pieces in all)"), "{}", e.message);
    assert!(e.secondary.len() <= 8);
}

/// The deepest nesting the nesting scan lets through parses on a small thread stack: pest
/// runs without its own stack probe (dsl/src/lib.rs), so this bound is what keeps a spawned
/// thread (2 MiB by default, as in the editor and the language server) from overflowing.
#[test]
fn the_deepest_accepted_nesting_fits_a_small_thread_stack() {
    let base = EMBEDDED.replace("    axis north -> north\n", "");
    // Brackets: the piece's `{`, the point's own `(` and 254 inside it make 256.
    let depth = 254;
    let cases = [
        format!("({}1{}, 0)", "(".repeat(depth), ")".repeat(depth)),
        format!(
            "(sin({}1{}), 0)",
            "cos(".repeat(depth - 1),
            ")".repeat(depth - 1)
        ),
        format!(
            "(1, 0) {}{}",
            "/*".repeat(256), // the scan's MAX_NESTING
            "*/".repeat(256)
        ),
    ];
    for case in cases {
        let src = base.replacen("(1, 0)", &case, 1);
        assert_ne!(src, base);
        let worker = std::thread::Builder::new()
            .stack_size(512 * 1024)
            .spawn(move || {
                compile(&src, "deep.clay", &CompileOptions::default())
                    .map(|_| ())
                    .map_err(|d| (d.items[0].code, d.items[0].message.clone()))
            })
            .unwrap();
        let got = worker.join().expect("parsing overflowed a 512 KiB stack");
        // pest parsed it all: too deep an expression tree is the lowering's E002 (its own
        // limit), never the nesting scan's, and a comment is fine.
        match &got {
            Ok(()) => {}
            Err((code, message)) => {
                assert_eq!(*code, "E002", "{message}");
                assert!(
                    message.contains("expression is nested too deeply"),
                    "{message}"
                );
            }
        }
    }
}

/// Issue 47: 60,000 site types took 3.56 GB (an n x n matrix of docking flags) and a scan of
/// every type per lookup. Docking is now kept as the pairs the grammar writes: 20,000 types,
/// every odd one docking with the next, dock as written, symmetric, the even ones with
/// themselves too.
#[test]
fn twenty_thousand_site_types_dock_as_written() {
    let n = 20_000;
    let mut src = String::new();
    for i in 0..n {
        if i % 2 == 1 {
            src += &format!("site type t{i} docks t{}\n", (i + 1) % n);
        } else {
            src += &format!("site type t{i}\n");
        }
    }
    src += "piece p {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    vertex c (0, 1)\n    \
            edges a-b-c-a\n    site s: t5 [a, b] out (0, -1)\n}\n";
    let g = clay_dsl::compile(&src, "types.clay", &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar;
    assert_eq!(g.site_types.len(), n);
    for (i, t) in g.site_types.iter().enumerate() {
        let want: Vec<usize> = if i % 2 == 1 {
            vec![(i + 1) % n]
        } else {
            // itself (no `docks`), and the odd type before it that docks with it
            let mut v = vec![i, (i + n - 1) % n];
            v.sort_unstable();
            v
        };
        assert_eq!(t.docks_with, want, "t{i}");
    }
}
