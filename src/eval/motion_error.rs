//! The image-space motion error: how far apart the estimated and the true motion put the
//! scene's points in the rolling-shutter views. Parameter errors say little on their own (some
//! directions of motion barely change the images); this says what the motion does to them.

use crate::geometry::{Camera, rs_project};
use crate::io::{MotionRecord, Raster};
use serde::Serialize;

/// The image-space error of an estimated motion.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImageMotionError {
    /// RMS distance (px) between the estimated and the true positions, over all points and views.
    pub rms_error_px: f64,
    /// RMS rolling-shutter shift of the true motion (px): true position against the position
    /// with no motion.
    pub rms_true_shift_px: f64,
    /// RMS distance per view: `(view index, px)`.
    pub per_view_px: Vec<(usize, f64)>,
    /// Points compared (per view).
    pub points: usize,
}

/// One t = 0 point imaged in one view under the true and the estimated motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct PointError {
    /// Where the captured central view shows it: its position there under the true motion,
    /// rounded (its pixel at t = 0, `gt_depth`'s grid, where the truth cannot image it there).
    pub seen_at: (usize, usize),
    /// Index of the view.
    pub view: usize,
    /// Its true position less its estimated one (px).
    pub error: (f64, f64),
    /// Its true position less its position with no motion (px).
    pub shift: (f64, f64),
}

/// The t = 0 points of `gt_depth` (every `stride`-th pixel each way, finite positive depth)
/// imaged in the central view and the four corners, in that order, each at the read-out time of
/// the row it lands on under `truth`, `estimate` and no motion. Points that any of the three
/// cannot image (behind the camera, no settled row) are left out; a grid without a central
/// view gives none.
pub(super) fn point_errors(
    camera: &Camera,
    estimate: &MotionRecord,
    truth: &MotionRecord,
    gt_depth: &Raster,
    stride: usize,
) -> Vec<PointError> {
    let stride = stride.max(1);
    let zero = MotionRecord::zero();
    let Some(central) = camera.grid.central() else { return Vec::new() };
    let mut views = vec![central];
    views.extend(camera.grid.corners());
    let points: Vec<_> = (0..gt_depth.height)
        .step_by(stride)
        .flat_map(|v| (0..gt_depth.width).step_by(stride).map(move |u| (u, v)))
        .filter_map(|(u, v)| {
            let z = gt_depth.data[v * gt_depth.width + u] as f64;
            (z.is_finite() && z > 0.0).then(|| ((u, v), camera.back_project(u as f64, v as f64, z)))
        })
        .map(|(pixel, p)| {
            let inside =
                |&(x, y, _): &(f64, f64, f64)| x >= 0.0 && y >= 0.0 && x <= (camera.width - 1) as f64 && y <= (camera.height - 1) as f64;
            let seen = rs_project(camera, truth, central, &p).filter(inside);
            (seen.map_or(pixel, |(x, y, _)| (x.round() as usize, y.round() as usize)), p)
        })
        .collect();
    let mut out = Vec::new();
    for view in views {
        for (seen_at, p) in &points {
            let imaged = |m: &MotionRecord| rs_project(camera, m, view, p);
            let (Some(t), Some(e), Some(s)) = (imaged(truth), imaged(estimate), imaged(&zero)) else { continue };
            out.push(PointError {
                seen_at: *seen_at,
                view: camera.grid.index(view),
                error: (t.0 - e.0, t.1 - e.1),
                shift: (t.0 - s.0, t.1 - s.1),
            });
        }
    }
    out
}

/// Compares `estimate` with `truth` on the t = 0 points of `gt_depth` ([`point_errors`]), in the
/// central view and the four corners. `None` when no point is left.
pub fn image_motion_error(
    camera: &Camera,
    estimate: &MotionRecord,
    truth: &MotionRecord,
    gt_depth: &Raster,
    stride: usize,
) -> Option<ImageMotionError> {
    let points = point_errors(camera, estimate, truth, gt_depth, stride);
    let norm2 = |d: (f64, f64)| d.0 * d.0 + d.1 * d.1;
    let mut per_view: Vec<(usize, f64, usize)> = Vec::new();
    for p in &points {
        match per_view.last_mut() {
            Some((view, err2, n)) if *view == p.view => {
                *err2 += norm2(p.error);
                *n += 1;
            }
            _ => per_view.push((p.view, norm2(p.error), 1)),
        }
    }
    let count = points.len();
    (count > 0).then(|| ImageMotionError {
        rms_error_px: (points.iter().map(|p| norm2(p.error)).sum::<f64>() / count as f64).sqrt(),
        rms_true_shift_px: (points.iter().map(|p| norm2(p.shift)).sum::<f64>() / count as f64).sqrt(),
        per_view_px: per_view.into_iter().map(|(view, err2, n)| (view, (err2 / n as f64).sqrt())).collect(),
        points: count / 5,
    })
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::geometry::ViewGrid;

    /// A 64 x 48 px, 9 x 9 capture with a rolling shutter (also the texture split's tests').
    pub(in crate::eval) fn camera() -> Camera {
        Camera { grid: ViewGrid { rows: 9, cols: 9 }, width: 64, height: 48, f_px: 80.0, baseline_m: 0.02, focus_m: 3.0, line_time_s: 4e-4 }
    }

    fn setup() -> (Camera, Raster) {
        let cam = camera();
        let depth = Raster { width: 64, height: 48, channels: 1, data: (0..64 * 48).map(|i| 2.0 + (i % 7) as f32 * 0.3).collect() };
        (cam, depth)
    }

    #[test]
    fn the_truth_scores_zero_and_no_motion_scores_the_true_shift() {
        let (cam, depth) = setup();
        let truth = MotionRecord::ConstantVelocity { omega_rad_s: [0.2, -0.1, 0.3], velocity_m_s: [0.3, 0.1, -0.2] };
        let same = image_motion_error(&cam, &truth, &truth, &depth, 3).unwrap();
        assert!(same.rms_error_px < 1e-9 && same.rms_true_shift_px > 0.05, "{same:?}");
        let none = image_motion_error(&cam, &MotionRecord::zero(), &truth, &depth, 3).unwrap();
        assert!((none.rms_error_px - none.rms_true_shift_px).abs() < 1e-9, "{none:?}");
        assert_eq!(none.per_view_px.iter().map(|v| v.0).collect::<Vec<_>>(), vec![40, 0, 8, 72, 80]);
        // Half the velocity leaves about half the shift.
        let half = MotionRecord::ConstantVelocity { omega_rad_s: [0.1, -0.05, 0.15], velocity_m_s: [0.15, 0.05, -0.1] };
        let e = image_motion_error(&cam, &half, &truth, &depth, 3).unwrap();
        assert!((e.rms_error_px / e.rms_true_shift_px - 0.5).abs() < 0.05, "{e:?}");
    }

    #[test]
    fn points_without_depth_are_left_out() {
        let (cam, mut depth) = setup();
        depth.data.iter_mut().for_each(|z| *z = f32::NAN);
        assert!(image_motion_error(&cam, &MotionRecord::zero(), &MotionRecord::zero(), &depth, 1).is_none());
    }
}
