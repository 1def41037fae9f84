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

use super::measured_cues::{Cue, predicted_cue};
use crate::geometry::Camera;
use crate::io::MotionRecord;

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
}

/// The support `cues` give `estimate` on a scene seen by `camera`: each component of each cue
/// is weighted by the inverse variance of that component's residuals about the prediction
/// (median absolute deviation), and residuals are clipped at three deviations. `None` with
/// fewer than 100 cues the estimate images, or when it predicts no cue at all (no motion).
pub fn cue_support(camera: &Camera, estimate: &MotionRecord, cues: &[Cue]) -> Option<CueSupport> {
    let pairs: Vec<((f64, f64), (f64, f64))> = cues.iter().filter_map(|c| Some((c.offset, predicted_cue(camera, estimate, c)?))).collect();
    if pairs.len() < MIN_CUES {
        return None;
    }
    let spread = |component: fn(&(f64, f64)) -> f64| {
        let residuals: Vec<f64> = pairs.iter().map(|(m, p)| component(m) - component(p)).collect();
        (1.4826 * median_absolute_deviation(residuals)).max(1e-6)
    };
    let (sx, sy) = (spread(|c| c.0), spread(|c| c.1));
    let (mut num, mut den) = (0.0, 0.0);
    for (m, p) in &pairs {
        let (rx, ry) = ((m.0 - p.0).clamp(-3.0 * sx, 3.0 * sx), (m.1 - p.1).clamp(-3.0 * sy, 3.0 * sy));
        num += rx * p.0 / (sx * sx) + ry * p.1 / (sy * sy);
        den += p.0 * p.0 / (sx * sx) + p.1 * p.1 / (sy * sy);
    }
    (den > 1e-12).then(|| CueSupport { share: 1.0 + num / den, standard_error: den.sqrt().recip(), cues: pairs.len() })
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
mod tests {
    use super::*;
    use crate::geometry::ViewGrid;
    use crate::random::Rng;

    fn camera() -> Camera {
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
                let mut cue = Cue { at, disparity: -1.0 + 0.005 * i as f64, view, offset: (0.0, 0.0) };
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
