//! The canvas: draws the posed assembly (the renderer's world triangles as egui meshes) with the
//! hovered, grabbed and pinned parts marked, finds the part or connection under the cursor, and
//! turns pointer and key input into [`Command`]s. It never changes the model itself.

use clay::{TessellationCache, WorldMesh, part_at, pose_assembly_into};
use clay_dsl::compiled::AssemblyData;
use egui::{Color32, Key, PointerButton, Pos2, Rect, Sense, Shape, Stroke, Vec2};
use glam::DVec2;

use super::overlay::ViewOverlays;
use super::{Command, Sculpt};
use crate::camera::{Camera, dv, pos};

/// Pointer distance (screen points) within which an edge or connection counts as under it.
const PICK_RADIUS: f64 = 10.0;
/// How near the canvas's edge (pixels) a drag held still makes the view follow it, and how
/// fast the view moves at the edge and beyond (pixels a frame).
const EDGE_ZONE: f32 = 40.0;
const EDGE_SPEED: f64 = 10.0;
/// How many frames a drag is held still near the edge before the view follows it.
const EDGE_STILL_FRAMES: u32 = 8;
const HOVER: Color32 = Color32::from_rgba_premultiplied(120, 90, 0, 90);
const GRABBED: Color32 = Color32::from_rgb(220, 30, 60);
const PINNED: Color32 = Color32::from_rgb(30, 80, 220);
const CUT: Color32 = Color32::from_rgb(230, 40, 160);
/// Zoom (points per metre) below which proxy outlines are not drawn.
const OUTLINE_MIN_SCALE: f64 = 20.0;
const EDGES: Color32 = Color32::from_rgb(70, 70, 90);

/// What a drag on the canvas is doing.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Drag {
    Pan,
    /// Moving the grabbed part: world point where the drag started.
    Move {
        start: DVec2,
    },
    /// Turning the grabbed part about `centre`; `start` is the pointer's initial angle.
    Rotate {
        centre: DVec2,
        start: f64,
    },
}

/// View state of the canvas, kept between frames.
pub struct Canvas {
    pub camera: Camera,
    cache: TessellationCache,
    meshes: Vec<WorldMesh>,
    /// The sculpt (grammar and revision) `meshes` were posed from.
    posed: Option<(usize, u64)>,
    drag: Option<Drag>,
    /// Frames a drag has been held still near the canvas's edge.
    edge_still: u32,
    /// Fit the view to the model at the next frame.
    fit_pending: bool,
    /// The part under the cursor in the last frame.
    pub hovered: Option<usize>,
    /// The connection (dock index) that Ctrl + click would cut.
    pub cut_target: Option<usize>,
    /// The canvas rectangle of the last frame (screen points).
    pub rect: Rect,
    /// Show the model in the isometric 3D view instead of the floor plan (View menu, I).
    pub iso: bool,
    /// The isometric view's last picture.
    pub iso_picture: Option<super::iso::IsoPicture>,
}

impl Default for Canvas {
    fn default() -> Self {
        Self {
            camera: Camera::default(),
            cache: TessellationCache::new(),
            meshes: Vec::new(),
            posed: None,
            drag: None,
            edge_still: 0,
            fit_pending: true,
            hovered: None,
            cut_target: None,
            rect: Rect::from_min_size(Pos2::ZERO, Vec2::splat(1.0)),
            iso: false,
            iso_picture: None,
        }
    }
}

impl Canvas {
    /// Fit the view at the next frame.
    pub fn request_fit(&mut self) {
        self.fit_pending = true;
    }

    /// The grammar changed: cached tessellations are stale.
    pub fn grammar_changed(&mut self) {
        self.cache.clear();
        self.posed = None;
    }

    /// Screen position of a world point in the last frame's canvas.
    pub fn to_screen(&self, p: DVec2) -> Pos2 {
        pos(self.camera.to_screen(p, dv(self.rect.center())))
    }

    pub fn to_world(&self, p: Pos2) -> DVec2 {
        self.camera.to_world(dv(p), dv(self.rect.center()))
    }

    /// Draws the sculpt and collects the user's commands.
    // Long because: the frame's input in the order egui delivers it (zoom, hover, gestures, keys), then painting.
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        sculpt: &Sculpt,
        overlays: &ViewOverlays,
        commands: &mut Vec<Command>,
    ) {
        let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::click_and_drag());
        self.rect = response.rect;
        let data = sculpt.data();
        let key = (
            std::sync::Arc::as_ptr(sculpt.grammar()) as usize,
            sculpt.revision(),
        );
        if self.posed != Some(key) {
            // In place: the meshes' buffers are reused on every solver frame of a drag.
            pose_assembly_into(sculpt.grammar(), data, &mut self.cache, &mut self.meshes);
            self.posed = Some(key);
        }
        if self.fit_pending {
            self.fit(data, overlays);
            self.fit_pending = false;
        }
        let mid = dv(self.rect.center());
        let (modifiers, space, pointer, press_origin) = ui.input(|i| {
            (
                i.modifiers,
                i.key_down(Key::Space),
                i.pointer.hover_pos(),
                i.pointer.press_origin(),
            )
        });
        let pointer = pointer.filter(|p| self.rect.contains(*p));
        let keyboard_free = !ui.ctx().egui_wants_keyboard_input();
        if keyboard_free && ui.input(|i| i.key_pressed(Key::I)) {
            self.iso = !self.iso;
        }
        if self.iso {
            // A picture, not the floor plan: no gesture maps onto it, so none starts.
            if self.drag.take().is_some_and(|d| !matches!(d, Drag::Pan)) {
                commands.push(Command::Release);
            }
            (self.hovered, self.cut_target) = (None, None);
            super::iso::paint(ui, &painter, self.rect, sculpt, &mut self.iso_picture);
            return;
        }

        // Zoom toward the cursor: wheel, pinch or Ctrl + wheel.
        if let Some(p) = pointer {
            let (scroll, zoom) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
            let factor = zoom as f64 * (scroll as f64 * 0.0025).exp();
            if (factor - 1.0).abs() > 1e-6 {
                self.camera.zoom_at(factor, dv(p), mid);
            }
        }
        if keyboard_free && ui.input(|i| i.key_pressed(Key::F)) {
            self.fit(data, overlays);
        }

        let world = pointer.map(|p| self.camera.to_world(dv(p), mid));
        let tolerance = PICK_RADIUS / self.camera.scale;
        self.hovered = match sculpt.grabbed() {
            Some(g) => Some(g),
            None => world.and_then(|w| part_at(w, &self.meshes, data, tolerance)),
        };
        let cutting = modifiers.command || modifiers.ctrl;
        self.cut_target = if cutting && self.drag.is_none() {
            world.and_then(|w| sculpt.cut_target(w))
        } else {
            None
        };

        // Gestures.
        if response.drag_started() {
            let origin = press_origin.unwrap_or_else(|| pointer.unwrap_or(self.rect.center()));
            let w0 = self.camera.to_world(dv(origin), mid);
            let middle = response.drag_started_by(PointerButton::Middle);
            let secondary = response.drag_started_by(PointerButton::Secondary);
            let primary = response.drag_started_by(PointerButton::Primary);
            self.drag = if middle || (primary && space) {
                Some(Drag::Pan)
            } else if (primary || secondary) && !cutting {
                match part_at(w0, &self.meshes, data, tolerance) {
                    Some(part) => {
                        commands.push(Command::Grab { part, at: w0 });
                        if secondary || modifiers.shift {
                            let centre = sculpt.assembly().part_centroid(part);
                            let d = w0 - centre;
                            Some(Drag::Rotate {
                                centre,
                                start: d.y.atan2(d.x),
                            })
                        } else {
                            Some(Drag::Move { start: w0 })
                        }
                    }
                    // Dragging empty space pans too.
                    None if primary => Some(Drag::Pan),
                    None => None,
                }
            } else {
                None
            };
        }
        if let Some(drag) = self.drag {
            let still = ui.input(|i| i.pointer.any_down());
            match drag {
                Drag::Pan => self.camera.pan(DVec2::new(
                    response.drag_delta().x as f64,
                    response.drag_delta().y as f64,
                )),
                Drag::Move { start } => {
                    if let Some(p) = ui.input(|i| i.pointer.interact_pos()) {
                        // Near the canvas's edge the view follows the drag, so a part can be
                        // pulled past what the view shows (issue 48: at the default zoom the
                        // wall's end had no room to be pulled).
                        // Only once the pointer is held still there for a few frames: a drag
                        // that moves past the edge and is let go lands where it is let go.
                        let push = edge_push(self.rect, p);
                        let still = ui.input(|i| i.pointer.delta().length()) < 1.0;
                        self.edge_still = match (push != DVec2::ZERO, still) {
                            (true, true) => self.edge_still.saturating_add(1),
                            _ => 0,
                        };
                        if push != DVec2::ZERO {
                            if self.edge_still > EDGE_STILL_FRAMES {
                                self.camera.pan(-push);
                            }
                            ui.ctx().request_repaint();
                        }
                        let w = self.camera.to_world(dv(p), mid);
                        commands.push(Command::MoveGrab {
                            translation: w - start,
                            angle: 0.0,
                        });
                    }
                }
                Drag::Rotate { centre, start } => {
                    if let Some(p) = ui.input(|i| i.pointer.interact_pos()) {
                        let d = self.camera.to_world(dv(p), mid) - centre;
                        if d.length() > 1e-9 {
                            commands.push(Command::MoveGrab {
                                translation: DVec2::ZERO,
                                angle: d.y.atan2(d.x) - start,
                            });
                        }
                    }
                }
            }
            if response.drag_stopped() || !still {
                if !matches!(drag, Drag::Pan) {
                    commands.push(Command::Release);
                }
                self.drag = None;
                self.edge_still = 0;
            }
        }
        if response.clicked()
            && cutting
            && let Some(w) = world
        {
            commands.push(Command::Cut { point: w });
        }
        if keyboard_free
            && ui.input(|i| i.key_pressed(Key::P))
            && let Some(part) = self.hovered
            && let Some(at) = world
        {
            commands.push(Command::TogglePin { part, at });
        }

        self.paint(&painter, sculpt);
        super::overlay::paint(&painter, self.rect, &self.camera, sculpt, overlays);
        self.label_parts(ui, sculpt);
    }

    /// Fits the model into the view, below the strain legend while it is shown.
    fn fit(&mut self, data: &AssemblyData, overlays: &ViewOverlays) {
        let (min, max) = clay::bounds(&self.meshes, data);
        let size = DVec2::new(self.rect.width() as f64, self.rect.height() as f64);
        let [_, y, _, height] = clay::STRAIN_LEGEND;
        let margin = 24.0;
        // The legend's plate ends `y + height` points down; the margin then starts below it.
        let legend = if overlays.strain && !self.iso {
            (y + height) as f64
        } else {
            0.0
        };
        self.camera.fit_below(min, max, size, margin, legend);
    }

    fn paint(&self, painter: &egui::Painter, sculpt: &Sculpt) {
        let data = sculpt.data();
        let mid = dv(self.rect.center());
        let screen = |p: DVec2| pos(self.camera.to_screen(p, mid));
        painter.rect_filled(self.rect, 0.0, Color32::from_rgb(246, 243, 236));
        // One mesh for all fills: far cheaper for egui than a shape per proxy.
        let mut fills = egui::Mesh::default();
        for m in &self.meshes {
            append(&mut fills, m, screen, colour(m.fill));
        }
        painter.add(Shape::mesh(fills));
        // Outlines only where they are more than a smear (about 2 points per 10 cm).
        if self.camera.scale >= OUTLINE_MIN_SCALE {
            for m in &self.meshes {
                let stroke = Stroke::new(1.0, darker(colour(m.fill)));
                let pts: Vec<Pos2> = m.positions.iter().map(|&p| screen(world_of(p))).collect();
                for &[a, b] in &m.outline {
                    if let (Some(&pa), Some(&pb)) = (pts.get(a as usize), pts.get(b as usize))
                        && (self.rect.contains(pa) || self.rect.contains(pb))
                    {
                        painter.line_segment([pa, pb], stroke);
                    }
                }
            }
        }
        // A grammar without proxy geometry still shows its parts, as edges.
        if self.meshes.is_empty() {
            for p in 0..data.parts.len() {
                self.paint_part_edges(painter, data, p, Stroke::new(1.0, EDGES));
            }
        }
        for part in 0..data.parts.len() {
            if sculpt.is_pinned(part) {
                self.paint_part_edges(painter, data, part, Stroke::new(1.5, PINNED));
                for &v in &data.parts[part].vertices {
                    if let Some(&p) = data.positions.get(v) {
                        painter.rect_filled(
                            Rect::from_center_size(screen(p), Vec2::splat(6.0)),
                            0.0,
                            PINNED,
                        );
                    }
                }
            }
        }
        if let Some(part) = self.hovered {
            let instances = data.part_instances(part);
            for m in self
                .meshes
                .iter()
                .filter(|m| instances.contains(&m.instance))
            {
                let mut overlay = egui::Mesh::default();
                append(&mut overlay, m, screen, HOVER);
                painter.add(Shape::mesh(overlay));
            }
            let colour = if sculpt.grabbed() == Some(part) {
                GRABBED
            } else {
                Color32::from_rgb(200, 140, 0)
            };
            self.paint_part_edges(painter, data, part, Stroke::new(1.5, colour));
        }
        if let Some((centre, _)) = sculpt.grab_target() {
            painter.circle_stroke(screen(centre), 7.0, Stroke::new(2.0, GRABBED));
        }
        if let Some(dock) = self.cut_target
            && let Some(&c) = sculpt.dock_centres().get(dock)
        {
            painter.circle_stroke(screen(c), 9.0, Stroke::new(3.0, CUT));
            painter.circle_filled(screen(c), 3.0, CUT);
        }
    }

    fn paint_part_edges(
        &self,
        painter: &egui::Painter,
        data: &AssemblyData,
        part: usize,
        stroke: Stroke,
    ) {
        let mid = dv(self.rect.center());
        let Some(p) = data.parts.get(part) else {
            return;
        };
        for &[a, b] in &p.edges {
            let ends = [a, b].map(|k| {
                p.vertices
                    .get(k)
                    .and_then(|&v| data.positions.get(v))
                    .map(|&w| pos(self.camera.to_screen(w, mid)))
            });
            if let [Some(pa), Some(pb)] = ends {
                painter.line_segment([pa, pb], stroke);
            }
        }
    }

    /// Gives every part an accessible label (`part 3`) at its centre, so tests and screen
    /// readers can find it; hover-only, so it never takes the canvas's drags.
    fn label_parts(&self, ui: &mut egui::Ui, sculpt: &Sculpt) {
        const MOST: usize = 2000;
        let asm = sculpt.assembly();
        for part in 0..asm.data().parts.len().min(MOST) {
            let at = self.to_screen(asm.part_centroid(part));
            if !self.rect.contains(at) {
                continue;
            }
            let id = ui.scope_id().with(("part", part));
            let r = ui.interact(
                Rect::from_center_size(at, Vec2::splat(4.0)),
                id,
                Sense::hover(),
            );
            r.widget_info(|| {
                egui::WidgetInfo::labeled(egui::Role::GraphicsObject, true, format!("part {part}"))
            });
        }
    }
}

fn world_of([x, y]: [f32; 2]) -> DVec2 {
    DVec2::new(x as f64, y as f64)
}

fn colour(c: clay_dsl::compiled::Rgba) -> Color32 {
    let [r, g, b, a] = c.0;
    Color32::from_rgba_unmultiplied(r, g, b, a)
}

fn darker(c: Color32) -> Color32 {
    let f = |v: u8| (v as f32 * 0.55) as u8;
    Color32::from_rgba_premultiplied(f(c.r()), f(c.g()), f(c.b()), c.a())
}

/// Appends a posed mesh, in screen space and one colour, to an egui mesh.
fn append(mesh: &mut egui::Mesh, m: &WorldMesh, screen: impl Fn(DVec2) -> Pos2, fill: Color32) {
    let base = mesh.vertices.len() as u32;
    for &p in &m.positions {
        mesh.colored_vertex(screen(world_of(p)), fill);
    }
    let n = m.positions.len() as u32;
    for &[a, b, c] in &m.triangles {
        if a < n && b < n && c < n {
            mesh.add_triangle(base + a, base + b, base + c);
        }
    }
}

/// How far a drag at `p` pushes the view this frame (screen pixels, toward the edge it is
/// near): nothing inside the canvas away from its edges, growing to [`EDGE_SPEED`] at the edge
/// and beyond it.
fn edge_push(rect: egui::Rect, p: egui::Pos2) -> DVec2 {
    let axis = |x: f32, lo: f32, hi: f32| -> f64 {
        let zone = EDGE_ZONE.min((hi - lo) / 4.0);
        if x > hi - zone {
            EDGE_SPEED * f64::from(((x - (hi - zone)) / zone).min(1.0))
        } else if x < lo + zone {
            -EDGE_SPEED * f64::from(((lo + zone - x) / zone).min(1.0))
        } else {
            0.0
        }
    };
    DVec2::new(
        axis(p.x, rect.min.x, rect.max.x),
        axis(p.y, rect.min.y, rect.max.y),
    )
}
