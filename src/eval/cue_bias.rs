//! How far the rolling-shutter cues measured between a scene's views stand from those its true
//! motion predicts: the measurement's own error, apart from any fit.
//!
//! Stage 2 checks and fits the motion with cues tracked between the views
//! ([`crate::pipeline::tracked_cues`]). A cue is 5-7 % of the motion's image effect, so a
//! hundredth of a pixel shared by many cues moves a fit along its weakly observed directions by
//! a large share of the shift. This measures the cues of the constant-velocity config (in the
//! corners, with its bounds), tracked from the true disparity, against the true motion's
//! prediction, and carries their misses into the motion a least-squares fit of them alone would
//! find about the truth: for the patches textured both ways (the check's cues), for the edges
//! and stripes (of which only the component across is measured), and for both together (the
//! fit's cue term).

use super::motion_error::image_motion_error;
use crate::config::ViewSelection;
use crate::geometry::Camera;
use crate::io::{MotionRecord, Raster, Scene};
use crate::pipeline::{Cue, MAX_LEVER_STEPS, MAX_RESIDUAL_OVER_MEDIAN, drop_outlying_matches, predicted_cue, stage2_views, tracked_cues};
use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;
use serde::Serialize;

/// Finite-difference steps of the cues' derivatives in ω (rad/s) and v (m/s).
const OMEGA_STEP: f64 = 1e-3;
const VELOCITY_STEP: f64 = 1e-2;
/// Components further than this many RMS misses from the prediction are left out of the share
/// and the fit, as the stage-2 check clips them.
const CLIP_RMS: f64 = 3.0;

/// One kind of measured cue against the true motion's.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CueGroup {
    /// Cues compared (each a patch in one view, both of whose positions the truth images).
    pub cues: usize,
    /// The scale of the true motion's predicted cues that fits the measured ones best (1: no
    /// bias along the motion's own cue; over 1: the cues run large); `null` for a still truth,
    /// which predicts no cue.
    pub truth_share: Option<f64>,
    /// Its standard error from the cues' scatter.
    pub truth_share_se: Option<f64>,
    /// RMS of the measured less the predicted cue, per measured component (px).
    pub rms_miss_px: f64,
    /// The image-space error (px, `rslf eval`'s measure) of the constant-velocity motion that
    /// fits these cues best, linearised about the truth: where they alone would take a fit;
    /// `null` unless the truth is a constant velocity.
    pub implied_error_px: Option<f64>,
}

/// The measured cues against the true motion's, by kind.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CueBias {
    /// Patches textured both ways: the cues the check judges a motion by.
    pub both_ways: Option<CueGroup>,
    /// Edges and stripes, across them.
    pub one_way: Option<CueGroup>,
    /// Both kinds: the cues of the fit's measured-cue term.
    pub all: Option<CueGroup>,
}

/// One measured component of a cue: the unit direction it is measured along, the measured less
/// the predicted offset along it, and the predicted offset along it.
struct Component {
    /// Index of the cue among those compared.
    cue: usize,
    axis: (f64, f64),
    miss: f64,
    predicted: f64,
}

/// The parameters of a constant-velocity truth, and each compared cue's derivatives in them
/// (px per unit, x and y).
struct Derivatives {
    truth: [f64; 6],
    per_cue: Vec<[(f64, f64); 6]>,
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
/// implied errors are taken over the t = 0 points of `gt_depth` (every `stride`-th pixel each
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
    let compared: Vec<(Cue, (f64, f64))> = cues.into_iter().filter_map(|c| Some((c, predicted_cue(camera, truth, &c)?))).collect();
    if compared.is_empty() {
        return None;
    }
    // Whether a cue belongs to a group: textured both ways (`Some(true)`), one way
    // (`Some(false)`), or any (`None`).
    let in_group = |c: &Cue, two_way: Option<bool>| two_way.is_none_or(|t| c.across.is_none() == t);
    let components = |two_way: Option<bool>| -> Vec<Component> {
        compared
            .iter()
            .enumerate()
            .filter(|(_, (c, _))| in_group(c, two_way))
            .flat_map(|(i, (c, p))| {
                c.measured_axes().into_iter().map(move |(_, (ax, ay))| Component {
                    cue: i,
                    axis: (ax, ay),
                    miss: ax * (c.offset.0 - p.0) + ay * (c.offset.1 - p.1),
                    predicted: ax * p.0 + ay * p.1,
                })
            })
            .collect()
    };
    // Each cue's derivatives in the six parameters of a constant-velocity truth, by central
    // differences about it.
    let derivatives = parameters(truth).map(|p0| {
        let shifted: Vec<(MotionRecord, MotionRecord, f64)> = (0..6)
            .map(|k| {
                let h = if k < 3 { OMEGA_STEP } else { VELOCITY_STEP };
                let (mut up, mut down) = (p0, p0);
                up[k] += h;
                down[k] -= h;
                (constant_velocity(&up), constant_velocity(&down), h)
            })
            .collect();
        let of = |c: &Cue| -> [(f64, f64); 6] {
            std::array::from_fn(|k| {
                let (up, down, h) = &shifted[k];
                match (predicted_cue(camera, up, c), predicted_cue(camera, down, c)) {
                    (Some(a), Some(b)) => ((a.0 - b.0) / (2.0 * h), (a.1 - b.1) / (2.0 * h)),
                    _ => (0.0, 0.0),
                }
            })
        };
        Derivatives { truth: p0, per_cue: compared.par_iter().map(|(c, _)| of(c)).collect() }
    });
    let group = |two_way: Option<bool>| {
        let components = components(two_way);
        let cues = compared.iter().filter(|(c, _)| in_group(c, two_way)).count();
        (cues > 0).then(|| cue_group(camera, truth, &components, cues, derivatives.as_ref(), gt_depth, stride))
    };
    Some(CueBias { both_ways: group(Some(true)), one_way: group(Some(false)), all: group(None) })
}

/// The figures of one group of `cues` cues, given as their measured `components`; with the
/// `derivatives` of a constant-velocity truth, the error of the motion they alone would give.
fn cue_group(
    camera: &Camera,
    truth: &MotionRecord,
    components: &[Component],
    cues: usize,
    derivatives: Option<&Derivatives>,
    gt_depth: &Raster,
    stride: usize,
) -> CueGroup {
    let rms_miss_px = (components.iter().map(|c| c.miss * c.miss).sum::<f64>() / components.len().max(1) as f64).sqrt();
    let kept: Vec<&Component> = components.iter().filter(|c| c.miss.abs() <= CLIP_RMS * rms_miss_px).collect();
    // The truth's share: measured = share x predicted, least squares over the kept components.
    let (num, den) = kept.iter().fold((0.0, 0.0), |(n, d), c| (n + c.miss * c.predicted, d + c.predicted * c.predicted));
    let scatter = (kept.iter().map(|c| c.miss * c.miss).sum::<f64>() / kept.len().max(1) as f64).sqrt();
    let (truth_share, truth_share_se) = if den > 1e-12 { (Some(1.0 + num / den), Some(scatter / den.sqrt())) } else { (None, None) };
    // The least-squares step the kept components ask for, each along its axis.
    let implied_error_px = derivatives.and_then(|Derivatives { truth: p0, per_cue }| {
        let (mut normal, mut rhs) = (SMatrix::<f64, 6, 6>::zeros(), SVector::<f64, 6>::zeros());
        for c in &kept {
            let row = SVector::<f64, 6>::from_fn(|k, _| {
                let d = per_cue[c.cue][k];
                c.axis.0 * d.0 + c.axis.1 * d.1
            });
            normal += row * row.transpose();
            rhs += row * c.miss;
        }
        let step = normal.svd(true, true).solve(&rhs, 1e-12 * normal.norm()).ok()?;
        let fitted: [f64; 6] = std::array::from_fn(|k| p0[k] + step[k]);
        image_motion_error(camera, &constant_velocity(&fitted), truth, gt_depth, stride).map(|e| e.rms_error_px)
    });
    CueGroup { cues, truth_share, truth_share_se, rms_miss_px, implied_error_px }
}
