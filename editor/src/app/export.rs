//! Exports of the sculpt: the view as PNG, the deformed assembly as JSON, the model as glTF or
//! OBJ, the gestures as a script, each through the library code `clayc` uses.

use std::path::Path;

use glam::DVec2;

use super::EditorApp;

impl EditorApp {
    /// Renders the current view to PNG through the same renderer as `clayc render`.
    pub fn export_png(&self, path: &Path) -> Result<(), String> {
        let rect = self.canvas.rect;
        let width = (rect.width().round() as u32).max(16);
        let height = (rect.height().round() as u32).max(16);
        let cam = self.canvas.camera;
        let mut pins = Vec::new();
        for pin in self.sculpt.pins() {
            pins.extend(pin.vertices);
        }
        let options = clay::RenderOptions {
            width,
            height,
            view: Some(clay::View {
                scale: cam.scale,
                world_origin: cam.centre,
                pixel_origin: DVec2::new(width as f64 / 2.0, height as f64 / 2.0),
            }),
            overlays: clay::Overlays {
                pins,
                ..Default::default()
            },
            ..Default::default()
        };
        let png = clay::render_png(self.sculpt.grammar(), self.sculpt.data(), &options)
            .map_err(|e| e.to_string())?;
        clay::write_atomic(path, &png).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Writes the deformed assembly as JSON (the contract's `AssemblyData`).
    pub fn export_json(&self, path: &Path) -> Result<(), String> {
        let text = serde_json::to_string_pretty(self.sculpt.data()).map_err(|e| e.to_string())?;
        clay::write_atomic(path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Writes the gestures since the grammar's initial model as a script (atomically), which
    /// `clayc run GRAMMAR --script PATH` replays. Returns the status line: what was written and
    /// how to replay it, with the `--set`s of solver settings changed from the grammar's and
    /// the `--param`s of the grammar parameters set.
    pub fn save_gestures(&self, path: &Path) -> Result<String, String> {
        let script = self
            .sculpt
            .gesture_script()
            .map_err(|why| format!("no gestures to save: {why}"))?;
        let text = script.to_json();
        // What is written must read back as the same steps (a non-finite point would not).
        match clay::Script::parse(&text) {
            Ok(back) if back == script => {}
            Ok(_) => return Err("the gestures do not read back as the same script".into()),
            Err(e) => return Err(format!("the gestures do not make a valid script: {e}")),
        }
        clay::write_atomic(path, text.as_bytes())
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let solver = &self.sculpt.grammar().solver;
        let settings = self.sculpt.settings();
        let mut sets = String::new();
        if settings.hysteresis != solver.hysteresis {
            sets += &format!(" --set hysteresis={}", settings.hysteresis);
        }
        if settings.norm != solver.norm {
            sets += &format!(" --set norm={}", settings.norm);
        }
        // The grammar's parameters as the Grammar parameters panel set them.
        for (name, value) in &self.param_overrides {
            sets += &format!(" --param {name}={value}");
        }
        Ok(format!(
            "saved {} steps, {} frames, to {}; replay: clayc run {} --script {}{sets}",
            script.steps.len(),
            script.frame_count(),
            path.display(),
            self.display_path(),
            path.display()
        ))
    }

    /// Writes the sculpted model as 3D meshes with `clayc export`'s code; the format comes from
    /// the extension (`.glb`, `.gltf`, `.obj`, whose `.mtl` is written beside it, `.usda`).
    pub fn export_3d(&self, path: &Path) -> Result<(), String> {
        let Some(format) = clay::ExportFormat::of_path(path) else {
            return Err(format!(
                "cannot tell the format of `{}`: {}",
                path.display(),
                clay::ExportFormat::unknown(path)
            ));
        };
        let scene = clay::scene(
            self.sculpt.grammar(),
            self.sculpt.data(),
            &Default::default(),
        );
        clay::write_export(&scene, path, format).map_err(|e| e.to_string())
    }
}
