//! The light-field camera model: the one place where view order, disparity sign, disparity to
//! depth, back-projection and row timing are defined. Everything else calls these.
//!
//! Conventions (binding, shared with every scene rslf reads or writes):
//! - central-view frame: OpenCV (X right, Y down, Z forward), metres;
//! - view (r, c) sits at `((c - cc) b, (r - rc) b, 0)` and its image is shifted so that the
//!   focus plane has zero disparity;
//! - disparity `d = b f (1/Z - 1/focus)`: positive = nearer than focus;
//! - a central pixel (u, v) with disparity d appears in view (r, c) at `(u - (c-cc) d, v - (r-rc) d)`;
//! - row v of every view is read at `t(v) = (v - v0) * line_time_s`.

use crate::io::SceneParameters;
use nalgebra::{Point3, Vector3};

/// The grid of sub-aperture views: `rows x cols`, view index `row * cols + col`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ViewGrid {
    /// Number of view rows (`num_cams_y`).
    pub rows: usize,
    /// Number of view columns (`num_cams_x`).
    pub cols: usize,
}

/// One sub-aperture view by its grid position.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ViewId {
    /// Grid row, top to bottom.
    pub row: usize,
    /// Grid column, left to right.
    pub col: usize,
}

impl ViewGrid {
    /// Number of views in the full grid.
    pub fn len(&self) -> usize {
        self.rows * self.cols
    }

    /// `true` for an empty grid.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The grid position of view index `i` (`input_CamNNN`, NNN = i).
    pub fn view(&self, index: usize) -> ViewId {
        ViewId { row: index / self.cols, col: index % self.cols }
    }

    /// The view index of a grid position.
    pub fn index(&self, v: ViewId) -> usize {
        v.row * self.cols + v.col
    }

    /// `rc = (rows - 1) / 2`: the central row, fractional for an even grid.
    pub fn centre_row(&self) -> f64 {
        (self.rows as f64 - 1.0) / 2.0
    }

    /// `cc = (cols - 1) / 2`: the central column, fractional for an even grid.
    pub fn centre_col(&self) -> f64 {
        (self.cols as f64 - 1.0) / 2.0
    }

    /// The central view, when the grid has one (odd rows and columns).
    pub fn central(&self) -> Option<ViewId> {
        (self.rows % 2 == 1 && self.cols % 2 == 1).then_some(ViewId { row: self.rows / 2, col: self.cols / 2 })
    }

    /// View offset `(c - cc, r - rc)` in baselines: the factor that multiplies disparity.
    pub fn offset(&self, v: ViewId) -> (f64, f64) {
        (v.col as f64 - self.centre_col(), v.row as f64 - self.centre_row())
    }

    /// Where a central-view pixel (u, v) of disparity `d` appears in view `view`.
    pub fn position_in_view(&self, view: ViewId, u: f64, v: f64, d: f64) -> (f64, f64) {
        let (dx, dy) = self.offset(view);
        (u - dx * d, v - dy * d)
    }

    /// The four corner views, in index order.
    pub fn corners(&self) -> [ViewId; 4] {
        let (r, c) = (self.rows - 1, self.cols - 1);
        [ViewId { row: 0, col: 0 }, ViewId { row: 0, col: c }, ViewId { row: r, col: 0 }, ViewId { row: r, col: c }]
    }
}

/// The metric camera of a scene with `parameters.cfg`: intrinsics, baseline, focus and timing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// The view grid.
    pub grid: ViewGrid,
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Focal length in pixels: `focal_length_mm * max(W, H) / sensor_size_mm`.
    pub f_px: f64,
    /// Distance between neighbouring views, metres.
    pub baseline_m: f64,
    /// Depth of the zero-disparity plane, metres.
    pub focus_m: f64,
    /// Seconds between two row read-outs; 0 for a global shutter.
    pub line_time_s: f64,
}

impl Camera {
    /// The camera described by `parameters.cfg`.
    pub fn from_parameters(p: &SceneParameters) -> Self {
        let (w, h) = (p.image_resolution_x_px, p.image_resolution_y_px);
        Self {
            grid: ViewGrid { rows: p.num_cams_y, cols: p.num_cams_x },
            width: w,
            height: h,
            f_px: p.focal_length_mm * w.max(h) as f64 / p.sensor_size_mm,
            baseline_m: p.baseline_mm / 1000.0,
            focus_m: p.focus_distance_m,
            line_time_s: p.line_time_s.unwrap_or(0.0),
        }
    }

    /// Principal point `u0 = (W - 1) / 2`.
    pub fn u0(&self) -> f64 {
        (self.width as f64 - 1.0) / 2.0
    }

    /// Principal point `v0 = (H - 1) / 2`.
    pub fn v0(&self) -> f64 {
        (self.height as f64 - 1.0) / 2.0
    }

    /// `b * f_px`: disparity times depth at infinite focus; the scale of disparity.
    pub fn bf(&self) -> f64 {
        self.baseline_m * self.f_px
    }

    /// Disparity of a point at depth `z`: `b f (1/z - 1/focus)`.
    pub fn depth_to_disparity(&self, z: f64) -> f64 {
        self.bf() * (1.0 / z - 1.0 / self.focus_m)
    }

    /// Depth of disparity `d`: `1 / (d / (b f) + 1 / focus)`. Not finite or not positive for
    /// disparities at or beyond infinity (`d <= -b f / focus`).
    pub fn disparity_to_depth(&self, d: f64) -> f64 {
        1.0 / (d / self.bf() + 1.0 / self.focus_m)
    }

    /// The 3D point (central frame) seen at central pixel (u, v) at depth `z`.
    pub fn back_project(&self, u: f64, v: f64, z: f64) -> Point3<f64> {
        Point3::new(z * (u - self.u0()) / self.f_px, z * (v - self.v0()) / self.f_px, z)
    }

    /// Where point `p` (central frame) appears in `view`: pixel (u, v) and its disparity.
    pub fn project(&self, view: ViewId, p: &Point3<f64>) -> (f64, f64, f64) {
        let u = self.f_px * p.x / p.z + self.u0();
        let v = self.f_px * p.y / p.z + self.v0();
        let d = self.depth_to_disparity(p.z);
        let (x, y) = self.grid.position_in_view(view, u, v, d);
        (x, y, d)
    }

    /// Optical centre of `view` in the central frame.
    pub fn view_centre(&self, view: ViewId) -> Vector3<f64> {
        let (dx, dy) = self.grid.offset(view);
        Vector3::new(dx * self.baseline_m, dy * self.baseline_m, 0.0)
    }

    /// Read-out time of image row `v` (any view): `(v - v0) * line_time_s`.
    pub fn row_time(&self, v: f64) -> f64 {
        (v - self.v0()) * self.line_time_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cotton() -> Camera {
        Camera {
            grid: ViewGrid { rows: 9, cols: 9 },
            width: 512,
            height: 512,
            f_px: 100.0 * 512.0 / 35.0,
            baseline_m: 0.025,
            focus_m: 4.25,
            line_time_s: 1e-4,
        }
    }

    #[test]
    fn disparity_and_depth_are_inverse_and_focus_has_zero_disparity() {
        let cam = cotton();
        assert!(cam.depth_to_disparity(4.25).abs() < 1e-12);
        for d in [-1.5, -0.3, 0.0, 0.7, 2.0] {
            assert!((cam.depth_to_disparity(cam.disparity_to_depth(d)) - d).abs() < 1e-9);
        }
        assert!(cam.depth_to_disparity(2.0) > 0.0, "nearer than focus must be positive");
    }

    #[test]
    fn projecting_a_back_projected_pixel_follows_the_view_shift_rule() {
        let cam = cotton();
        let (u, v, z) = (100.0, 300.0, 3.0);
        let p = cam.back_project(u, v, z);
        let d = cam.depth_to_disparity(z);
        let corner = ViewId { row: 0, col: 8 };
        let (x, y, dp) = cam.project(corner, &p);
        assert!((dp - d).abs() < 1e-12);
        assert!((x - (u - 4.0 * d)).abs() < 1e-9 && (y - (v + 4.0 * d)).abs() < 1e-9);
        // The same, from the pinhole of that view with its zero-disparity shift at focus.
        let c = cam.view_centre(corner);
        let shift_u = cam.f_px * c.x / cam.focus_m;
        let shift_v = cam.f_px * c.y / cam.focus_m;
        let x2 = cam.f_px * (p.x - c.x) / p.z + cam.u0() + shift_u;
        let y2 = cam.f_px * (p.y - c.y) / p.z + cam.v0() + shift_v;
        assert!((x - x2).abs() < 1e-9 && (y - y2).abs() < 1e-9);
    }

    #[test]
    fn row_times_are_centred_on_the_middle_row() {
        let cam = cotton();
        assert_eq!(cam.row_time(255.5), 0.0);
        assert!((cam.row_time(0.0) + 255.5e-4).abs() < 1e-15);
    }

    #[test]
    fn grid_indexing_follows_row_major_order() {
        let g = ViewGrid { rows: 9, cols: 9 };
        assert_eq!(g.central(), Some(ViewId { row: 4, col: 4 }));
        assert_eq!(g.index(g.central().unwrap()), 40);
        assert_eq!(g.view(44), ViewId { row: 4, col: 8 });
        assert_eq!(g.corners().map(|v| g.index(v)), [0, 8, 72, 80]);
        assert_eq!(ViewGrid { rows: 8, cols: 9 }.central(), None);
    }
}
