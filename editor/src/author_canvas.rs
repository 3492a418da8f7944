//! Authoring mode's canvas: draws the drawing, the grid, the cut points and the design (regions
//! filled by piece, instance outlines, docking sites coloured by site type), and turns clicks
//! into [`AuthorCommand`]s: drawing strokes snapped to the grid or to drawn points in the draw
//! tool, placing cut points on the drawing in the cut tool; it also picks sites (site tool)
//! and lets the author drag the vertices of a posed copy of a piece (a rest state in the
//! making). It never changes the work itself.

use clay::authoring::Polyline;
use clay::segment::nearest_on_segment;
use egui::{Align2, Color32, FontId, Key, PointerButton, Pos2, Rect, Sense, Shape, Stroke, Vec2};
use glam::DVec2;

use crate::author::{AuthorCommand, Authoring, Computed, SiteName};
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

/// Piece fills, by piece index.
const PIECE_COLOURS: [Color32; 8] = [
    Color32::from_rgb(232, 176, 120),
    Color32::from_rgb(150, 196, 230),
    Color32::from_rgb(170, 214, 150),
    Color32::from_rgb(226, 160, 200),
    Color32::from_rgb(236, 214, 120),
    Color32::from_rgb(180, 170, 230),
    Color32::from_rgb(140, 210, 200),
    Color32::from_rgb(220, 150, 140),
];

/// Site type colours, by site type index.
const SITE_COLOURS: [Color32; 6] = [
    Color32::from_rgb(200, 30, 30),
    Color32::from_rgb(20, 120, 40),
    Color32::from_rgb(30, 60, 200),
    Color32::from_rgb(190, 110, 0),
    Color32::from_rgb(130, 30, 160),
    Color32::from_rgb(0, 130, 140),
];

/// The colour a piece is drawn in.
pub fn piece_colour(piece: usize) -> Color32 {
    PIECE_COLOURS[piece % PIECE_COLOURS.len()]
}

/// The colour a site type is drawn in.
pub fn site_colour(site_type: usize) -> Color32 {
    SITE_COLOURS[site_type % SITE_COLOURS.len()]
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
    /// The site picked with the site tool.
    pub selected_site: Option<SiteName>,
    /// The rest state being posed, if any.
    pub pose: Option<Pose>,
    panning: bool,
    fit_pending: bool,
    /// The canvas rectangle of the last fit, while the user has not moved the view since:
    /// panels settle their width a frame after a change, so the fit follows the canvas.
    fitted: Option<Rect>,
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
            selected_site: None,
            pose: None,
            panning: false,
            fit_pending: true,
            fitted: None,
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
    fn draw_target(&self, author: &Authoring, w: DVec2) -> DVec2 {
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
        near.unwrap_or_else(|| {
            if self.grid.is_finite() && self.grid > 0.0 {
                (w / self.grid).round() * self.grid
            } else {
                w
            }
        })
    }

    /// Where a click in the cut tool cuts: the nearest point on the drawing within reach.
    fn cut_target(&self, author: &Authoring, w: DVec2) -> Option<DVec2> {
        let radius = PICK_RADIUS / self.camera.scale;
        author
            .work()
            .drawing
            .polylines
            .iter()
            .flat_map(segments)
            .map(|(a, b)| nearest_on_segment(w, a, b).0)
            .filter(|p| p.distance(w) <= radius)
            .min_by(|a, b| a.distance(w).total_cmp(&b.distance(w)))
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
        if self.fitted.is_some_and(|r| r != self.rect) {
            self.fit_pending = true;
        }
        if self.fit_pending {
            if !author.work().drawing.polylines.is_empty() {
                self.fit(author);
                self.fitted = Some(self.rect);
                ui.ctx().request_repaint();
            }
            self.fit_pending = false;
        }
        let mid = dv(self.rect.center());
        let pointer = ui
            .input(|i| i.pointer.hover_pos())
            .filter(|p| self.rect.contains(*p));
        let keyboard_free = !ui.ctx().egui_wants_keyboard_input();
        if let Some(p) = pointer {
            let (scroll, zoom) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
            let factor = zoom as f64 * (scroll as f64 * 0.0025).exp();
            if (factor - 1.0).abs() > 1e-6 {
                self.camera.zoom_at(factor, dv(p), mid);
                self.fitted = None;
            }
        }
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
                _ => {
                    self.panning = true;
                    self.fitted = None;
                }
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

        let world = pointer.map(|p| self.camera.to_world(dv(p), mid));
        self.target = world.and_then(|w| match self.tool {
            Tool::Draw => Some(self.draw_target(author, w)),
            Tool::Cut => self.cut_target(author, w),
            Tool::Site => None,
        });
        let radius = PICK_RADIUS / self.camera.scale;
        match self.tool {
            Tool::Draw => {
                if response.clicked_by(PointerButton::Primary)
                    && let Some(t) = self.target
                {
                    let closes = self.pending.len() >= 3 && self.pending[0].distance(t) <= radius;
                    if closes {
                        self.finish(true, commands);
                    } else if self.pending.last() != Some(&t) {
                        self.pending.push(t);
                    }
                }
                let enter = keyboard_free && ui.input(|i| i.key_pressed(Key::Enter));
                if response.double_clicked() || enter {
                    self.finish(false, commands);
                }
                if keyboard_free && ui.input(|i| i.key_pressed(Key::Escape)) {
                    self.pending.clear();
                }
                if keyboard_free && ui.input(|i| i.key_pressed(Key::Backspace)) {
                    self.pending.pop();
                }
            }
            Tool::Cut => {
                if response.clicked_by(PointerButton::Primary)
                    && let Some(t) = self.target
                {
                    commands.push(AuthorCommand::Cut { point: t });
                }
                if response.clicked_by(PointerButton::Secondary)
                    && let Some(w) = world
                    && let Some((index, _)) = author
                        .work()
                        .cuts
                        .iter()
                        .enumerate()
                        .map(|(i, c)| (i, c.distance(w)))
                        .filter(|(_, d)| *d <= radius)
                        .min_by(|a, b| a.1.total_cmp(&b.1))
                {
                    commands.push(AuthorCommand::RemoveCut { index });
                }
            }
            Tool::Site => {
                if response.clicked_by(PointerButton::Primary)
                    && let Some(w) = world
                {
                    self.selected_site = self.site_at(author, w);
                }
            }
        }
        self.paint(&painter, author);
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
            match self.tool {
                Tool::Draw => {
                    if let Some(&last) = self.pending.last() {
                        painter.line_segment(
                            [screen(last), screen(t)],
                            Stroke::new(1.0, PENDING.gamma_multiply(0.6)),
                        );
                    }
                    painter.circle_stroke(screen(t), 5.0, Stroke::new(1.5, PENDING));
                }
                Tool::Cut => {
                    painter.circle_stroke(screen(t), 6.0, Stroke::new(2.0, CUT));
                }
                Tool::Site => {}
            }
        }
        self.paint_pose(painter, author);
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
            let fill = piece_colour(inst.piece);
            let edge = Stroke::new(1.5, fill.gamma_multiply(0.5).to_opaque());
            let world_of = |k: usize| inst.vertices.get(k).and_then(|&v| at(v));
            match &piece.outline {
                Some(outline) => {
                    let ring: Vec<DVec2> = outline.iter().filter_map(|&k| world_of(k)).collect();
                    if let Some((vs, tris)) = clay::render::tessellate_polygon(&ring, &[]) {
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
