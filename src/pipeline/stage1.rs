//! Stage 1 as a run carries it out: the initial disparity map (a plane sweep over the central
//! row, or a map given in the config), the Gaussians sampled on the central view, and their fit
//! ([`super::fit_stage1`]), each with its line in the run's log.

use super::run_log::{RunLog, curve_ends};
use super::{
    LearningRates, LossCurves, Stage1Fit, column_views, fit_stage1, plane_sweep, render_settings, sample_gaussians, stage1_views,
    sweep_settings,
};
use crate::config::Config;
use crate::geometry::ViewId;
use crate::io::{Raster, Scene};
use crate::loss::WeightedLosses;
use crate::model::Gaussians;
use crate::render::row_bands;
use burn::tensor::Device;
use std::time::Instant;

/// Stage 1: plane sweep, sampling and fit. Returns the Gaussians, the initial disparity map
/// (the fallback where the render is transparent) and the loss curve.
pub(super) fn run(
    config: &Config,
    scene: &Scene,
    losses: &WeightedLosses,
    device: &Device,
    log: &mut RunLog,
) -> crate::Result<(Gaussians, Raster, LossCurves)> {
    let initial = match &config.stage1.initial_disparity {
        Some(path) => {
            let map = crate::io::read_pfm(path)?;
            if (map.width, map.height) != (scene.width(), scene.height()) {
                return Err(crate::Error::Usage(format!(
                    "config: stage1.initial_disparity {} is {}x{}, the views are {}x{}",
                    path.display(),
                    map.width,
                    map.height,
                    scene.width(),
                    scene.height()
                )));
            }
            log.push(format!("stage 1 initialisation: disparity from {}", path.display()));
            map
        }
        None => sweep(config, scene, log),
    };
    let start = Instant::now();
    let set = sample_gaussians(scene.central(), &initial, config.stage1.gaussians, config.seed);
    let mut gaussians = set.to_module(device);
    log.push(format!("stage 1 sampling: {} Gaussians, {:.1} s", set.len(), start.elapsed().as_secs_f64()));

    let views = stage1_views(scene, config.stage1.views, column_views(config, scene));
    let mut curves = Vec::new();
    if config.stage1.iterations > 0 {
        let s = &config.stage1;
        let fit = Stage1Fit {
            iterations: s.iterations,
            band_height: s.band_height,
            adam_epsilon: s.adam_epsilon as f32,
            lr: LearningRates { position: s.lr_position, disparity: s.lr_disparity, size: s.lr_size, colour: s.lr_colour },
            disparity_final_share: s.lr_disparity_final_share,
            render: render_settings(config),
        };
        let bar = crate::progress::bar(s.iterations as u64, "stage 1: fit");
        let start = Instant::now();
        let (fitted, curve) = fit_stage1(gaussians, scene, &views, &fit, losses, device, |done, _, loss| {
            bar.set_position(done as u64);
            bar.set_message(format!("stage 1: loss {loss:.4}"));
        });
        bar.finish_and_clear();
        gaussians = fitted;
        // Bands are taken in turn, one a step: a round of them is one pass over the views.
        let ends = curve_ends(&curve, row_bands(0..scene.height(), s.band_height).len());
        log.push(format!(
            "stage 1 fit: {} Adam steps{} over {}-row bands of {} central-row and {} central-column views, loss ({}) {:.4} -> {:.4} over the first and the last round of bands, {:.1} s",
            s.iterations,
            if s.lr_disparity_final_share < 1.0 { format!(" (the disparities' rate decaying to {} of itself)", s.lr_disparity_final_share) } else { String::new() },
            s.band_height,
            views.iter().filter(|v| v.row == scene.central_id().row).count(),
            views.iter().filter(|v| v.row != scene.central_id().row).count(),
            losses.names().join(" + "),
            ends.0,
            ends.1,
            start.elapsed().as_secs_f64()
        ));
        curves.push(("stage1".to_string(), curve));
    }
    Ok((gaussians, initial, curves))
}

/// The plane sweep over the central row (and the stage-1 views of the central column): the
/// initial disparity map.
pub(super) fn sweep(config: &Config, scene: &Scene, log: &mut RunLog) -> Raster {
    let settings = sweep_settings(config, scene);
    let row_views = scene.central_row_views();
    let column = stage1_views(scene, 0, column_views(config, scene));
    let views: Vec<ViewId> = row_views.iter().chain(&column).copied().collect();
    let labels = ((settings.range.1 - settings.range.0) / settings.step).round() as u64 + 1;
    let bar = crate::progress::bar(labels, "stage 1: sweep");
    let start = Instant::now();
    let estimate = plane_sweep(scene, &views, &settings, |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64)
    });
    bar.finish_and_clear();
    let pixels = estimate.disparity.width * estimate.disparity.height;
    log.push(format!(
        "stage 1 initialisation: plane sweep over {} central-row and {} central-column views, disparity {:.2}..{:.2} px in {} steps, {:.1} s; {:.1} % of the pixels filled from their neighbours (a flat or flat-bottomed cost)",
        row_views.len(),
        column.len(),
        settings.range.0,
        settings.range.1,
        labels,
        start.elapsed().as_secs_f64(),
        100.0 * estimate.untrusted as f64 / pixels.max(1) as f64
    ));

    estimate.disparity
}
