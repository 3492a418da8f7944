//! The editor screenshots in `docs/pictures/` show what the editor draws today: every scene
//! of `screens` is rendered again (wgpu, Mesa's software rasteriser on CI) and compared with
//! its file. Text that changes from run to run (the frame time in milliseconds) and the
//! rasteriser's anti-aliasing may differ in a few pixels (measured: 30-100 of 912,000), so a
//! picture is stale when more than 0.1% of its pixels differ by more than 24 levels in a
//! channel. When this fails, run
//! `cargo run -p clay-editor --example screenshots` and look at the new pictures.

mod screens;

/// Share of pixels allowed to differ: a changed number in a panel is about 0.01%; the castle
/// without its part-outline overlay differs in 0.56%, a moved part in several percent.
const MOST_DIFFERING: f64 = 0.001;

#[test]
fn editor_screenshots_match_what_the_editor_draws() {
    let mut stale = Vec::new();
    for (name, mut h) in screens::scenes() {
        let drawn = h.render().expect("wgpu renders the editor");
        let path = screens::pictures().join(name);
        let Ok(on_disk) = image::open(&path).map(|i| i.to_rgba8()) else {
            stale.push(format!("{name}: missing or unreadable"));
            continue;
        };
        if on_disk.dimensions() != drawn.dimensions() {
            stale.push(format!("{name}: size differs"));
            continue;
        }
        let differing = on_disk
            .pixels()
            .zip(drawn.pixels())
            .filter(|(a, b)| a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 24))
            .count();
        let share = differing as f64 / (drawn.width() * drawn.height()) as f64;
        eprintln!("{name}: {differing} pixels differ ({:.3}%)", 100.0 * share);
        if share > MOST_DIFFERING {
            stale.push(format!(
                "{name}: {:.2}% of the pixels differ",
                100.0 * share
            ));
        }
    }
    assert!(
        stale.is_empty(),
        "docs/pictures/ is stale (run `cargo run -p clay-editor --example screenshots`):\n{}",
        stale.join("\n")
    );
}
