//! Every gesture and key of the editor, in one table: the F1 / `?` overlay lists it, and
//! `docs/editor.md` repeats it (a test checks that each row is there).

/// One row: the keys or gesture, and what it does.
pub type Row = (&'static str, &'static str);

/// Sculpt mode.
pub const SCULPT: &[Row] = &[
    (
        "Drag a part",
        "pull it: the part is the handle, the model follows elastically; held near the view's edge, the view follows the drag",
    ),
    (
        "Right-drag, or Shift + drag",
        "turn the part about its centre",
    ),
    (
        "Drag empty space, middle-drag, Space + drag",
        "pan the view",
    ),
    ("Wheel, pinch, Ctrl + wheel", "zoom toward the cursor"),
    (
        "P",
        "pin or unpin the part under the cursor (a pinned part stays put)",
    ),
    (
        "Hold Ctrl",
        "show the connection a cut would split (magenta ring)",
    ),
    ("Ctrl + click", "cut that connection"),
    ("F", "fit the model into the view"),
    (
        "I",
        "isometric 3D view on or off (View menu); sculpting is off while it is on",
    ),
    (
        "Hover a part",
        "the Inspector says why it is in its rest state",
    ),
];

/// Author mode.
pub const AUTHOR: &[Row] = &[
    (
        "D",
        "Draw tool: click to add points, click the first point to close the shape",
    ),
    (
        "Enter, double-click",
        "finish an open stroke (Esc drops it, Backspace takes a point back)",
    ),
    (
        "C",
        "Cut tool: click on the drawing to cut it there; right-click a cut removes it",
    ),
    (
        "S",
        "Site tool: click a docking site to pick it; the panel sets its type",
    ),
    ("F", "fit the drawing into the view"),
];

/// Both modes.
pub const GLOBAL: &[Row] = &[
    ("Tab", "switch between Sculpt and Author"),
    (
        "Ctrl + Z",
        "undo the last gesture (with the rules it fired)",
    ),
    ("Ctrl + Shift + Z, Ctrl + Y", "redo"),
    ("Ctrl + O", "open a grammar"),
    ("Ctrl + S", "save the session"),
    ("Ctrl + Q", "quit (asks first about unsaved changes)"),
    ("F1, ?", "show or hide this list"),
    ("Esc", "close this list or a dialog"),
];

/// The overlay listing every gesture and key; `open` is cleared when it is closed.
pub fn show(ctx: &egui::Context, open: &mut bool) {
    if !*open {
        return;
    }
    let mut keep = true;
    egui::Window::new("Gestures and keys")
        .id(egui::Id::unique("help overlay"))
        .collapsible(false)
        .resizable(false)
        .open(&mut keep)
        .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
        .show(ctx, |ui| {
            egui::Grid::new("help rows")
                .num_columns(2)
                .striped(true)
                .show(ui, |ui| {
                    for (title, rows) in [
                        ("Sculpt", SCULPT),
                        ("Author", AUTHOR),
                        ("Everywhere", GLOBAL),
                    ] {
                        ui.heading(title);
                        ui.end_row();
                        for (keys, what) in rows {
                            ui.strong(*keys);
                            ui.label(*what);
                            ui.end_row();
                        }
                    }
                });
            ui.label("F1 or ? closes this list.");
        });
    *open &= keep;
}
