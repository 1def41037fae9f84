//! How far the rolling-shutter cues measured between a scene's views stand from those its true
//! motion predicts: the measurement's own error, apart from any fit.
//!
//! Stage 2 checks and fits the motion with cues tracked between the views
//! ([`crate::pipeline::tracked_cues`]). A cue is 5-7 % of the motion's image effect, so a
//! hundredth of a pixel shared by many cues moves a fit along its weakly observed directions by
//! a large share of the shift. This measures the cues the constant-velocity config's check uses
//! (patches textured both ways, in the corners, with its bounds), tracked from the true
//! disparity, against the true motion's prediction, and carries their misses into the motion a
//! least-squares fit of the cues alone would find about the truth.

use super::motion_error::image_motion_error;
use crate::config::ViewSelection;
use crate::geometry::Camera;
use crate::io::{MotionRecord, Raster, Scene};
use crate::pipeline::{Cue, MAX_LEVER_STEPS, MAX_RESIDUAL_OVER_MEDIAN, drop_outlying_matches, predicted_cue, stage2_views, tracked_cues};
use nalgebra::{SMatrix, SVector};
use serde::Serialize;

/// Finite-difference steps of the cues' derivatives in ω (rad/s) and v (m/s).
const OMEGA_STEP: f64 = 1e-3;
const VELOCITY_STEP: f64 = 1e-2;
/// Components further than this many RMS misses from the prediction are left out of the
/// least-squares fit, as the stage-2 check clips them.
const CLIP_RMS: f64 = 3.0;

/// The measured cues against the true motion's.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CueBias {
    /// Cues compared (patches textured both ways, each in one view, both of whose positions the
    /// truth images).
    pub cues: usize,
    /// The scale of the true motion's predicted cues that fits the measured ones best (1: no
    /// bias along the motion's own cue; over 1: the cues run large) and its standard error
    /// from their scatter; `null` for a still truth, which predicts no cue.
    pub truth_share: Option<f64>,
    /// Standard error of `truth_share`.
    pub truth_share_se: Option<f64>,
    /// RMS of the measured less the predicted cue, per component (px).
    pub rms_miss_px: f64,
    /// The image-space error (px, `rslf eval`'s measure) of the constant-velocity motion that
    /// fits the measured cues best, linearised about the truth: where the cues alone would take
    /// a fit; `null` unless the truth is a constant velocity.
    pub implied_error_px: Option<f64>,
}

/// The parameters of a constant-velocity record, ω then v.
fn parameters(record: &MotionRecord) -> Option<[f64; 6]> {
    match record {
        MotionRecord::ConstantVelocity { omega_rad_s: w, velocity_m_s: v } => Some([w[0], w[1], w[2], v[0], v[1], v[2]]),
        _ => None,
    }
}

fn constant_velocity(p: &[f64; 6]) -> MotionRecord {
    MotionRecord::ConstantVelocity { omega_rad_s: [p[0], p[1], p[2]], velocity_m_s: [p[3], p[4], p[5]] }
}

/// The cues of `scene` (tracked from `true_disparity`) against those `truth` predicts; the
/// implied error is taken over the t = 0 points of `gt_depth` (every `stride`-th pixel each
/// way). `None` when no cue is measured.
pub fn cue_bias(
    scene: &Scene,
    camera: &Camera,
    truth: &MotionRecord,
    true_disparity: &Raster,
    gt_depth: &Raster,
    stride: usize,
) -> Option<CueBias> {
    let views = stage2_views(scene, ViewSelection::Corners);
    let mut cues = tracked_cues(scene, true_disparity, &views, true, MAX_LEVER_STEPS).cues;
    drop_outlying_matches(&mut cues, MAX_RESIDUAL_OVER_MEDIAN);
    let compared: Vec<(Cue, (f64, f64))> =
        cues.into_iter().filter(|c| c.across.is_none()).filter_map(|c| Some((c, predicted_cue(camera, truth, &c)?))).collect();
    if compared.is_empty() {
        return None;
    }
    // Residuals and predictions, both components of each cue.
    let misses: Vec<f64> = compared.iter().flat_map(|(c, p)| [c.offset.0 - p.0, c.offset.1 - p.1]).collect();
    let predicted: Vec<f64> = compared.iter().flat_map(|(_, p)| [p.0, p.1]).collect();
    let rms_miss_px = (misses.iter().map(|r| r * r).sum::<f64>() / misses.len() as f64).sqrt();
    let kept: Vec<bool> = misses.iter().map(|r| r.abs() <= CLIP_RMS * rms_miss_px).collect();
    let n = kept.iter().filter(|&&k| k).count().max(1) as f64;
    // The truth's share: measured = share x predicted, least squares over the kept components.
    let (num, den) = misses
        .iter()
        .zip(&predicted)
        .zip(&kept)
        .filter(|(_, k)| **k)
        .fold((0.0, 0.0), |(num, den), ((r, p), _)| (num + r * p, den + p * p));
    let scatter = (misses.iter().zip(&kept).filter(|(_, k)| **k).map(|(r, _)| r * r).sum::<f64>() / n).sqrt();
    let still = den <= 1e-12;
    let (truth_share, truth_share_se) = if still { (None, None) } else { (Some(1.0 + num / den), Some(scatter / den.sqrt())) };
    let implied_error_px = parameters(truth).and_then(|p0| {
        // The cues' derivatives in each parameter, by central differences about the truth.
        let mut jacobian: Vec<[f64; 6]> = vec![[0.0; 6]; misses.len()];
        for k in 0..6 {
            let h = if k < 3 { OMEGA_STEP } else { VELOCITY_STEP };
            let (mut up, mut down) = (p0, p0);
            up[k] += h;
            down[k] -= h;
            let (up, down) = (constant_velocity(&up), constant_velocity(&down));
            for (i, (c, _)) in compared.iter().enumerate() {
                let (Some(a), Some(b)) = (predicted_cue(camera, &up, c), predicted_cue(camera, &down, c)) else { continue };
                jacobian[2 * i][k] = (a.0 - b.0) / (2.0 * h);
                jacobian[2 * i + 1][k] = (a.1 - b.1) / (2.0 * h);
            }
        }
        let (mut normal, mut rhs) = (SMatrix::<f64, 6, 6>::zeros(), SVector::<f64, 6>::zeros());
        for ((row, r), _) in jacobian.iter().zip(&misses).zip(&kept).filter(|(_, k)| **k) {
            let j = SVector::<f64, 6>::from_row_slice(row);
            normal += j * j.transpose();
            rhs += j * *r;
        }
        let step = normal.svd(true, true).solve(&rhs, 1e-12 * normal.norm()).ok()?;
        let fitted: [f64; 6] = std::array::from_fn(|k| p0[k] + step[k]);
        image_motion_error(camera, &constant_velocity(&fitted), truth, gt_depth, stride).map(|e| e.rms_error_px)
    });
    Some(CueBias { cues: compared.len(), truth_share, truth_share_se, rms_miss_px, implied_error_px })
}
