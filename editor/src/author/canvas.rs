//! Authoring mode's canvas: draws the drawing, the grid (and its step), the cut points and the
//! design (regions filled in their piece's written colour, instance outlines, docking sites
//! coloured by site type), and turns clicks into [`AuthorCommand`]s: drawing strokes snapped to
//! the grid or to drawn points in the draw tool, placing cut points in the cut tool snapped to
//! a drawn vertex or to where an edge crosses a grid line (an indicator shows the snap while
//! hovering); it also picks sites (site tool) and lets the author drag the vertices of a posed
//! copy of a piece (a rest state in the making). A click that does nothing says why. The view
//! only fits the drawing on request, never after a stroke. It never changes the work itself.

use clay::{
    authoring::Computed, authoring::PieceDesign, authoring::Polyline, authoring::SiteName,
    nearest_on_segment,
};
use egui::{Align2, Color32, FontId, Key, PointerButton, Pos2, Rect, Sense, Shape, Stroke, Vec2};
use glam::DVec2;

use super::{AuthorCommand, Authoring, short};
use crate::camera::{Camera, dv, pos};

/// Pointer distance (screen points) within which a point or edge counts as under it.
const PICK_RADIUS: f64 = 10.0;
/// Grid lines closer than this on screen (points) are not drawn.
const GRID_MIN_SPACING: f64 = 8.0;
const BACKGROUND: Color32 = Color32::from_rgb(246, 243, 236);
const GRID: Color32 = Color32::from_rgb(226, 222, 212);
const STROKES: Color32 = Color32::from_rgb(60, 60, 70);
const PENDING: Color32 = Color32::from_rgb(30, 80, 220);
const CUT: Color32 = Color32::from_rgb(230, 40, 160);
const POSE: Color32 = Color32::from_rgb(0, 150, 110);
const LABELS: Color32 = Color32::from_rgb(50, 40, 30);

/// The colour a piece is drawn in: its fill as the grammar writes it (the SVG's fill, or the
/// editor's palette for pieces drawn without one), so "Try it" shows the same colours.
pub fn piece_colour(piece: &PieceDesign) -> Color32 {
    let [r, g, b] = piece.fill;
    Color32::from_rgb(r, g, b)
}

/// The colour a site type is drawn in: the renderer's, so a site type has one colour in the
/// author canvas, the sculpt overlays and `clayc render --overlay sites`.
pub fn site_colour(site_type: usize) -> Color32 {
    let [r, g, b, a] = clay::site_type_colour(site_type).0;
    Color32::from_rgba_unmultiplied(r, g, b, a)
}

/// What a click on the canvas does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tool {
    /// Click to add points (snapped), click the first point to close, double-click or Enter
    /// to finish an open stroke, Esc to drop it.
    Draw,
    /// Click on the drawing to cut it there; right-click a cut to remove it.
    Cut,
    /// Click a docking site to pick it (the panel then sets its type).
    Site,
}

/// What a click's point snapped to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SnapKind {
    /// A vertex of the drawing (or of the stroke being drawn).
    Vertex,
    /// A grid point (draw tool), or where the edge crosses a grid line (cut tool).
    Grid,
    /// The nearest point of an edge that crosses no grid line (cut tool).
    Edge,
}

impl SnapKind {
    fn label(self) -> &'static str {
        match self {
            SnapKind::Vertex => "vertex",
            SnapKind::Grid => "grid",
            SnapKind::Edge => "edge",
        }
    }
}

/// A posed copy of a piece: a new rest state in the making. Shown over one instance of the
/// piece; its vertices are dragged (snapped to the grid in the piece's coordinates).
#[derive(Clone, Debug, PartialEq)]
pub struct Pose {
    pub piece: String,
    /// The instance the copy is shown over.
    pub instance: usize,
    /// One position per piece vertex, in the piece's coordinates.
    pub positions: Vec<DVec2>,
    /// The vertex being dragged.
    pub dragging: Option<usize>,
}

/// View state of the authoring canvas, kept between frames.
pub struct AuthorCanvas {
    pub camera: Camera,
    pub tool: Tool,
    /// Grid spacing (metres) that drawn points snap to.
    pub grid: f64,
    /// The stroke being drawn (not yet part of the work).
    pub pending: Vec<DVec2>,
    /// Where a click would put a point or a cut, in the last frame.
    pub target: Option<DVec2>,
    /// What `target` snapped to.
    pub snap: Option<SnapKind>,
    /// The site picked with the site tool.
    pub selected_site: Option<SiteName>,
    /// The rest state being posed, if any.
    pub pose: Option<Pose>,
    panning: bool,
    /// Fit the view to the drawing at the next frame: only on request (Fit, F, an import,
    /// entering the mode), never after a stroke or cut.
    fit_pending: bool,
    pub rect: Rect,
}

impl Default for AuthorCanvas {
    fn default() -> Self {
        Self {
            camera: Camera {
                centre: DVec2::new(2.0, 1.0),
                scale: 100.0,
            },
            tool: Tool::Draw,
            grid: 0.1,
            pending: Vec::new(),
            target: None,
            snap: None,
            selected_site: None,
            pose: None,
            panning: false,
            fit_pending: true,
            rect: Rect::from_min_size(Pos2::ZERO, Vec2::splat(1.0)),
        }
    }
}

/// The segments of a stroke, closing segment included.
fn segments(p: &Polyline) -> impl Iterator<Item = (DVec2, DVec2)> + '_ {
    let n = p.points.len();
    let count = if p.closed && n > 2 {
        n
    } else {
        n.saturating_sub(1)
    };
    (0..count).map(move |i| (p.points[i], p.points[(i + 1) % n]))
}

/// Where segment `a`-`b` crosses a grid line (`x = k step` or `y = k step`) nearest its
/// point `p`, if it crosses one; the crossing's grid coordinate is exact.
fn grid_crossing(a: DVec2, b: DVec2, p: DVec2, step: f64) -> Option<DVec2> {
    if !(step.is_finite() && step > 0.0) {
        return None;
    }
    let mut best: Option<DVec2> = None;
    for axis in 0..2 {
        let (from, to) = (a[axis], b[axis]);
        if (to - from).abs() < 1e-12 {
            // Along a grid line or parallel to one: no crossing on this axis.
            continue;
        }
        for k in [(p[axis] / step).floor(), (p[axis] / step).ceil()] {
            let t = (k * step - from) / (to - from);
            if !(0.0..=1.0).contains(&t) {
                continue;
            }
            let mut q = a + (b - a) * t;
            q[axis] = k * step;
            if best.is_none_or(|c| q.distance(p) < c.distance(p)) {
                best = Some(q);
            }
        }
    }
    best
}

impl AuthorCanvas {
    /// Fit the view to the drawing at the next frame.
    pub fn request_fit(&mut self) {
        self.fit_pending = true;
    }

    pub fn to_screen(&self, p: DVec2) -> Pos2 {
        pos(self.camera.to_screen(p, dv(self.rect.center())))
    }

    pub fn to_world(&self, p: Pos2) -> DVec2 {
        self.camera.to_world(dv(p), dv(self.rect.center()))
    }

    fn fit(&mut self, author: &Authoring) {
        let pts = author
            .work()
            .drawing
            .polylines
            .iter()
            .flat_map(|p| p.points.iter().copied());
        let (mut min, mut max) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for p in pts {
            min = min.min(p);
            max = max.max(p);
        }
        let size = DVec2::new(self.rect.width() as f64, self.rect.height() as f64);
        self.camera.fit(min, max, size, 40.0);
    }

    /// Where a click in the draw tool puts a point: a drawn or pending point under the
    /// pointer, else the nearest grid point.
    fn draw_target(&self, author: &Authoring, w: DVec2) -> (DVec2, SnapKind) {
        let radius = PICK_RADIUS / self.camera.scale;
        let near = author
            .work()
            .drawing
            .polylines
            .iter()
            .flat_map(|p| p.points.iter().copied())
            .chain(self.pending.iter().copied())
            .filter(|p| p.distance(w) <= radius)
            .min_by(|a, b| a.distance(w).total_cmp(&b.distance(w)));
        match near {
            Some(p) => (p, SnapKind::Vertex),
            None if self.grid.is_finite() && self.grid > 0.0 => {
                ((w / self.grid).round() * self.grid, SnapKind::Grid)
            }
            None => (w, SnapKind::Edge),
        }
    }

    /// Where a click in the cut tool cuts: a vertex of the drawing under the pointer, else
    /// where the nearest edge in reach crosses the grid line nearest the pointer, else the
    /// nearest point of that edge. So two clicks a few millimetres apart cut at one place.
    /// `Err` says why there is no cut: the distance (screen points) to the nearest edge.
    fn cut_target(&self, author: &Authoring, w: DVec2) -> Result<(DVec2, SnapKind), f64> {
        let radius = PICK_RADIUS / self.camera.scale;
        let polylines = &author.work().drawing.polylines;
        let vertex = polylines
            .iter()
            .flat_map(|p| p.points.iter().copied())
            .filter(|p| p.distance(w) <= radius)
            .min_by(|a, b| a.distance(w).total_cmp(&b.distance(w)));
        if let Some(v) = vertex {
            return Ok((v, SnapKind::Vertex));
        }
        let (a, b, p) = polylines
            .iter()
            .flat_map(segments)
            .map(|(a, b)| (a, b, nearest_on_segment(w, a, b).0))
            .min_by(|x, y| x.2.distance(w).total_cmp(&y.2.distance(w)))
            .ok_or(f64::INFINITY)?;
        let d = p.distance(w);
        if d > radius {
            return Err(d * self.camera.scale);
        }
        Ok(match grid_crossing(a, b, p, self.grid) {
            Some(q) => (q, SnapKind::Grid),
            None => (p, SnapKind::Edge),
        })
    }

    /// Starts posing a copy of piece `piece` over its first instance.
    pub fn start_pose(&mut self, author: &Authoring, piece: usize) {
        let Some(design) = author.design() else {
            return;
        };
        let (Some(p), Some(instance)) = (
            design.pieces.get(piece),
            design.instances.iter().position(|i| i.piece == piece),
        ) else {
            return;
        };
        self.pose = Some(Pose {
            piece: p.name.clone(),
            instance,
            positions: p.positions.clone(),
            dragging: None,
        });
    }

    /// Where vertex `k` of the posed copy is drawn (metres, y up).
    pub fn pose_world(&self, author: &Authoring, k: usize) -> Option<DVec2> {
        let pose = self.pose.as_ref()?;
        let inst = author.design()?.instances.get(pose.instance)?;
        let p = *pose.positions.get(k)?;
        Some(DVec2::from_angle(inst.angle).rotate(p) + inst.at)
    }

    /// Moves vertex `k` of the posed copy under the world point `w`, snapped to the grid in
    /// the piece's coordinates (so the written state has round numbers).
    pub fn move_pose_vertex(&mut self, author: &Authoring, k: usize, w: DVec2) {
        let Some(inst) = self
            .pose
            .as_ref()
            .and_then(|p| author.design()?.instances.get(p.instance))
        else {
            return;
        };
        let local = DVec2::from_angle(-inst.angle).rotate(w - inst.at);
        let snapped = if self.grid.is_finite() && self.grid > 0.0 {
            (local / self.grid).round() * self.grid
        } else {
            local
        };
        if let Some(p) = self.pose.as_mut().and_then(|p| p.positions.get_mut(k))
            && snapped.is_finite()
        {
            *p = snapped;
        }
    }

    /// The site of an instance under the world point `w`: the nearest site centre in reach.
    fn site_at(&self, author: &Authoring, w: DVec2) -> Option<SiteName> {
        let c = author.result.as_ref().ok()?;
        let radius = PICK_RADIUS / self.camera.scale;
        let mut best: Option<(f64, SiteName)> = None;
        for inst in &c.design.instances {
            let Some(piece) = c.design.pieces.get(inst.piece) else {
                continue;
            };
            for site in &piece.sites {
                let pts: Vec<DVec2> = site
                    .vertices
                    .iter()
                    .filter_map(|&k| inst.vertices.get(k).and_then(|&v| c.graph.positions.get(v)))
                    .copied()
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                // Docked sites share their vertices: a point just inside tells them apart.
                let out = DVec2::from_angle(inst.angle).rotate(site.out);
                let centre = pts.iter().sum::<DVec2>() / pts.len() as f64 - out * radius * 0.5;
                let d = centre.distance(w);
                if d <= radius && best.as_ref().is_none_or(|(b, _)| d < *b) {
                    best = Some((
                        d,
                        SiteName {
                            piece: piece.name.clone(),
                            site: site.name.clone(),
                        },
                    ));
                }
            }
        }
        best.map(|(_, s)| s)
    }

    /// Ends the pending stroke; too few points are dropped with a message saying so.
    fn finish(&mut self, closed: bool, commands: &mut Vec<AuthorCommand>) {
        let points = std::mem::take(&mut self.pending);
        let needed = if closed { 3 } else { 2 };
        if points.len() >= needed {
            commands.push(AuthorCommand::AddPolyline(Polyline {
                points,
                closed,
                fill: None,
                name: None,
            }));
        } else if !points.is_empty() {
            commands.push(AuthorCommand::Report(format!(
                "a stroke needs at least {needed} points, this one has {}: it was dropped",
                points.len()
            )));
        }
    }

    /// Draws the authoring state and collects the user's commands.
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        author: &Authoring,
        commands: &mut Vec<AuthorCommand>,
    ) {
        let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::click_and_drag());
        self.rect = response.rect;
        if self.fit_pending {
            if !author.work().drawing.polylines.is_empty() {
                self.fit(author);
                ui.ctx().request_repaint();
            }
            self.fit_pending = false;
        }
        let pointer = ui
            .input(|i| i.pointer.hover_pos())
            .filter(|p| self.rect.contains(*p));
        self.view_input(ui, &response, author, pointer);
        let world = pointer.map(|p| self.to_world(p));
        let (target, snap) = match (world, self.tool) {
            (Some(w), Tool::Draw) => {
                let (t, k) = self.draw_target(author, w);
                (Some(t), Some(k))
            }
            (Some(w), Tool::Cut) => match self.cut_target(author, w) {
                Ok((t, k)) => (Some(t), Some(k)),
                Err(_) => (None, None),
            },
            _ => (None, None),
        };
        (self.target, self.snap) = (target, snap);
        match self.tool {
            Tool::Draw => self.draw_input(ui, &response, commands),
            Tool::Cut => self.cut_input(&response, author, world, commands),
            Tool::Site => {
                if response.clicked_by(PointerButton::Primary)
                    && let Some(w) = world
                {
                    self.selected_site = self.site_at(author, w);
                    if self.selected_site.is_none() {
                        commands.push(AuthorCommand::Report(match author.design() {
                            Some(_) => format!(
                                "no docking site within {PICK_RADIUS} px of the click: click \
                                 just inside an instance, next to a site's coloured line"
                            ),
                            None => "no sites yet: the drawing has no design".into(),
                        }));
                    }
                }
                if response.clicked_by(PointerButton::Secondary) {
                    commands.push(AuthorCommand::Report(
                        "right-click does nothing in the Pick site tool (in the Cut tool it \
                         removes a cut)"
                            .into(),
                    ));
                }
            }
        }
        self.paint(&painter, author);
    }

    /// Zoom (wheel, pinch), fit (F), dragging a posed vertex, and panning (any other drag).
    fn view_input(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        author: &Authoring,
        pointer: Option<Pos2>,
    ) {
        let mid = dv(self.rect.center());
        if let Some(p) = pointer {
            let (scroll, zoom) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
            let factor = zoom as f64 * (scroll as f64 * 0.0025).exp();
            if (factor - 1.0).abs() > 1e-6 {
                self.camera.zoom_at(factor, dv(p), mid);
            }
        }
        let keyboard_free = !ui.ctx().egui_wants_keyboard_input();
        if keyboard_free && ui.input(|i| i.key_pressed(Key::F)) {
            self.fit(author);
        }
        // A drag on a posed vertex moves it; every other drag pans: clicks, not drags, edit
        // the drawing.
        if response.drag_started() {
            let press = ui.input(|i| i.pointer.press_origin()).or(pointer);
            let grabbed = press.and_then(|p| {
                let n = self.pose.as_ref()?.positions.len();
                (0..n)
                    .filter_map(|k| {
                        Some((k, self.to_screen(self.pose_world(author, k)?).distance(p)))
                    })
                    .filter(|(_, d)| *d as f64 <= PICK_RADIUS)
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .map(|(k, _)| k)
            });
            match (grabbed, self.pose.as_mut()) {
                (Some(k), Some(pose)) => pose.dragging = Some(k),
                _ => self.panning = true,
            }
        }
        if let Some(k) = self.pose.as_ref().and_then(|p| p.dragging) {
            if let Some(p) = pointer {
                let w = self.to_world(p);
                self.move_pose_vertex(author, k, w);
            }
            if (response.drag_stopped() || !ui.input(|i| i.pointer.any_down()))
                && let Some(pose) = self.pose.as_mut()
            {
                pose.dragging = None;
            }
        }
        if self.panning {
            let d = response.drag_delta();
            self.camera.pan(DVec2::new(d.x as f64, d.y as f64));
            if response.drag_stopped() || !ui.input(|i| i.pointer.any_down()) {
                self.panning = false;
            }
        }
    }

    /// The draw tool: clicks add snapped points, the first point closes, double-click or
    /// Enter ends an open stroke, Backspace drops a point, Esc the stroke.
    fn draw_input(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        commands: &mut Vec<AuthorCommand>,
    ) {
        let radius = PICK_RADIUS / self.camera.scale;
        let keyboard_free = !ui.ctx().egui_wants_keyboard_input();
        let finishing =
            response.double_clicked() || (keyboard_free && ui.input(|i| i.key_pressed(Key::Enter)));
        if response.clicked_by(PointerButton::Primary)
            && let Some(t) = self.target
        {
            let closes = self.pending.len() >= 3 && self.pending[0].distance(t) <= radius;
            if closes {
                self.finish(true, commands);
                return;
            } else if self.pending.last() != Some(&t) {
                self.pending.push(t);
            } else if !finishing {
                commands.push(AuthorCommand::Report(
                    "that point is already the stroke's last one: click elsewhere, or \
                     double-click or press Enter to end the stroke"
                        .into(),
                ));
            }
        }
        if response.clicked_by(PointerButton::Secondary) {
            commands.push(AuthorCommand::Report(
                "right-click does nothing in the Draw tool (Backspace drops the last point, \
                 Esc the stroke)"
                    .into(),
            ));
        }
        if finishing {
            self.finish(false, commands);
        }
        if keyboard_free && ui.input(|i| i.key_pressed(Key::Escape)) {
            self.pending.clear();
        }
        if keyboard_free && ui.input(|i| i.key_pressed(Key::Backspace)) {
            self.pending.pop();
        }
    }

    /// The cut tool: a click cuts at the snapped point, a right-click removes the cut under it;
    /// a click that does neither says why.
    fn cut_input(
        &self,
        response: &egui::Response,
        author: &Authoring,
        world: Option<DVec2>,
        commands: &mut Vec<AuthorCommand>,
    ) {
        let Some(w) = world else {
            return;
        };
        if response.clicked_by(PointerButton::Primary) {
            commands.push(match self.cut_target(author, w) {
                Ok((t, _)) => AuthorCommand::Cut { point: t },
                Err(d) if d.is_finite() => AuthorCommand::Report(format!(
                    "no edge within {PICK_RADIUS} px of the click (the nearest is {d:.0} px \
                     away); cuts go across an edge: click on or next to one"
                )),
                Err(_) => {
                    AuthorCommand::Report("nothing to cut yet: import an SVG or draw first".into())
                }
            });
        }
        if response.clicked_by(PointerButton::Secondary) {
            let radius = PICK_RADIUS / self.camera.scale;
            let near = author
                .work()
                .cuts
                .iter()
                .enumerate()
                .map(|(i, c)| (i, c.distance(w)))
                .filter(|(_, d)| *d <= radius)
                .min_by(|a, b| a.1.total_cmp(&b.1));
            commands.push(match near {
                Some((index, _)) => AuthorCommand::RemoveCut { index },
                None => AuthorCommand::Report(format!(
                    "no cut within {PICK_RADIUS} px of the right-click: right-click a \
                     magenta X to remove that cut"
                )),
            });
        }
    }

    fn paint(&self, painter: &egui::Painter, author: &Authoring) {
        let screen = |p: DVec2| self.to_screen(p);
        painter.rect_filled(self.rect, 0.0, BACKGROUND);
        self.paint_grid(painter);
        if let Ok(c) = &author.result {
            self.paint_design(painter, c);
        }
        for p in &author.work().drawing.polylines {
            for (a, b) in segments(p) {
                painter.line_segment([screen(a), screen(b)], Stroke::new(1.0, STROKES));
            }
        }
        for &c in &author.work().cuts {
            let s = screen(c);
            painter.circle_stroke(s, 7.0, Stroke::new(2.0, CUT));
            let d = Vec2::splat(4.0);
            painter.line_segment([s - d, s + d], Stroke::new(2.0, CUT));
            painter.line_segment(
                [s + Vec2::new(-4.0, 4.0), s + Vec2::new(4.0, -4.0)],
                Stroke::new(2.0, CUT),
            );
        }
        let stroke = Stroke::new(2.0, PENDING);
        for w in self.pending.windows(2) {
            painter.line_segment([screen(w[0]), screen(w[1])], stroke);
        }
        for &p in &self.pending {
            painter.circle_filled(screen(p), 3.0, PENDING);
        }
        if let Some(t) = self.target {
            if let (Tool::Draw, Some(&last)) = (self.tool, self.pending.last()) {
                painter.line_segment(
                    [screen(last), screen(t)],
                    Stroke::new(1.0, PENDING.gamma_multiply(0.6)),
                );
            }
            self.paint_snap(painter, t);
        }
        self.paint_grid_step(painter);
        self.paint_pose(painter, author);
    }

    /// The snap indicator under the pointer: a square on a vertex, a ring with a cross on the
    /// grid, a plain ring on an edge off the grid, with what it snapped to and where.
    fn paint_snap(&self, painter: &egui::Painter, t: DVec2) {
        let colour = if self.tool == Tool::Cut { CUT } else { PENDING };
        let s = self.to_screen(t);
        let stroke = Stroke::new(2.0, colour);
        match self.snap {
            Some(SnapKind::Vertex) => {
                let r = Rect::from_center_size(s, Vec2::splat(12.0));
                painter.rect_stroke(r, 0.0, stroke, egui::StrokeKind::Middle);
            }
            Some(SnapKind::Grid) => {
                painter.circle_stroke(s, 6.0, stroke);
                let d = 9.0;
                let thin = Stroke::new(1.0, colour);
                painter.line_segment([s - Vec2::new(d, 0.0), s + Vec2::new(d, 0.0)], thin);
                painter.line_segment([s - Vec2::new(0.0, d), s + Vec2::new(0.0, d)], thin);
            }
            _ => {
                painter.circle_stroke(s, 6.0, stroke);
            }
        }
        if let Some(k) = self.snap {
            painter.text(
                s + Vec2::new(10.0, -10.0),
                Align2::LEFT_BOTTOM,
                format!("{} {}", k.label(), super::coords(t)),
                FontId::proportional(11.0),
                colour,
            );
        }
    }

    /// The snap grid's step, in the canvas's lower-left corner (the lines are not drawn when
    /// they would be too dense, but points still snap to it).
    fn paint_grid_step(&self, painter: &egui::Painter) {
        painter.text(
            self.rect.left_bottom() + Vec2::new(8.0, -6.0),
            Align2::LEFT_BOTTOM,
            format!("grid {} m", short(self.grid)),
            FontId::proportional(11.0),
            LABELS,
        );
    }

    /// The posed copy: its edges and its vertices as handles.
    fn paint_pose(&self, painter: &egui::Painter, author: &Authoring) {
        let (Some(pose), Some(design)) = (&self.pose, author.design()) else {
            return;
        };
        let Some(piece) = design.pieces.iter().find(|p| p.name == pose.piece) else {
            return;
        };
        let at = |k: usize| self.pose_world(author, k).map(|p| self.to_screen(p));
        for &[a, b] in &piece.edges {
            if let (Some(pa), Some(pb)) = (at(a), at(b)) {
                painter.line_segment([pa, pb], Stroke::new(2.0, POSE));
            }
        }
        if let Some(o) = &piece.outline {
            for k in 0..o.len() {
                if let (Some(pa), Some(pb)) = (at(o[k]), at(o[(k + 1) % o.len()])) {
                    painter.line_segment([pa, pb], Stroke::new(2.0, POSE));
                }
            }
        }
        for k in 0..pose.positions.len() {
            if let Some(p) = at(k) {
                let r = if pose.dragging == Some(k) { 7.0 } else { 5.0 };
                painter.circle_filled(p, r, POSE);
            }
        }
    }

    fn paint_grid(&self, painter: &egui::Painter) {
        let step = self.grid * self.camera.scale;
        if !(step.is_finite() && step >= GRID_MIN_SPACING) {
            return;
        }
        let lo = self.to_world(self.rect.left_bottom());
        let hi = self.to_world(self.rect.right_top());
        let stroke = Stroke::new(1.0, GRID);
        let mut x = (lo.x / self.grid).floor() * self.grid;
        while x <= hi.x {
            let sx = self.to_screen(DVec2::new(x, 0.0)).x;
            painter.vline(sx, self.rect.y_range(), stroke);
            x += self.grid;
        }
        let mut y = (lo.y / self.grid).floor() * self.grid;
        while y <= hi.y {
            let sy = self.to_screen(DVec2::new(0.0, y)).y;
            painter.hline(self.rect.x_range(), sy, stroke);
            y += self.grid;
        }
    }

    /// Regions filled by piece, instance outlines, sites in their type's colour (drawn just
    /// inside their instance so that two docked sites both show), instance names.
    fn paint_design(&self, painter: &egui::Painter, c: &Computed) {
        let screen = |p: DVec2| self.to_screen(p);
        let design = &c.design;
        let at = |v: usize| c.graph.positions.get(v).copied();
        for inst in &design.instances {
            let Some(piece) = design.pieces.get(inst.piece) else {
                continue;
            };
            let fill = piece_colour(piece);
            let edge = Stroke::new(1.5, fill.gamma_multiply(0.5).to_opaque());
            let world_of = |k: usize| inst.vertices.get(k).and_then(|&v| at(v));
            match &piece.outline {
                Some(outline) => {
                    let ring: Vec<DVec2> = outline.iter().filter_map(|&k| world_of(k)).collect();
                    if let Some((vs, tris)) = clay::tessellate_polygon(&ring, &[]) {
                        let mut mesh = egui::Mesh::default();
                        for &v in &vs {
                            mesh.colored_vertex(screen(v), fill);
                        }
                        for t in tris {
                            mesh.add_triangle(t[0], t[1], t[2]);
                        }
                        painter.add(Shape::mesh(mesh));
                    }
                    let pts: Vec<Pos2> = ring.iter().map(|&p| screen(p)).collect();
                    painter.add(Shape::closed_line(pts, edge));
                }
                None => {
                    for &[a, b] in &piece.edges {
                        if let (Some(pa), Some(pb)) = (world_of(a), world_of(b)) {
                            painter.line_segment([screen(pa), screen(pb)], Stroke::new(4.0, fill));
                        }
                    }
                }
            }
            let rot = DVec2::from_angle(inst.angle);
            for site in &piece.sites {
                let out = rot.rotate(site.out);
                // Screen y points down.
                let inward = -Vec2::new(out.x as f32, -out.y as f32) * 3.0;
                let pts: Vec<Pos2> = site
                    .vertices
                    .iter()
                    .filter_map(|&k| world_of(k))
                    .map(|p| screen(p) + inward)
                    .collect();
                let colour = site_colour(site.site_type);
                let picked = self
                    .selected_site
                    .as_ref()
                    .is_some_and(|s| s.piece == piece.name && s.site == site.name);
                if picked && pts.len() >= 2 {
                    painter.add(Shape::line(pts.clone(), Stroke::new(7.0, LABELS)));
                }
                if pts.len() >= 2 {
                    painter.add(Shape::line(pts, Stroke::new(3.0, colour)));
                } else if let Some(&p) = pts.first() {
                    painter.circle_filled(p, 3.5, colour);
                }
            }
            let centre = inst.vertices.iter().filter_map(|&v| at(v)).sum::<DVec2>()
                / inst.vertices.len().max(1) as f64;
            if self.camera.scale > 30.0 {
                painter.text(
                    screen(centre),
                    Align2::CENTER_CENTER,
                    &inst.name,
                    FontId::proportional(11.0),
                    LABELS,
                );
            }
        }
    }
}
