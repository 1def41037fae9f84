//! Rolling-shutter cues measured straight from the views, with no scene model.
//!
//! The views of the central row read each image row at the same time, so a patch moves between
//! them by its disparity alone: `a d` between views `a` columns apart. A corner view `(r, c)`
//! sees the same patch `b = r - rc` view rows away, `b d` image rows up or down, read that much
//! earlier or later; under a motion it sits `μ` off where the disparity alone puts it. Tracking a
//! textured patch of the central-row view of the corner's column into the central view (which
//! gives `d`) and into the corner (same column: no horizontal parallax) measures `μ`:
//! [`measure_cues`]. With a still camera every `μ` is zero up to the tracking noise.
//!
//! Stage 2 can weigh these against the cues its motion predicts ([`super::cue_term`]); the
//! photometric fit alone compares the corners with renders of the stage-1 model, whose errors
//! there are far larger than `μ` (docs/results.md).

use super::view_tracking::{TrackSettings, textured_points, track};
use crate::geometry::{Camera, ViewId, pose_at, readout_interval, rs_project};
use crate::io::{MotionRecord, Raster, Scene};
use rayon::prelude::*;

/// A measured rolling-shutter cue: a textured patch, where it is in the central view, and where
/// it sits in one corner view against where its disparity alone would put it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cue {
    /// The patch centre in the central view (px).
    pub at: (f64, f64),
    /// Its disparity, measured against the central-row view of the corner's column (px).
    pub disparity: f64,
    /// The corner view.
    pub view: ViewId,
    /// Its offset in that view from the position its disparity gives (px).
    pub offset: (f64, f64),
}

/// The measured cues of `scene`, corner by corner: the patches of the central-row view of the
/// corner's column that are textured in both directions (on a grid of about 128 x 128), each
/// tracked into the central view and into the corner. `guess` (a disparity map of the central
/// view, e.g. the plane sweep's) only starts the tracking. Patches lost in either view, or found
/// more than 0.25 px up or down in the central view (the row views are read at the same time,
/// so that is a mismatch), are left out. Corners or row views the scene lacks give no cues.
pub fn measure_cues(scene: &Scene, guess: &Raster) -> Vec<Cue> {
    let grid = scene.grid;
    let (Some(centre), w, h) = (grid.central(), scene.width(), scene.height()) else { return Vec::new() };
    let settings = TrackSettings::default();
    let central = scene.central().to_grey();
    let stride = ((w * h) as f64 / 16384.0).sqrt().round().max(2.0) as usize;
    let mut cues = Vec::new();
    // The corners two by two, by column: both are tracked from the same row view.
    let mut columns: Vec<usize> = grid.corners().iter().map(|c| c.col).collect();
    columns.sort();
    columns.dedup();
    for col in columns {
        let corners: Vec<(ViewId, Raster)> =
            grid.corners().into_iter().filter(|c| c.col == col).filter_map(|c| Some((c, scene.view(c)?.to_grey()))).collect();
        let Some(row_img) = scene.view(ViewId { row: centre.row, col }) else { continue };
        let a = grid.offset(ViewId { row: centre.row, col }).0;
        if a == 0.0 || corners.is_empty() {
            continue;
        }
        let row_img = row_img.to_grey();
        let points = textured_points(&row_img, settings.radius, stride, 0.1);
        let found: Vec<Vec<Cue>> = points
            .par_iter()
            .filter_map(|&(x, y)| {
                let gx = ((x as f64 + a * guess_d0(guess, x, y)?).round().max(0.0) as usize).min(w - 1);
                let d0 = guess_d0(guess, gx, y)?;
                // The patch of the row view, found in the central view `a d` to the right: `d`.
                let to_centre = track(&row_img, &central, (x, y), (a * d0, 0.0), &settings)?;
                if to_centre.displacement.1.abs() > 0.25 {
                    return None;
                }
                let d = to_centre.displacement.0 / a;
                // The same patch in each corner of its column: `b d` rows up or down, and `μ`.
                let in_corners = corners.iter().filter_map(|(view, image)| {
                    let b = grid.offset(*view).1;
                    let (dx, dy) = track(&row_img, image, (x, y), (0.0, -b * d), &settings)?.displacement;
                    Some(Cue { at: (x as f64 + a * d, y as f64), disparity: d, view: *view, offset: (dx, dy + b * d) })
                });
                Some(in_corners.collect())
            })
            .collect();
        cues.extend(found.into_iter().flatten());
    }
    cues
}

/// The guess's disparity at (x, y), when finite.
fn guess_d0(guess: &Raster, x: usize, y: usize) -> Option<f64> {
    let d = *guess.data.get(y * guess.width + x)? as f64;
    d.is_finite().then_some(d)
}

/// The cue `estimate` predicts for a patch: where it puts the point seen at `cue.at` with
/// `cue.disparity` (the scene at that row's read-out time) in `cue.view`, less where no motion
/// puts it. `None` when either cannot image it.
pub fn predicted_cue(camera: &Camera, estimate: &MotionRecord, cue: &Cue) -> Option<(f64, f64)> {
    let z = camera.disparity_to_depth(cue.disparity);
    if !(z.is_finite() && z > 0.0) {
        return None;
    }
    let (u, v) = cue.at;
    let seen = camera.back_project(u, v, z);
    let at_zero = pose_at(estimate, camera.row_time(v), readout_interval(camera.height, camera.line_time_s)).inverse().apply(&seen);
    let moved = rs_project(camera, estimate, cue.view, &at_zero)?;
    let still = rs_project(camera, &MotionRecord::zero(), cue.view, &seen)?;
    Some((moved.0 - still.0, moved.1 - still.1))
}
