//! The metrics of an estimate against ground truth, each over an explicit set of pixels.
//!
//! Disparity: HCI's benchmark metrics, MSE x 100 and BadPix(t) = percentage of pixels with
//! `|d - d_gt| > t`. Depth: the paper's abs diff (m), RMSE (m) and δ < 1.25 (fraction of pixels
//! with `max(z/z_gt, z_gt/z) < 1.25`). Image: PSNR in dB for values in [0, 1].

use crate::io::{MotionRecord, Raster};
use serde::Serialize;

/// HCI's border rule: this many pixels on each side are left out of disparity metrics.
pub const HCI_BORDER_PX: usize = 15;

/// The BadPix thresholds reported.
pub const BADPIX_THRESHOLDS: [f64; 3] = [0.07, 0.03, 0.01];

/// The pixels a metric is computed over: inside the mask (when any), away from the border.
pub fn evaluation_region(width: usize, height: usize, mask: Option<&[bool]>, border: usize) -> Vec<bool> {
    (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let inside = x >= border && y >= border && x + border < width && y + border < height;
            inside && mask.is_none_or(|m| m[i])
        })
        .collect()
}

/// Disparity metrics (HCI).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DisparityMetrics {
    /// Mean squared error x 100 over the finite estimates.
    pub mse_x100: f64,
    /// `[threshold, percentage of bad pixels]` for each of [`BADPIX_THRESHOLDS`]; a non-finite
    /// estimate counts as bad.
    pub badpix_percent: Vec<(f64, f64)>,
    /// Pixels evaluated.
    pub pixels: usize,
    /// Evaluated pixels whose estimate is not finite.
    pub non_finite: usize,
}

/// Disparity metrics of `est` against `gt` over `region` (pixels with a non-finite truth are skipped).
pub fn disparity_metrics(est: &Raster, gt: &Raster, region: &[bool]) -> DisparityMetrics {
    let (mut sq, mut finite, mut pixels, mut non_finite) = (0.0f64, 0usize, 0usize, 0usize);
    let mut bad = [0usize; BADPIX_THRESHOLDS.len()];
    for ((&e, &g), &inside) in est.data.iter().zip(&gt.data).zip(region) {
        let (e, g) = (e as f64, g as f64);
        if !inside || !g.is_finite() {
            continue;
        }
        pixels += 1;
        if !e.is_finite() {
            non_finite += 1;
            bad.iter_mut().for_each(|b| *b += 1);
            continue;
        }
        let err = (e - g).abs();
        sq += err * err;
        finite += 1;
        for (b, t) in bad.iter_mut().zip(BADPIX_THRESHOLDS) {
            *b += usize::from(err > t);
        }
    }
    let pct = |n: usize| if pixels == 0 { f64::NAN } else { 100.0 * n as f64 / pixels as f64 };
    DisparityMetrics {
        mse_x100: if finite == 0 { f64::NAN } else { 100.0 * sq / finite as f64 },
        badpix_percent: BADPIX_THRESHOLDS.iter().zip(bad).map(|(&t, n)| (t, pct(n))).collect(),
        pixels,
        non_finite,
    }
}

/// Depth metrics (the paper's).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DepthMetrics {
    /// Mean of `|z - z_gt|`, metres.
    pub abs_diff_m: f64,
    /// Root mean squared error, metres.
    pub rmse_m: f64,
    /// Fraction of pixels with `max(z/z_gt, z_gt/z) < 1.25` (a non-positive estimate fails).
    pub delta_1_25: f64,
    /// Pixels evaluated (positive finite truth and finite estimate).
    pub pixels: usize,
    /// Evaluated pixels skipped because the estimate is not finite.
    pub non_finite: usize,
}

/// Depth metrics of `est` against `gt` over `region`.
pub fn depth_metrics(est: &Raster, gt: &Raster, region: &[bool]) -> DepthMetrics {
    let (mut abs, mut sq, mut good, mut pixels, mut non_finite) = (0.0f64, 0.0f64, 0usize, 0usize, 0usize);
    for ((&z, &g), &inside) in est.data.iter().zip(&gt.data).zip(region) {
        let (z, g) = (z as f64, g as f64);
        if !inside || !g.is_finite() || g <= 0.0 {
            continue;
        }
        if !z.is_finite() {
            non_finite += 1;
            continue;
        }
        pixels += 1;
        abs += (z - g).abs();
        sq += (z - g) * (z - g);
        good += usize::from(z > 0.0 && (z / g).max(g / z) < 1.25);
    }
    let n = pixels as f64;
    let mean = |s: f64| if pixels == 0 { f64::NAN } else { s / n };
    DepthMetrics { abs_diff_m: mean(abs), rmse_m: mean(sq).sqrt(), delta_1_25: mean(good as f64), pixels, non_finite }
}

/// PSNR (dB) of `est` against `gt` over `region`, all channels; images of different channel
/// counts are compared in grey. Infinite for identical images.
pub fn psnr_db(est: &Raster, gt: &Raster, region: &[bool]) -> f64 {
    let (est, gt) = if est.channels == gt.channels { (est.clone(), gt.clone()) } else { (est.to_grey(), gt.to_grey()) };
    let ch = gt.channels;
    let (mut sq, mut n) = (0.0f64, 0usize);
    for i in (0..gt.pixels()).filter(|&i| region[i]) {
        for c in 0..ch {
            let e = (est.data[i * ch + c] - gt.data[i * ch + c]) as f64;
            sq += e * e;
            n += 1;
        }
    }
    if n == 0 {
        return f64::NAN;
    }
    10.0 * (1.0 / (sq / n as f64)).log10()
}

/// The error of one group of motion parameters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterError {
    /// Group name as in the motion file (`omega_rad_s`, `velocity_m_s`, ...).
    pub name: String,
    /// `|est - true|` (Euclidean norm over the group).
    pub absolute: f64,
    /// `|est - true| / |true|`; `None` when the truth is zero.
    pub relative: Option<f64>,
    /// `|true|`.
    pub true_norm: f64,
}

/// Parameter errors of an estimated motion against the truth; `None` when their models differ.
pub fn motion_parameter_errors(est: &MotionRecord, truth: &MotionRecord) -> Option<Vec<ParameterError>> {
    let (ge, gt) = (est.groups(), truth.groups());
    if est.model_name() != truth.model_name() || ge.iter().zip(&gt).any(|(a, b)| a.1.len() != b.1.len()) {
        return None;
    }
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    Some(
        ge.iter()
            .zip(&gt)
            .map(|((name, e), (_, t))| {
                let diff: Vec<f64> = e.iter().zip(t).map(|(a, b)| a - b).collect();
                let (absolute, true_norm) = (norm(&diff), norm(t));
                let relative = (true_norm > 0.0).then(|| absolute / true_norm);
                ParameterError { name: name.to_string(), absolute, relative, true_norm }
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(values: &[f32]) -> Raster {
        Raster::from_vec(values.len(), 1, 1, values.to_vec()).unwrap()
    }

    #[test]
    fn badpix_and_mse_count_what_they_should() {
        let gt = map(&[0.0, 0.0, 0.0, 0.0]);
        let est = map(&[0.0, 0.05, -0.5, f32::NAN]);
        let m = disparity_metrics(&est, &gt, &[true; 4]);
        assert_eq!(m.pixels, 4);
        assert_eq!(m.non_finite, 1);
        assert!((m.mse_x100 - 100.0 * (0.0025 + 0.25) / 3.0).abs() < 1e-6);
        assert_eq!(m.badpix_percent[0], (0.07, 50.0)); // -0.5 and NaN
        assert_eq!(m.badpix_percent[1], (0.03, 75.0)); // 0.05, -0.5, NaN
    }

    #[test]
    fn the_border_and_mask_shrink_the_region() {
        let mask: Vec<bool> = (0..100).map(|i| i % 2 == 0).collect();
        let region = evaluation_region(10, 10, Some(&mask), 2);
        assert_eq!(region.iter().filter(|&&r| r).count(), 18); // 6x6 interior, half masked
        assert!(!region[0] && !region[2 * 10 + 1] && region[2 * 10 + 2]);
    }

    #[test]
    fn depth_metrics_follow_the_paper() {
        let gt = map(&[1.0, 2.0, 4.0, 0.0]);
        let est = map(&[1.0, 2.5, 2.0, 9.0]);
        let m = depth_metrics(&est, &gt, &[true; 4]);
        assert_eq!(m.pixels, 3); // zero truth skipped
        assert!((m.abs_diff_m - 2.5 / 3.0).abs() < 1e-12);
        assert!((m.rmse_m - ((0.25 + 4.0) / 3.0f64).sqrt()).abs() < 1e-12);
        assert!((m.delta_1_25 - 1.0 / 3.0).abs() < 1e-12); // 2.5/2 = 1.25 is not < 1.25, 4/2 = 2 neither
    }

    #[test]
    fn psnr_of_a_known_error() {
        let gt = map(&[0.5; 4]);
        let est = map(&[0.6; 4]);
        assert!((psnr_db(&est, &gt, &[true; 4]) - 20.0).abs() < 1e-4);
        assert!(psnr_db(&gt, &gt, &[true; 4]).is_infinite());
    }

    #[test]
    fn motion_errors_are_per_group_and_relative_to_the_truth() {
        let truth = MotionRecord::ConstantVelocity { omega_rad_s: [0.0, 0.0, 0.0], velocity_m_s: [3.0, 0.0, 4.0] };
        let est = MotionRecord::ConstantVelocity { omega_rad_s: [0.1, 0.0, 0.0], velocity_m_s: [3.0, 0.0, 3.0] };
        let errs = motion_parameter_errors(&est, &truth).unwrap();
        assert_eq!(errs[0].relative, None);
        assert!((errs[0].absolute - 0.1).abs() < 1e-12);
        assert!((errs[1].relative.unwrap() - 0.2).abs() < 1e-12);
        let other = MotionRecord::PiecewiseConstant { omega_rad_s: vec![[0.0; 3]], velocity_m_s: vec![[0.0; 3]] };
        assert!(motion_parameter_errors(&other, &truth).is_none());
    }
}
