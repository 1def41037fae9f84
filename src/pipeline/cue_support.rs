//! How far the cues measured straight from the views ([`super::measured_cues`]) bear out an
//! estimated motion: the check stage 2 makes before it keeps a motion.
//!
//! The photometric fit can settle on a small spurious motion where the stage-1 model renders
//! the corners imperfectly (a still camera drifting by a few tenths of a pixel; docs/results.md).
//! The measured cues owe nothing to that model. The support of an estimate is the robust,
//! noise-weighted least-squares scale `s` that best fits `s × predicted` to the measured cues:
//! about 1 when they show the motion the estimate predicts, about 0 when they show none of it.
//! Stage 2 keeps a motion only when its support is clearly over a threshold
//! ([`CueSupport::confirms`]).

use super::measured_cues::{Cue, CueAxis, predicted_cue};
use crate::geometry::Camera;
use crate::io::MotionRecord;
use std::collections::BTreeMap;

/// Fewest cues a support is computed from.
const MIN_CUES: usize = 100;

/// The support the measured cues give an estimated motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CueSupport {
    /// The scale of the estimate's predicted cues that fits the measured ones best (1: borne
    /// out; 0: the cues show no such motion).
    pub share: f64,
    /// Its standard error from the cues' scatter alone (biases of the measurement, e.g. a
    /// renderer's aliasing, come on top).
    pub standard_error: f64,
    /// Cues used.
    pub cues: usize,
}

impl CueSupport {
    /// Whether the cues refute a motion at the threshold `min_share`: its support lies under
    /// it by more than two standard errors. A motion whose cues are too small to judge (few
    /// cues, little disparity) is never refuted.
    pub fn refutes(&self, min_share: f64) -> bool {
        self.share + 2.0 * self.standard_error < min_share
    }

    /// Whether the cues confirm a motion at the threshold `min_share`: its support lies at or
    /// over it by at least two standard errors.
    pub fn confirms(&self, min_share: f64) -> bool {
        self.share - 2.0 * self.standard_error >= min_share
    }

    /// How far the cues the motion predicts stand clear of none, per cue, in units of the
    /// measured cues' scatter: the support's share over its standard error (the signal-to-noise
    /// ratio of the motion in all the cues) over the square root of their number. About the RMS
    /// of the predicted cues over the scatter for a motion the cues bear out; unlike the ratio
    /// itself it does not grow with the number of cues, which would carry the cues' shared
    /// biases (not counted in the scatter) over any fixed bound on a large enough image.
    pub fn signal(&self) -> f64 {
        self.share / (self.standard_error * (self.cues.max(1) as f64).sqrt())
    }
}

/// The support `cues` give `estimate` on a scene seen by `camera`: each measured component of
/// each cue ([`Cue::measured_axes`]) is weighted by the inverse variance of the residuals
/// about the prediction of the components along its axis (median absolute deviation), and
/// residuals are clipped at three deviations. `None` with fewer than 100 cues the estimate
/// images, or when it predicts no cue at all (no motion).
pub fn cue_support(camera: &Camera, estimate: &MotionRecord, cues: &[Cue]) -> Option<CueSupport> {
    let (components, imaged) = weighed_components(camera, &MotionRecord::zero(), estimate, cues)?;
    let (num, den) = components.iter().fold((0.0, 0.0), |(n, d), c| (n + c.weight * c.residual * c.part, d + c.weight * c.part * c.part));
    (den > 1e-12).then(|| CueSupport { share: 1.0 + num / den, standard_error: den.sqrt().recip(), cues: imaged })
}

/// One measured component of a cue, weighed against an estimate and the part of its prediction
/// that a smaller `base` motion lacks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct WeighedComponent {
    /// The cue's patch centre in the central view (px).
    pub at: (f64, f64),
    /// The inverse variance of the residuals along its axis.
    pub weight: f64,
    /// Measured less predicted by the estimate, clipped at three deviations (px).
    pub residual: f64,
    /// Predicted by the estimate less predicted by `base` (px).
    pub part: f64,
}

/// Each measured component of the cues that both `estimate` and `base` image, weighed as in
/// [`cue_support`], with the number of cues they came from. The least-squares scale of the
/// part `estimate` adds to `base` is then `1 + Σ w r p / Σ w p²`. `None` under 100 cues.
pub(super) fn weighed_components(
    camera: &Camera,
    base: &MotionRecord,
    estimate: &MotionRecord,
    cues: &[Cue],
) -> Option<(Vec<WeighedComponent>, usize)> {
    // Each component's position and (measured, predicted, predicted by base) values, by axis.
    type Row = ((f64, f64), [f64; 3]);
    let mut by_axis: BTreeMap<CueAxis, Vec<Row>> = BTreeMap::new();
    let mut imaged = 0;
    for cue in cues {
        let Some(predicted) = predicted_cue(camera, estimate, cue) else { continue };
        let Some(from_base) = predicted_cue(camera, base, cue) else { continue };
        imaged += 1;
        for (axis, (ax, ay)) in cue.measured_axes() {
            let along = |(du, dv): (f64, f64)| ax * du + ay * dv;
            by_axis.entry(axis).or_default().push((cue.at, [along(cue.offset), along(predicted), along(from_base)]));
        }
    }
    if imaged < MIN_CUES {
        return None;
    }
    let mut components = Vec::new();
    for rows in by_axis.values() {
        let spread = (1.4826 * median_absolute_deviation(rows.iter().map(|(_, [m, p, _])| m - p).collect())).max(1e-6);
        components.extend(rows.iter().map(|&(at, [m, p, b])| WeighedComponent {
            at,
            weight: (spread * spread).recip(),
            residual: (m - p).clamp(-3.0 * spread, 3.0 * spread),
            part: p - b,
        }));
    }
    Some((components, imaged))
}

/// The median absolute deviation of `values` from their median.
fn median_absolute_deviation(mut values: Vec<f64>) -> f64 {
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let m = median(&mut values);
    let mut deviations: Vec<f64> = values.iter().map(|x| (x - m).abs()).collect();
    median(&mut deviations)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::geometry::ViewGrid;
    use crate::random::Rng;

    /// A 256 px, 9 x 9 capture with a rolling shutter (also the roll-and-forward check's tests').
    pub(in crate::pipeline) fn camera() -> Camera {
        Camera {
            grid: ViewGrid { rows: 9, cols: 9 },
            width: 256,
            height: 256,
            f_px: 360.0,
            baseline_m: 0.03,
            focus_m: 3.0,
            line_time_s: 1e-4,
        }
    }

    /// [`cues`], each made one-way across a direction that turns from cue to cue (the offset
    /// keeps its component across it, with noise of 0.05 px along it).
    fn one_way_cues(truth: &MotionRecord) -> Vec<Cue> {
        let mut rng = Rng::new(11);
        cues(truth)
            .into_iter()
            .enumerate()
            .map(|(i, mut cue)| {
                let angle = 0.37 * i as f64;
                let n = (angle.cos(), angle.sin());
                let across = n.0 * cue.offset.0 + n.1 * cue.offset.1 + 0.1 * (rng.unit() - 0.5);
                cue.offset = (across * n.0, across * n.1);
                cue.across = Some(n);
                cue
            })
            .collect()
    }

    #[test]
    fn one_way_cues_weigh_the_component_across_their_edges() {
        let truth = MotionRecord::ConstantVelocity { omega_rad_s: [0.05, 0.3, 0.1], velocity_m_s: [0.8, 0.1, -0.3] };
        let support = |m: &MotionRecord, cues: &[Cue]| {
            let Some(support) = cue_support(&camera(), m, cues) else { panic!("no support from {} cues", cues.len()) };
            support
        };
        let measured = one_way_cues(&truth);
        let right = support(&truth, &measured);
        assert!((right.share - 1.0).abs() < 4.0 * right.standard_error + 0.02, "{right:?}");
        let double = MotionRecord::ConstantVelocity { omega_rad_s: [0.1, 0.6, 0.2], velocity_m_s: [1.6, 0.2, -0.6] };
        assert!((support(&double, &measured).share - 0.5).abs() < 0.05);
        // Mixed with two-way cues, one support over both.
        let mixed: Vec<Cue> = measured.into_iter().chain(cues(&truth)).collect();
        let both = support(&truth, &mixed);
        assert!((both.share - 1.0).abs() < 4.0 * both.standard_error + 0.02 && both.cues == mixed.len(), "{both:?}");
        assert!(both.standard_error < right.standard_error, "{both:?} against {right:?}");
    }

    /// Cues at assorted positions and disparities in the four corners, measured under `truth`
    /// with Gaussian noise of 0.05 px (0.1 px vertically).
    fn cues(truth: &MotionRecord) -> Vec<Cue> {
        let cam = camera();
        let mut rng = Rng::new(7);
        let mut normal = move || (-2.0 * rng.unit().max(1e-12).ln()).sqrt() * (std::f64::consts::TAU * rng.unit()).cos();
        cam.grid
            .corners()
            .into_iter()
            .flat_map(|view| (0..400).map(move |i| (view, i)))
            .filter_map(|(view, i)| {
                let at = (20.0 + (i % 20) as f64 * 11.0, 20.0 + (i / 20) as f64 * 11.0);
                let mut cue = Cue { at, disparity: -1.0 + 0.005 * i as f64, view, offset: (0.0, 0.0), across: None, residual: 0.0 };
                let p = predicted_cue(&cam, truth, &cue)?;
                cue.offset = (p.0 + 0.05 * normal(), p.1 + 0.1 * normal());
                Some(cue)
            })
            .collect()
    }

    #[test]
    fn the_true_motion_is_borne_out_and_a_spurious_one_is_not() {
        let truth = MotionRecord::ConstantVelocity { omega_rad_s: [0.05, 0.3, 0.1], velocity_m_s: [0.8, 0.1, -0.3] };
        let measured = cues(&truth);
        let support = |m: &MotionRecord, cues: &[Cue]| cue_support(&camera(), m, cues).unwrap();
        let right = support(&truth, &measured);
        assert!((right.share - 1.0).abs() < 4.0 * right.standard_error + 0.02, "{right:?}");
        // Twice the true motion: half of it is borne out.
        let double = MotionRecord::ConstantVelocity { omega_rad_s: [0.1, 0.6, 0.2], velocity_m_s: [1.6, 0.2, -0.6] };
        assert!((support(&double, &measured).share - 0.5).abs() < 0.05);
        // A still camera's cues bear out none of a roll-and-zoom drift.
        let still = cues(&MotionRecord::zero());
        let drift = MotionRecord::ConstantVelocity { omega_rad_s: [0.0, 0.0, 0.2], velocity_m_s: [0.0, 0.0, -0.4] };
        let spurious = support(&drift, &still);
        assert!(spurious.share.abs() < 4.0 * spurious.standard_error + 0.05, "{spurious:?}");
        // No motion predicts no cue: nothing to weigh.
        assert!(cue_support(&camera(), &MotionRecord::zero(), &still).is_none());
    }
}
