//! The RSLF composition: stage-1 initialisation (plane sweep, Gaussian sampling), stage-1 fit,
//! then stage 2 (motion) as it arrives, and the result.

mod gaussian_init;
mod plane_sweep;
mod results;
mod stage1_fit;

pub use gaussian_init::{frequency_map, sample_gaussians};
pub use plane_sweep::{DisparityEstimate, PlaneSweepSettings, plane_sweep};
pub use results::{RunResult, depth_map};
pub use stage1_fit::{LearningRates, Stage1Fit, fit_stage1, image_tensor};

use crate::config::Config;
use crate::geometry::ViewId;
use crate::io::{Raster, Scene};
use crate::model::Gaussians;
use crate::render::{RenderSettings, render_rows};
use burn::tensor::Device;
use std::time::Instant;

/// Opacity above which a rendered pixel's blended disparity is trusted over the initial map.
const TRUSTED_ALPHA: f32 = 0.5;

/// Which stages a run carried out, for the user and the logs.
#[derive(Debug, Clone, Default)]
pub struct RunLog {
    /// One line per stage: what ran, with its figures, or why it did not.
    pub lines: Vec<String>,
}

/// The plane-sweep settings a config gives for a scene: the config's range, else the scene's
/// `[meta]` range, else [-4, 4] pixels.
pub fn sweep_settings(config: &Config, scene: &Scene) -> PlaneSweepSettings {
    let range = config
        .stage1
        .disparity_range
        .map(|[lo, hi]| (lo, hi))
        .or_else(|| scene.params.as_ref().and_then(|p| p.disparity_range))
        .unwrap_or((-4.0, 4.0));
    PlaneSweepSettings { range, step: config.stage1.disparity_step, window_radius: 2 }
}

/// The renderer settings of a config.
pub fn render_settings(config: &Config) -> RenderSettings {
    RenderSettings { max_per_pixel: config.render.max_per_pixel, cutoff_sigma: config.render.cutoff_sigma as f32 }
}

/// The `count` central-row views the stage-1 fit uses: the central view and its nearest
/// neighbours on the row, alternating sides.
pub fn stage1_views(scene: &Scene, count: usize) -> Vec<ViewId> {
    let centre = scene.central_id();
    let mut row = scene.central_row_views();
    row.sort_by_key(|v| (v.col.abs_diff(centre.col), v.col));
    row.truncate(count);
    row.sort();
    row
}

/// Renders the central view of `g`: its colour, and its disparity where opaque enough
/// (elsewhere `fallback`'s).
pub fn render_central(g: &Gaussians, scene: &Scene, settings: &RenderSettings, fallback: &Raster, device: &Device) -> (Raster, Raster) {
    let (w, h, c) = (scene.width(), scene.height(), scene.channels());
    let out = render_rows(g, (0.0, 0.0), w, 0..h, settings, device);
    let data = |t: burn::tensor::TensorData| t.convert::<f32>().try_to_vec::<f32>().expect("float data");
    let colour = data(out.colour.into_data());
    let disparity = data(out.disparity.into_data());
    let alpha = data(out.alpha.into_data());
    let disparity = (0..w * h)
        .map(|i| if alpha[i] > TRUSTED_ALPHA { disparity[i] / alpha[i] } else { fallback.data[i] })
        .collect();
    (Raster { width: w, height: h, channels: c, data: colour }, Raster { width: w, height: h, channels: 1, data: disparity })
}

/// Runs the pipeline on `scene` with `config` on `device`.
pub fn run(config: &Config, scene: &Scene, device: &Device) -> (RunResult, RunLog) {
    let mut log = RunLog::default();
    let settings = sweep_settings(config, scene);
    let row_views = scene.central_row_views();
    let labels = ((settings.range.1 - settings.range.0) / settings.step).round() as u64 + 1;
    let bar = crate::progress::bar(labels, "stage 1: sweep");
    let start = Instant::now();
    let estimate = plane_sweep(scene, &row_views, &settings, |done, _| bar.set_position(done as u64));
    bar.finish_and_clear();
    log.lines.push(format!(
        "stage 1 initialisation: plane sweep over {} central-row views, disparity {:.2}..{:.2} px in {} steps, {:.1} s",
        row_views.len(),
        settings.range.0,
        settings.range.1,
        labels,
        start.elapsed().as_secs_f64()
    ));

    let start = Instant::now();
    let set = sample_gaussians(scene.central(), &estimate.disparity, config.stage1.gaussians, config.seed);
    let mut gaussians = set.to_module(device);
    log.lines.push(format!("stage 1 sampling: {} Gaussians, {:.1} s", set.len(), start.elapsed().as_secs_f64()));

    let render = render_settings(config);
    let views = stage1_views(scene, config.stage1.views);
    let mut curves = Vec::new();
    if config.stage1.iterations > 0 {
        let s = &config.stage1;
        let fit = Stage1Fit {
            iterations: s.iterations,
            band_height: s.band_height,
            adam_epsilon: s.adam_epsilon as f32,
            lr: LearningRates { position: s.lr_position, disparity: s.lr_disparity, size: s.lr_size, colour: s.lr_colour },
            render,
        };
        let bar = crate::progress::bar(s.iterations as u64, "stage 1: fit");
        let start = Instant::now();
        let (fitted, curve) = fit_stage1(gaussians, scene, &views, &fit, device, |done, _, loss| {
            bar.set_position(done as u64);
            bar.set_message(format!("stage 1: L1 {loss:.4}"));
        });
        bar.finish_and_clear();
        gaussians = fitted;
        log.lines.push(format!(
            "stage 1 fit: {} Adam steps over {}-row bands of {} central-row views, L1 {:.4} -> {:.4}, {:.1} s",
            s.iterations,
            s.band_height,
            views.len(),
            curve.first().copied().unwrap_or(f32::NAN),
            curve.last().copied().unwrap_or(f32::NAN),
            start.elapsed().as_secs_f64()
        ));
        curves.push(("stage1".to_string(), curve));
    }
    if scene.is_rolling_shutter() && config.stage2.iterations > 0 {
        log.lines.push("stage 2 (motion): not part of this version yet; no motion.toml written".into());
    }
    let (central, disparity) = render_central(&gaussians, scene, &render, &estimate.disparity, device);
    let result = RunResult { disparity, central, motion: None, gaussians: Some(gaussians.to_set()), curves };
    (result, log)
}
