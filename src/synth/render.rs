//! Ray-traced rolling-shutter views: row v of every view is read at `t(v)`, when the scene has
//! the pose the motion gives it at that time.

use super::world::{Hit, World};
use crate::geometry::{Camera, Pose, ViewId, pose_at, readout_interval};
use crate::io::{MotionRecord, Raster};
use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

/// A scene, a camera and a motion: everything needed to render any view.
pub struct Capture<'a> {
    /// The scene at t = 0.
    pub world: &'a World,
    /// The camera.
    pub camera: &'a Camera,
    /// Scene-frame-at-0 from camera-frame-at-t, per image row (the inverse of the row's pose).
    row_inverse: Vec<Pose>,
    motion: MotionRecord,
}

impl<'a> Capture<'a> {
    /// A capture of `world` by `camera` under `motion` (zero motion: global shutter).
    pub fn new(world: &'a World, camera: &'a Camera, motion: &MotionRecord) -> Self {
        let readout = readout_interval(camera.height, camera.line_time_s);
        let row_inverse = (0..camera.height).map(|y| pose_at(motion, camera.row_time(y as f64), readout).inverse()).collect();
        Self { world, camera, row_inverse, motion: motion.clone() }
    }

    /// The scene-frame ray through point (px, py) of `view` at the exact time `row_time(py)`.
    pub fn ray_at_row_time(&self, view: ViewId, px: f64, py: f64) -> (Point3<f64>, Vector3<f64>) {
        let cam = self.camera;
        let inv = pose_at(&self.motion, cam.row_time(py), readout_interval(cam.height, cam.line_time_s)).inverse();
        self.ray_with(view, px, py, &inv)
    }

    /// The scene-frame ray through point (px, py) of `view`, at the pose of image row `row`.
    pub fn ray(&self, view: ViewId, px: f64, py: f64, row: usize) -> (Point3<f64>, Vector3<f64>) {
        let inv = &self.row_inverse[row.min(self.row_inverse.len() - 1)];
        self.ray_with(view, px, py, inv)
    }

    fn ray_with(&self, view: ViewId, px: f64, py: f64, inv: &Pose) -> (Point3<f64>, Vector3<f64>) {
        let cam = self.camera;
        let c = cam.view_centre(view);
        let dir = Vector3::new((px - cam.u0()) / cam.f_px - c.x / cam.focus_m, (py - cam.v0()) / cam.f_px - c.y / cam.focus_m, 1.0);
        (inv.apply(&Point3::from(c)), inv.rotation * dir)
    }

    /// Renders `view` with `n x n` samples per pixel, each row at its read-out time.
    pub fn render_view(&self, view: ViewId, n: usize) -> Raster {
        let (w, h) = (self.camera.width, self.camera.height);
        let mut img = Raster::zeros(w, h, 3);
        let bg = self.world.background;
        img.data.par_chunks_mut(w * 3).enumerate().for_each(|(y, row)| {
            for x in 0..w {
                let mut sum = [0.0f64; 3];
                for sy in 0..n {
                    for sx in 0..n {
                        let px = x as f64 + (sx as f64 + 0.5) / n as f64 - 0.5;
                        let py = y as f64 + (sy as f64 + 0.5) / n as f64 - 0.5;
                        let (o, d) = self.ray(view, px, py, y);
                        let c = self.world.trace(&o, &d).map_or(bg, |hit| hit.color);
                        (0..3).for_each(|k| sum[k] += c[k]);
                    }
                }
                for k in 0..3 {
                    row[x * 3 + k] = (sum[k] / (n * n) as f64) as f32;
                }
            }
        });
        img
    }

    /// The first hit through the centre of every pixel of `view` (row-major).
    pub fn trace_centres(&self, view: ViewId) -> Vec<Option<Hit>> {
        let (w, h) = (self.camera.width, self.camera.height);
        (0..w * h)
            .into_par_iter()
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let (o, d) = self.ray(view, x as f64, y as f64, y);
                self.world.trace(&o, &d)
            })
            .collect()
    }
}
