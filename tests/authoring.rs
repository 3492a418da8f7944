//! Authoring (issue 7): drawings become grammars that compile and sculpt, and `clayc fmt`'s
//! command-line contract (stdout, --write, --check, exit codes).

use std::path::PathBuf;
use std::process::Command;

use clay::authoring::svg::drawing_from_svg;
use clay::authoring::{AuthorOptions, Drawing, Polyline, StretchChoice, author};
use glam::DVec2;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
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
    match clay_dsl::compile(text, "authored.clay") {
        Ok(c) => c.grammar,
        Err(d) => panic!(
            "authored grammar does not compile:\n{}\n{text}",
            clay_dsl::render(&d, text, "authored.clay", false)
        ),
    }
}

#[test]
fn six_identical_bricks_become_one_piece_with_six_instances() {
    let svg = std::fs::read_to_string(fixture("wall.svg")).unwrap();
    let drawing = drawing_from_svg(&svg, 0.01).unwrap();
    let authored = author(&drawing, &AuthorOptions::default()).unwrap();
    let d = &authored.design;
    assert_eq!(d.pieces.len(), 1, "{}", authored.text);
    assert_eq!(d.instances.len(), 6);
    assert_eq!(d.docks.len(), 5, "neighbours dock where they share an edge");
    assert_eq!(d.pieces[0].name, "brick", "named after the SVG ids");
    let g = compiles_clean(&authored.text);
    assert_eq!(g.assembly.instances.len(), 6);
    // Six 1 x 0.5 bricks sharing edges: 14 distinct corners, spanning 6 m (y flipped: 0..-0.5).
    assert_eq!(g.assembly.positions.len(), 14);
    let xs: Vec<f64> = g.assembly.positions.iter().map(|p| p.x).collect();
    let ys: Vec<f64> = g.assembly.positions.iter().map(|p| p.y).collect();
    let span = |v: &[f64]| {
        v.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - v.iter().cloned().fold(f64::INFINITY, f64::min)
    };
    assert!((span(&xs) - 6.0).abs() < 1e-9 && (span(&ys) - 0.5).abs() < 1e-9);
    // The output is already canonical.
    assert_eq!(clay_dsl::format(&authored.text).unwrap(), authored.text);
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

fn l_shape(at: DVec2, angle: f64) -> Polyline {
    let pts = [
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
        (0.0, 2.0),
    ];
    Polyline::polygon(
        pts.iter()
            .map(|&(x, y)| DVec2::from_angle(angle).rotate(DVec2::new(x, y)) + at)
            .collect(),
    )
}

#[test]
fn regions_equal_up_to_a_rigid_motion_are_one_piece() {
    let drawing = Drawing {
        polylines: vec![
            l_shape(DVec2::ZERO, 0.0),
            l_shape(DVec2::new(10.0, 3.0), 1.0),
            // Not congruent: a mirrored L is not a rigid motion of it.
            Polyline::polygon(vec![
                DVec2::new(20.0, 0.0),
                DVec2::new(18.0, 0.0),
                DVec2::new(18.0, 1.0),
            ]),
        ],
    };
    let authored = author(&drawing, &AuthorOptions::default()).unwrap();
    let d = &authored.design;
    assert_eq!(d.pieces.len(), 2);
    assert_eq!(d.instances.iter().filter(|i| i.piece == 0).count(), 2);
    let g = compiles_clean(&authored.text);
    // Every drawn corner is where the compiled model puts a vertex (placement by at/rotate).
    for line in &drawing.polylines[..2] {
        for p in &line.points {
            let nearest = g
                .assembly
                .positions
                .iter()
                .map(|q| q.distance(*p))
                .fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-5, "{p} is {nearest} from the model");
        }
    }
    // A tolerance below the perturbation keeps a slightly different region apart.
    let mut bent = l_shape(DVec2::new(10.0, 3.0), 1.0);
    bent.points[2] += DVec2::new(0.01, 0.0);
    let two = Drawing {
        polylines: vec![l_shape(DVec2::ZERO, 0.0), bent],
    };
    let strict = author(
        &two,
        &AuthorOptions {
            congruence: 1e-3,
            ..AuthorOptions::default()
        },
    )
    .unwrap();
    let loose = author(
        &two,
        &AuthorOptions {
            congruence: 0.02,
            ..AuthorOptions::default()
        },
    )
    .unwrap();
    assert_eq!(
        (strict.design.pieces.len(), loose.design.pieces.len()),
        (2, 1)
    );
}

#[test]
fn cuts_split_an_outline_into_docked_pieces() {
    // One 3 m x 0.5 m outline, cut at x = 1 and x = 2: three congruent pieces in a row.
    let outline = Polyline::polygon(vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(3.0, 0.0),
        DVec2::new(3.0, 0.5),
        DVec2::new(0.0, 0.5),
    ]);
    let options = AuthorOptions {
        cuts: vec![DVec2::new(1.0, 0.0), DVec2::new(2.0, 0.02)],
        stretch: Some(StretchChoice::Auto),
        ..AuthorOptions::default()
    };
    let authored = author(
        &Drawing {
            polylines: vec![outline],
        },
        &options,
    )
    .unwrap();
    let d = &authored.design;
    assert_eq!(
        (d.pieces.len(), d.instances.len(), d.docks.len()),
        (1, 3, 2),
        "{}",
        authored.text
    );
    let g = compiles_clean(&authored.text);
    assert_eq!(g.assembly.chains.len(), 1);
    assert_eq!(g.assembly.chains[0].instances.len(), 3);
    // The cut line runs across to the far side: a triangle cut at the middle of its base splits
    // into a triangle and a quadrilateral, docked along the cut.
    let triangle = Polyline::polygon(vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(1.0, 1.0),
    ]);
    let once = AuthorOptions {
        cuts: vec![DVec2::new(0.5, 0.0)],
        ..AuthorOptions::default()
    };
    let split = author(
        &Drawing {
            polylines: vec![triangle],
        },
        &once,
    )
    .unwrap();
    let sizes: Vec<usize> = split
        .design
        .pieces
        .iter()
        .map(|p| p.positions.len())
        .collect();
    assert_eq!(
        (sizes, split.design.docks.len()),
        (vec![3, 4], 1),
        "{}",
        split.text
    );
    compiles_clean(&split.text);
}

#[test]
fn bad_drawings_are_errors_not_panics() {
    assert!(drawing_from_svg("not svg", 0.01).is_err());
    assert!(drawing_from_svg("<svg xmlns='http://www.w3.org/2000/svg'/>", 0.01).is_err());
    assert!(
        drawing_from_svg(
            "<svg xmlns='http://www.w3.org/2000/svg'><rect width='1' height='1'/></svg>",
            f64::NAN
        )
        .is_err()
    );
    let nan = Drawing {
        polylines: vec![Polyline::polygon(vec![DVec2::ZERO, DVec2::X, DVec2::NAN])],
    };
    assert!(author(&nan, &AuthorOptions::default()).is_err());
    let open = Drawing {
        polylines: vec![Polyline {
            points: vec![DVec2::ZERO, DVec2::X],
            closed: false,
            fill: None,
            name: None,
        }],
    };
    assert!(
        author(&open, &AuthorOptions::default()).is_err(),
        "no closed path and no cut"
    );
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
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("grammars");
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "clay") {
            continue;
        }
        let o = clayc(&["fmt", p.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(0), "{}", p.display());
        assert!(
            // At the file's own path: its `mesh` assets are found beside it.
            clay_dsl::compile(&String::from_utf8(o.stdout).unwrap(), p.to_str().unwrap()).is_ok(),
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
fn the_editor_refuses_every_keyword_of_the_grammar_as_a_name() {
    // Every `kw_NAME` rule of the pest grammar is in the editor's keyword list.
    let pest =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/dsl/src/grammar.pest"))
            .unwrap();
    let keywords: Vec<&str> = pest
        .lines()
        .filter_map(|l| l.strip_prefix("kw_"))
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(keywords.len() > 30 && keywords.contains(&"bend"));
    for k in keywords {
        assert!(
            clay::authoring::work::KEYWORDS.contains(&k),
            "`{k}` is a keyword of grammar.pest but not in authoring::work::KEYWORDS"
        );
    }
}
