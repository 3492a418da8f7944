//! One truth per setting (issue 47): the solver settings' tables in docs/language.md (a
//! grammar's `solver { }` block) and docs/scripts.md (`clayc run --set`) are the settings
//! table of `clay_dsl::settings`, row for row, so no doc gives a range or a default the code
//! does not check.

use clay_dsl::settings::SETTINGS;

fn doc(name: &str) -> String {
    std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../docs")
            .join(name),
    )
    .unwrap()
}

/// The rows of the table under `header` in `text`.
fn table(text: &str, header: &str) -> String {
    let start = text
        .find(header)
        .unwrap_or_else(|| panic!("no table {header:?}"));
    text[start..]
        .lines()
        .take_while(|l| l.starts_with('|'))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn the_solver_block_table_is_the_settings_table() {
    let header = "| parameter | default | allowed | meaning |";
    let mut want = vec![header.to_string(), "|---|---|---|---|".to_string()];
    for s in SETTINGS.iter().filter(|s| s.in_grammar) {
        want.push(format!(
            "| `{}` | {} | {} | {} |",
            s.name,
            s.default,
            s.range.words(),
            s.meaning
        ));
    }
    let want = want.join("\n");
    assert_eq!(
        table(&doc("language.md"), header),
        want,
        "docs/language.md should read:\n{want}"
    );
}

#[test]
fn the_set_table_is_the_settings_table() {
    let header = "| name | range | default | meaning |";
    let mut want = vec![header.to_string(), "|---|---|---|---|".to_string()];
    for s in SETTINGS {
        want.push(format!(
            "| `{}` | {} | {} | {} |",
            s.name,
            s.range.interval(),
            s.default,
            s.meaning
        ));
    }
    let want = want.join("\n");
    assert_eq!(
        table(&doc("scripts.md"), header),
        want,
        "docs/scripts.md should read:\n{want}"
    );
}
