//! Ground truth of a generated scene: the central view at t = 0 (colour, depth, disparity) and
//! which of its points the rolling-shutter central view shows.

use super::render::Capture;
use super::world::World;
use crate::geometry::{Camera, rs_project};
use crate::io::{MotionRecord, Raster};
use rayon::prelude::*;

/// The evaluation files of a generated scene.
#[derive(Debug, Clone)]
pub struct Truth {
    /// Depth Z (m) of the central view at t = 0; infinite where a ray meets nothing.
    pub depth: Raster,
    /// Disparity of the central view at t = 0.
    pub disparity: Raster,
    /// The central view at t = 0 without rolling shutter.
    pub central: Raster,
    /// Pixels whose t = 0 point is visible in the rolling-shutter central view.
    pub mask: Vec<bool>,
}

/// Computes the ground truth of `world` seen by `camera` under `motion`, `n x n` samples per pixel.
pub fn ground_truth(world: &World, camera: &Camera, motion: &MotionRecord, n: usize) -> Truth {
    let (w, h) = (camera.width, camera.height);
    let still = Capture::new(world, camera, &MotionRecord::zero());
    let centre = camera.grid.central().expect("odd grid");
    let central = still.render_view(centre, n);
    let hits = still.trace_centres(centre);
    let depth_data: Vec<f32> = hits.iter().map(|h| h.map_or(f32::INFINITY, |h| h.point.z as f32)).collect();
    let disparity_data = depth_data.iter().map(|&z| camera.depth_to_disparity(z as f64) as f32).collect();
    let moving = Capture::new(world, camera, motion);
    let mask = hits
        .par_iter()
        .map(|hit| {
            let Some(hit) = hit else { return false };
            let Some((x, y, _)) = rs_project(camera, motion, centre, &hit.point) else { return false };
            if !(x >= -0.5 && y >= -0.5 && x < w as f64 - 0.5 && y < h as f64 - 0.5) {
                return false;
            }
            // The rolling-shutter ray through (x, y) passes through the point; it is visible when
            // nothing nearer stops that ray.
            let (o, d) = moving.ray_at_row_time(centre, x, y);
            world.trace(&o, &d).is_some_and(|seen| (seen.point - hit.point).norm() < 1e-4 * (1.0 + hit.point.z.abs()))
        })
        .collect();
    Truth {
        depth: Raster { width: w, height: h, channels: 1, data: depth_data },
        disparity: Raster { width: w, height: h, channels: 1, data: disparity_data },
        central,
        mask,
    }
}
