//! The canvas camera: world metres (y north) to screen points (y down), with pan, zoom about a
//! fixed screen point and fit-to-bounds.

use egui::Pos2;
use glam::DVec2;

/// Nearest and furthest zoom, in screen points per metre.
const SCALE_RANGE: (f64, f64) = (1e-3, 1e5);

/// World point `centre` is drawn at the middle of the canvas, `scale` points per metre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub centre: DVec2,
    pub scale: f64,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            centre: DVec2::ZERO,
            scale: 40.0,
        }
    }
}

impl Camera {
    /// Screen position of a world point, for a canvas whose middle is `mid`.
    pub fn to_screen(&self, p: DVec2, mid: DVec2) -> DVec2 {
        let d = (p - self.centre) * self.scale;
        DVec2::new(mid.x + d.x, mid.y - d.y)
    }

    /// World position of a screen point.
    pub fn to_world(&self, s: DVec2, mid: DVec2) -> DVec2 {
        let d = s - mid;
        self.centre + DVec2::new(d.x, -d.y) / self.scale
    }

    /// Moves the view by a screen-space drag.
    pub fn pan(&mut self, screen_delta: DVec2) {
        let moved = self.centre - DVec2::new(screen_delta.x, -screen_delta.y) / self.scale;
        if moved.is_finite() {
            self.centre = moved;
        }
    }

    /// Zooms by `factor` keeping the world point under screen point `at` where it is.
    pub fn zoom_at(&mut self, factor: f64, at: DVec2, mid: DVec2) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let anchor = self.to_world(at, mid);
        self.scale = (self.scale * factor).clamp(SCALE_RANGE.0, SCALE_RANGE.1);
        // Put `anchor` back under `at`.
        let d = at - mid;
        self.centre = anchor - DVec2::new(d.x, -d.y) / self.scale;
    }

    /// The camera showing the world box `[min, max]` in a canvas of `size` points with `margin`
    /// points free on every side. An empty or broken box keeps the camera as it is.
    pub fn fit(&mut self, min: DVec2, max: DVec2, size: DVec2, margin: f64) {
        self.fit_below(min, max, size, margin, 0.0);
    }

    /// As [`Camera::fit`], with the top `reserved` points of the canvas kept free as well (a
    /// legend drawn there): the box is fitted into the canvas below them.
    pub fn fit_below(&mut self, min: DVec2, max: DVec2, size: DVec2, margin: f64, reserved: f64) {
        if !(min.is_finite() && max.is_finite() && min.cmple(max).all()) {
            return;
        }
        let extent = (max - min).max(DVec2::splat(1e-6));
        let room = (size - DVec2::new(2.0 * margin, 2.0 * margin + reserved)).max(DVec2::ONE);
        self.scale = (room.x / extent.x)
            .min(room.y / extent.y)
            .clamp(SCALE_RANGE.0, SCALE_RANGE.1);
        // The box's middle at the room's middle, `reserved / 2` points below the canvas's.
        self.centre = (min + max) / 2.0 + DVec2::new(0.0, reserved / 2.0 / self.scale);
    }
}

/// A screen point (egui, f32) as a `DVec2`, for the camera's f64 arithmetic.
pub(crate) fn dv(p: Pos2) -> DVec2 {
    DVec2::new(p.x as f64, p.y as f64)
}

/// A screen-space `DVec2` as an egui point.
pub(crate) fn pos(p: DVec2) -> Pos2 {
    Pos2::new(p.x as f32, p.y as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zoom_keeps_the_point_under_the_cursor() {
        let mut cam = Camera {
            centre: DVec2::new(3.0, -2.0),
            scale: 25.0,
        };
        let mid = DVec2::new(400.0, 300.0);
        let cursor = DVec2::new(520.0, 110.0);
        let before = cam.to_world(cursor, mid);
        cam.zoom_at(1.7, cursor, mid);
        let after = cam.to_world(cursor, mid);
        assert!((before - after).length() < 1e-9);
        assert!((cam.scale - 42.5).abs() < 1e-9);
    }

    #[test]
    fn screen_and_world_are_inverse_and_y_flips() {
        let cam = Camera {
            centre: DVec2::new(1.0, 1.0),
            scale: 10.0,
        };
        let mid = DVec2::new(50.0, 50.0);
        let s = cam.to_screen(DVec2::new(2.0, 3.0), mid);
        assert_eq!(s, DVec2::new(60.0, 30.0));
        assert!((cam.to_world(s, mid) - DVec2::new(2.0, 3.0)).length() < 1e-12);
    }

    #[test]
    fn fit_shows_the_whole_box() {
        let mut cam = Camera::default();
        cam.fit(
            DVec2::new(-1.0, 0.0),
            DVec2::new(11.0, 4.0),
            DVec2::new(640.0, 480.0),
            20.0,
        );
        let mid = DVec2::new(320.0, 240.0);
        for corner in [DVec2::new(-1.0, 0.0), DVec2::new(11.0, 4.0)] {
            let s = cam.to_screen(corner, mid);
            assert!(s.x >= 19.999 && s.x <= 620.001 && s.y >= 19.999 && s.y <= 460.001);
        }
    }
}
