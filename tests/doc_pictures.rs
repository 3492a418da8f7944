//! The pictures in `docs/pictures/` show what the code draws today: every grammar's sheet,
//! initial assembly and after-script assembly ([`clay::testing::gallery`]) are drawn again and compared
//! pixel by pixel with the files (rendering and solving are deterministic). When this fails,
//! run `cargo run --release --example pictures` and look at the new pictures before
//! committing them.

use std::path::Path;

use clay::Script;

#[test]
fn docs_pictures_match_what_the_code_draws() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut stale = Vec::new();
    let mut checked = 0;
    let mut grammars: Vec<_> = std::fs::read_dir(root.join("grammars"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "clay"))
        .collect();
    grammars.sort();
    for path in grammars {
        let name = path.file_stem().unwrap().to_str().unwrap().to_string();
        let source = std::fs::read_to_string(&path).unwrap();
        // the sheet's title names the grammar as the docs do
        let grammar = clay_dsl::compile(
            &source,
            &format!("grammars/{name}.clay"),
            &clay_dsl::CompileOptions::default(),
        )
        .unwrap()
        .grammar;
        let script_path = path.with_extension("script.json");
        let script = script_path
            .exists()
            .then(|| Script::parse(&std::fs::read_to_string(&script_path).unwrap()).unwrap());
        for picture in clay::testing::gallery::pictures(&name, &grammar, script.as_ref()).unwrap() {
            checked += 1;
            let file = root.join("docs/pictures").join(&picture.file);
            let drawn = tiny_skia::Pixmap::decode_png(&picture.png).unwrap();
            let on_disk = std::fs::read(&file)
                .ok()
                .and_then(|b| tiny_skia::Pixmap::decode_png(&b).ok());
            match on_disk {
                None => stale.push(format!("{}: missing or unreadable", picture.file)),
                Some(p) if (p.width(), p.height()) != (drawn.width(), drawn.height()) => {
                    stale.push(format!("{}: size differs", picture.file));
                }
                Some(p) => {
                    let differing = p
                        .pixels()
                        .iter()
                        .zip(drawn.pixels())
                        .filter(|(a, b)| a != b)
                        .count();
                    if differing > 0 {
                        let share = differing as f64 / drawn.pixels().len() as f64;
                        stale.push(format!(
                            "{}: {differing} pixels ({:.2}%) differ",
                            picture.file,
                            100.0 * share
                        ));
                    }
                }
            }
        }
    }
    assert!(checked >= 12, "only {checked} pictures checked");
    assert!(
        stale.is_empty(),
        "docs/pictures/ is stale (run `cargo run --release --example pictures`):\n{}",
        stale.join("\n")
    );
}
