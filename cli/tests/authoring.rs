//! `clayc author` and `clayc fmt` on the command line (issue 7): a drawing authored to a
//! grammar file that compiles and sculpts (through `clayc run`), declarations it cannot take
//! refused naming them, drawings it cannot take refused with exit 1 and nothing written, bad
//! arguments exit 2; `clayc fmt`'s contract (stdout, --write, --check, exit codes). What
//! authoring makes of a drawing is `clay::authoring`'s, tested in the clay crate's
//! `tests/authoring.rs`.

use std::path::PathBuf;
use std::process::Command;

/// The repository's root, where the fixtures and example grammars are.
const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(ROOT)
        .join("tests/fixtures/authoring")
        .join(name)
}

fn clayc(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_clayc"))
        .args(args)
        .output()
        .unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-authoring-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn compiles_clean(text: &str) -> clay_dsl::CompiledGrammar {
    match clay_dsl::compile(text, "authored.clay", &clay_dsl::CompileOptions::default()) {
        Ok(c) => c.grammar,
        Err(d) => panic!(
            "authored grammar does not compile:\n{}\n{text}",
            clay_dsl::render(&d, text, "authored.clay", false)
        ),
    }
}

/// A closed SVG path through `points` (SVG units).
fn svg_path(id: &str, points: &[(f64, f64)]) -> String {
    let d: Vec<String> = points
        .iter()
        .enumerate()
        .map(|(i, (x, y))| format!("{}{x:.4} {y:.4}", if i == 0 { "M" } else { "L" }))
        .collect();
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"1000\" height=\"1000\"><path id=\"{id}\" d=\"{} Z\"/></svg>",
        d.join(" ")
    )
}

/// A closed path of `n` points that crosses itself all over: a star polygon (every edge
/// crosses many others), or a pseudo-random walk over the page.
fn self_intersecting(n: usize, star: bool) -> String {
    let mut seed = n as u64;
    let mut next = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let k = n / 2 - 1;
    let points: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            if star {
                let a = std::f64::consts::TAU * (i * k % n) as f64 / n as f64;
                (500.0 + 400.0 * a.cos(), 500.0 + 400.0 * a.sin())
            } else {
                (1000.0 * next(), 1000.0 * next())
            }
        })
        .collect();
    svg_path("scribble", &points)
}

#[test]
fn a_stretchable_authored_wall_grows_when_pulled() {
    let out = scratch("wall.clay");
    let o = clayc(&[
        "author",
        fixture("wall.svg").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--stretch",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("stretch brick from west to east"), "{text}");
    assert!(
        text.contains("= chain brick x 6"),
        "consecutive stretchable bricks form a chain:\n{text}"
    );
    let g = compiles_clean(&text);
    assert_eq!(g.stretch_rules.len(), 1);
    // Pin the west end, drag the east end out to twice the length.
    let o = clayc(&[
        "run",
        out.to_str().unwrap(),
        "--script",
        fixture("pull_east.json").to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let bricks = summary["pieces"]["brick"].as_u64().unwrap();
    assert!(
        bricks > 6,
        "the wall should grow bricks, has {bricks}: {summary}"
    );
    let bbox = summary["bbox"].as_array().unwrap();
    let width = bbox[2].as_f64().unwrap() - bbox[0].as_f64().unwrap();
    assert!(width > 11.0, "dragged to about 12 m, is {width}");
}

#[test]
fn fmt_prints_checks_and_writes_with_the_documented_exit_codes() {
    let messy = "site type joint\npiece p{vertex a(0,0) vertex b (1,0) // b\nvertex c(0,1)\nedges a-b-c-a\n site s: joint [a, b] out (0, -1)}\nmodel{x=p}\n";
    let file = scratch("messy.clay");
    std::fs::write(&file, messy).unwrap();
    let f = file.to_str().unwrap();
    // stdout by default, the file untouched.
    let o = clayc(&["fmt", f]);
    assert_eq!(o.status.code(), Some(0));
    let printed = String::from_utf8(o.stdout).unwrap();
    assert_eq!(printed, clay_dsl::format(messy).unwrap());
    assert!(printed.contains("    vertex b (1, 0) // b\n"));
    assert_eq!(std::fs::read_to_string(&file).unwrap(), messy);
    // --check: 1 and the file listed while it would change; 0 after --write.
    let o = clayc(&["fmt", "--check", f]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stdout).contains("messy.clay"));
    assert_eq!(clayc(&["fmt", "--write", f]).status.code(), Some(0));
    assert_eq!(std::fs::read_to_string(&file).unwrap(), printed);
    let o = clayc(&["fmt", "--check", f]);
    assert_eq!(o.status.code(), Some(0));
    assert!(o.stdout.is_empty());
    // A file that does not parse: diagnostics, exit 1, never rewritten.
    let broken = scratch("broken.clay");
    std::fs::write(&broken, "piece p { vertex a (0, }\n").unwrap();
    let o = clayc(&["fmt", "--write", broken.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("E001"));
    assert_eq!(
        std::fs::read_to_string(&broken).unwrap(),
        "piece p { vertex a (0, }\n"
    );
    // I/O errors win: 2.
    assert_eq!(
        clayc(&["fmt", "--check", f, "/nonexistent/x.clay"])
            .status
            .code(),
        Some(2)
    );
    // Every example grammar formats to text that still compiles.
    let dir = PathBuf::from(ROOT).join("grammars");
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "clay") {
            continue;
        }
        let o = clayc(&["fmt", p.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(0), "{}", p.display());
        assert!(
            // At the file's own path: its `mesh` assets are found beside it.
            clay_dsl::compile(
                &String::from_utf8(o.stdout).unwrap(),
                p.to_str().unwrap(),
                &clay_dsl::CompileOptions::default()
            )
            .is_ok(),
            "{}",
            p.display()
        );
    }
}

#[test]
fn clayc_author_writes_merges_and_posed_states_as_the_editor_does() {
    let wall = fixture("wall.svg");
    let o = clayc(&[
        "author",
        wall.to_str().unwrap(),
        "-o",
        "-",
        "--merge",
        "brick.east:brick.west",
        "--state",
        "brick:lean:0,0;1,0;1.2,0.5;0.2,0.5",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("merge brick.east onto brick.west"), "{text}");
    assert!(text.contains("state lean {"), "{text}");
    let g = compiles_clean(&text);
    assert_eq!(g.merge_rules.len(), 1);
    let brick = g.pieces.iter().find(|p| p.name == "brick").unwrap();
    let lean = brick.states.iter().find(|s| s.name == "lean").unwrap();
    assert_eq!(lean.positions[2], glam::DVec2::new(1.2, 0.5));

    // A declaration the drawing cannot take is an error naming it, and nothing is written.
    let out = scratch("refused.clay");
    let _ = std::fs::remove_file(&out);
    let o = clayc(&[
        "author",
        wall.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--state",
        "tower:tall:0,0",
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("state `tall` does not apply"), "{err}");
    assert!(!out.exists());
    // Variants belong to the stretch rule.
    let o = clayc(&[
        "author",
        wall.to_str().unwrap(),
        "-o",
        "-",
        "--variant",
        "brick=1",
    ]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn every_authoring_fixture_is_authored_clean_or_refused_clearly() {
    let dir = PathBuf::from(ROOT).join("tests/fixtures/authoring");
    let mut svgs: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "svg"))
        .collect();
    svgs.sort();
    assert!(svgs.len() >= 10);
    for svg in svgs {
        for stretch in [false, true] {
            let out = scratch("fixture.clay");
            let _ = std::fs::remove_file(&out);
            let mut args = vec!["author", svg.to_str().unwrap(), "-o", out.to_str().unwrap()];
            if stretch {
                args.push("--stretch");
            }
            let o = clayc(&args);
            let err = String::from_utf8_lossy(&o.stderr);
            match o.status.code() {
                Some(0) => {
                    compiles_clean(&std::fs::read_to_string(&out).unwrap());
                }
                Some(1) => {
                    assert!(
                        err.starts_with(&format!("error: {}", svg.display())),
                        "{}: {err}",
                        svg.display()
                    );
                    assert!(!out.exists());
                }
                code => panic!("{} exited {code:?}: {err}", svg.display()),
            }
        }
    }
}

#[test]
fn clayc_author_refuses_a_missing_drawing_and_a_bad_cut_with_exit_2() {
    let o = clayc(&["author", "/nonexistent.svg", "-o", "/tmp/x.clay"]);
    assert_eq!(o.status.code(), Some(2));
    let o = clayc(&[
        "author",
        fixture("wall.svg").to_str().unwrap(),
        "-o",
        "-",
        "--cut",
        "1,x",
    ]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn clayc_author_refuses_an_outline_that_crosses_itself_at_its_svg_line() {
    // The CLI: exit 1, the SVG's line of the path, nothing written.
    let out = scratch("bowtie.clay");
    let _ = std::fs::remove_file(&out);
    let o = clayc(&[
        "author",
        fixture("bowtie.svg").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("bowtie.svg:3: the outline of path `bowtie` crosses itself"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn clayc_author_refuses_ten_thousand_points_that_cross_themselves() {
    // 2,000 points wrote 2,970 errors; 4,000 and 10,000 took 3.7 s and over 45 s (issue 37).
    let file = scratch("scribble.svg");
    std::fs::write(&file, self_intersecting(10_000, false)).unwrap();
    let o = clayc(&["author", file.to_str().unwrap(), "-o", "-"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(o.stdout.is_empty());
}

#[test]
fn clayc_author_refuses_a_tolerance_finer_than_the_grammar_is_written_in() {
    let o = clayc(&[
        "author",
        fixture("wall.svg").to_str().unwrap(),
        "-o",
        "-",
        "--tolerance",
        "1e-9",
    ]);
    assert_eq!(o.status.code(), Some(2));
}
