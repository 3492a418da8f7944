//! Writes the editor screenshots in `docs/pictures/` (`editor-*.png`) from the scenes that
//! `tests/screenshots.rs` compares them with: `cargo run -p clay-editor --example screenshots`.

#[path = "../tests/screens/mod.rs"]
mod screens;

fn main() {
    for (name, mut h) in screens::scenes() {
        let image = h.render().expect("wgpu renders the editor");
        let path = screens::pictures().join(name);
        image.save(&path).expect("the picture is written");
        println!("wrote {}", path.display());
    }
}
