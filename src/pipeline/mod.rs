//! The RSLF composition: stage-1 initialisation (plane sweep, Gaussian sampling), stage-1 fit,
//! then stage 2 (motion) as it arrives, and the result.

mod aperture;
mod box_filter;
mod cue_support;
mod cue_term;
mod gaussian_init;
mod light_field;
mod measured_cues;
mod plane_sweep;
mod results;
mod spline_image;
mod stage1_fit;
mod stage2_fit;
mod targets;
mod view_tracking;
mod visibility;

pub use aperture::aperture_weights;
pub use cue_support::{CueSupport, cue_support};
pub use cue_term::{CueTerm, residual_weights};
pub use gaussian_init::{frequency_map, sample_gaussians};
pub use light_field::{Moment, motion_of_record, render_light_field};
pub use measured_cues::{
    Cue, LeverTally, MAX_LEVER_STEPS, MAX_RESIDUAL_OVER_MEDIAN, TrackedCues, drop_outlying_matches, measure_cues, median_two_way_residual,
    predicted_cue, tracked_cues,
};
pub use plane_sweep::{DisparityEstimate, PlaneSweepSettings, plane_sweep};
pub use results::{LossCurves, PointCloud, RunResult, depth_map};
pub use spline_image::SplineImage;
pub use stage1_fit::{LearningRates, Stage1Fit, fit_stage1, image_tensor, with_gaussian_groups};
pub use stage2_fit::{MotionFit, Stage2Fit, fit_stage2, motion_scales, pose_table};
pub use view_tracking::{Track, TrackSettings, textured_points, track};
pub use visibility::explained_mask;

use crate::config::{Config, TimingChoice, ViewSelection};
use crate::device::host_values;
use crate::geometry::{Camera, TensorCamera, ViewId, readout_interval};
use crate::io::{MotionRecord, Raster, Scene};
use crate::loss::{LossRegistry, WeightedLosses};
use crate::model::Gaussians;
use crate::model::motion::{MotionModel, MotionRegistry, MotionSetup};
use crate::optim::NewtonSettings;
use crate::render::{RenderOutput, RenderSettings, RsTiming, StaticShape, render_rows, row_bands, splat};
use burn::tensor::{Device, Tensor, TensorData};
use std::time::Instant;

/// Residual (px) beyond which a measured cue counts linearly in the cue term.
const CUE_HUBER_PX: f32 = 0.1;

/// Finite-difference step (scaled units: about a pixel of image motion each) of the stage-2
/// Newton steps' Hessian, and their longest step.
const NEWTON_FD_STEP: f64 = 0.05;
const NEWTON_MAX_STEP: f64 = 2.0;
/// The stage-2 Newton steps hold the directions whose curvature is under this share of the
/// steepest's. On the 256 px suite the two flattest (about 1/300 of the steepest, mostly the
/// motion prior's own curvature: tilt against vertical translation, pan against sideways
/// translation) carried the steps that made the slow scenes worse, while the roll and v_z
/// directions (1/80 and more) carried the gains (docs/results.md).
const NEWTON_MIN_CURVATURE_RATIO: f64 = 5e-3;

/// Opacity above which a rendered pixel's blended disparity is trusted over the initial map.
const TRUSTED_ALPHA: f32 = 0.5;

/// Which stages a run carried out, for the user and the logs.
#[derive(Debug, Clone, Default)]
pub struct RunLog {
    /// One line per stage: what ran, with its figures, or why it did not.
    pub lines: Vec<String>,
    /// Whether each line is also printed to standard output as it is added.
    echo: bool,
}

impl RunLog {
    /// A log that prints each line as it comes, so that a long run shows where it is even with
    /// its output going to a file (the progress bars draw only on a terminal).
    pub fn printing() -> Self {
        Self { lines: Vec::new(), echo: true }
    }

    /// Adds a line (and prints it, for a [`RunLog::printing`] log).
    pub fn push(&mut self, line: impl Into<String>) {
        let line = line.into();
        if self.echo {
            outln!("{line}");
        }
        self.lines.push(line);
    }
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

/// The views the stage-1 fit uses: `row` views of the central row (the central view and its
/// nearest neighbours on the row, alternating sides), then `column` views of the central column
/// (nearest the central view first, alternating sides; the central view is not counted again).
pub fn stage1_views(scene: &Scene, row: usize, column: usize) -> Vec<ViewId> {
    let centre = scene.central_id();
    let mut on_row = scene.central_row_views();
    on_row.sort_by_key(|v| (v.col.abs_diff(centre.col), v.col));
    on_row.truncate(row);
    on_row.sort();
    let mut on_column: Vec<ViewId> = scene.present_views().into_iter().filter(|v| v.col == centre.col && v.row != centre.row).collect();
    on_column.sort_by_key(|v| (v.row.abs_diff(centre.row), v.row));
    on_column.truncate(column);
    on_column.sort();
    on_row.extend(on_column);
    on_row
}

/// How many central-column views stage 1 (sweep and fit) and the joint refinement use on
/// `scene`: the config's count, else the default for the scene's shutter.
fn column_views(config: &Config, scene: &Scene) -> usize {
    config.stage1.column_views_for(scene.is_rolling_shutter())
}

/// The registries a run draws its loss terms and motion models from. The defaults hold the
/// built-in ones; add to them to run a config that names terms or models of your own.
#[derive(Clone, Default)]
pub struct Registries {
    /// Loss terms by name.
    pub losses: LossRegistry,
    /// Motion models by name.
    pub motions: MotionRegistry,
}

impl Registries {
    /// Checks that every loss term and the motion model a config names exist and accept their
    /// settings, so that a run fails at once rather than after stage 1.
    pub fn check(&self, config: &Config) -> Result<(), String> {
        self.losses.build(&config.loss).map_err(|e| e.to_string())?;
        self.motions.build(&config.motion, &MotionSetup { readout: (-1.0, 1.0) }).map_err(|e| e.to_string())?;
        Ok(())
    }
}

/// The views stage 2 compares against: the four corners or every present view off the
/// central row.
///
/// `Corners` takes, in each quadrant of the grid (off the central row and column), the present
/// view farthest from the central row, and of those the one farthest from the central column:
/// the corner itself when it is there (the paper's choice). A capture that lacks the corners
/// (a plenoptic camera's vignetted corner views are often dropped) gets the outermost views it
/// has; the vertical offset comes first because it alone sets the read-out delay the motion
/// shows in. With no view in any quadrant (only the central row and column), every view off
/// the central row is taken.
pub fn stage2_views(scene: &Scene, selection: ViewSelection) -> Vec<ViewId> {
    let centre = scene.central_id();
    let off_row: Vec<ViewId> = scene.present_views().into_iter().filter(|v| v.row != centre.row).collect();
    if selection == ViewSelection::AllOffRow {
        return off_row;
    }
    let corners: Vec<ViewId> = [(false, false), (false, true), (true, false), (true, true)]
        .into_iter()
        .filter_map(|(below, right)| {
            off_row
                .iter()
                .filter(|v| v.col != centre.col && (v.row > centre.row) == below && (v.col > centre.col) == right)
                .max_by_key(|v| (v.row.abs_diff(centre.row), v.col.abs_diff(centre.col)))
                .copied()
        })
        .collect();
    if corners.is_empty() { off_row } else { corners }
}

/// The read-out timing a config asks for.
pub fn rs_timing(config: &Config) -> RsTiming {
    match config.stage2.timing {
        TimingChoice::Bands => RsTiming::Bands(config.stage2.band_height),
        TimingChoice::PerGaussian => RsTiming::PerGaussian(config.stage2.timing_iterations),
    }
}

/// Colour and opacity-normalised disparity of a whole-image render; the disparity is
/// `fallback`'s where the render is not opaque enough.
fn central_rasters(out: RenderOutput, w: usize, h: usize, c: usize, fallback: &Raster) -> (Raster, Raster) {
    let colour = colour_raster(out.colour, w, h, c);
    let disparity = host_values(out.disparity);
    let alpha = host_values(out.alpha);
    let disparity = (0..w * h).map(|i| if alpha[i] > TRUSTED_ALPHA { disparity[i] / alpha[i] } else { fallback.data[i] }).collect();
    (colour, Raster { width: w, height: h, channels: 1, data: disparity })
}

/// The `[P, C]` colour of a whole-view render as a `w x h` image with `c` channels.
fn colour_raster(colour: Tensor<2>, w: usize, h: usize, c: usize) -> Raster {
    Raster { width: w, height: h, channels: c, data: host_values(colour) }
}

/// Renders the central view of `g`: its colour, and its disparity where opaque enough
/// (elsewhere `fallback`'s).
pub fn render_central(g: &Gaussians, scene: &Scene, settings: &RenderSettings, fallback: &Raster, device: &Device) -> (Raster, Raster) {
    let (w, h, c) = (scene.width(), scene.height(), scene.channels());
    central_rasters(render_rows(g, (0.0, 0.0), w, 0..h, settings, device), w, h, c, fallback)
}

/// A parameter vector as a tensor.
fn params_tensor(params: &[f64], device: &Device) -> Tensor<1> {
    Tensor::from_data(TensorData::new(params.iter().map(|&x| x as f32).collect::<Vec<_>>(), [params.len()]), device)
}

/// The scene at t = 0 under a motion: the Gaussians moved back from their rows' times.
pub fn static_shape(g: &Gaussians, camera: &Camera, model: &dyn MotionModel, params: &[f64], device: &Device) -> StaticShape {
    StaticShape::new(g, TensorCamera::new(camera), model, params_tensor(params, device))
}

/// Renders the central view at t = 0 of the static shape of `g` under `model` at `params`:
/// the rolling-shutter-compensated colour and disparity.
#[allow(clippy::too_many_arguments)]
pub fn render_compensated_central(
    g: &Gaussians,
    scene: &Scene,
    camera: &Camera,
    model: &dyn MotionModel,
    params: &[f64],
    settings: &RenderSettings,
    fallback: &Raster,
    device: &Device,
) -> (Raster, Raster, StaticShape) {
    let (w, h, c) = (scene.width(), scene.height(), scene.channels());
    let shape = static_shape(g, camera, model, params, device);
    let splats = shape.splats_at_time(model, params_tensor(params, device), (0.0, 0.0), 0.0);
    let out = splat(&splats, &splats.bins(w, 0..h, settings), device);
    let (colour, disparity) = central_rasters(out, w, h, c, fallback);
    (colour, disparity, shape)
}

/// Runs the pipeline on `scene` with `config` on `device`, with the built-in loss terms and
/// motion models.
pub fn run(config: &Config, scene: &Scene, device: &Device) -> crate::Result<(RunResult, RunLog)> {
    run_with(config, scene, device, &Registries::default())
}

/// Runs the pipeline with loss terms and motion models drawn from `registries`.
pub fn run_with(config: &Config, scene: &Scene, device: &Device, registries: &Registries) -> crate::Result<(RunResult, RunLog)> {
    run_logged(config, scene, device, registries, RunLog::default())
}

/// [`run_with`], its lines added to `log` as the stages end ([`RunLog::printing`] shows them as
/// they come).
pub fn run_logged(
    config: &Config,
    scene: &Scene,
    device: &Device,
    registries: &Registries,
    mut log: RunLog,
) -> crate::Result<(RunResult, RunLog)> {
    let usage = |e: &dyn std::fmt::Display| crate::Error::Usage(format!("config: {e}"));
    let losses = |stage| registries.losses.build(&config.losses_in(stage)).map_err(|e| usage(&e));
    let (stage1_losses, stage2_losses) = (losses(1)?.without_motion_terms(), losses(2)?);
    let camera = scene.camera();
    let motion_model = match &camera {
        Some(cam) => {
            let setup = MotionSetup { readout: readout_interval(cam.height, cam.line_time_s) };
            Some(registries.motions.build(&config.motion, &setup).map_err(|e| usage(&e))?)
        }
        None => None,
    };
    let (gaussians, initial, mut curves) = stage1(config, scene, &stage1_losses, device, &mut log)?;
    let render = render_settings(config);

    let initial_motion = match &config.stage2.initial_motion {
        Some(path) => Some(MotionRecord::read(path)?),
        None => None,
    };
    // The motion shows only in views off the central row: without one it cannot be estimated,
    // and a given `initial_motion` is used as it is.
    let observable = !stage2_views(scene, ViewSelection::AllOffRow).is_empty();
    let unobserved;
    let config = if observable || config.stage2.iterations == 0 {
        config
    } else {
        unobserved = Config { stage2: crate::config::Stage2Config { iterations: 0, ..config.stage2.clone() }, ..config.clone() };
        &unobserved
    };
    let stage2_ready = scene.is_rolling_shutter() && (config.stage2.iterations > 0 || initial_motion.is_some());
    let (central, disparity, motion, points, gaussians) = match (stage2_ready, &camera, &motion_model) {
        (true, Some(cam), Some(model)) => {
            let start = match &initial_motion {
                Some(record) => model.parameters_of(record).ok_or_else(|| {
                    crate::Error::Usage(format!(
                        "config: stage2.initial_motion is a `{}` motion, which the `{}` model cannot express",
                        record.model_name(),
                        model.name()
                    ))
                })?,
                None => vec![0.0; model.parameters().len()],
            };
            if !observable {
                log.push("stage 2 (motion): the scene has no view off the central row to fit a motion to; stage2.initial_motion is used as given");
            }
            // The stage-1 geometry the disocclusion masks come from, rendered only when they are asked for.
            let stage1_disparity = config.stage2.mask_disocclusions.then(|| render_central(&gaussians, scene, &render, &initial, device).1);
            let fitted = stage2(
                config,
                scene,
                cam,
                model.as_ref(),
                gaussians.clone(),
                &start,
                &stage2_losses,
                device,
                stage1_disparity.as_ref(),
                &initial,
                &mut log,
                &mut curves,
            );
            let gaussians = fitted.gaussians.clone();
            let (central, disparity, shape) =
                render_compensated_central(&gaussians, scene, cam, model.as_ref(), &fitted.parameters, &render, &initial, device);
            (central, disparity, Some(model.record(&fitted.parameters)), Some(PointCloud::of_shape(&shape)), gaussians)
        }
        _ => {
            if scene.is_rolling_shutter() && !observable {
                log.push(
                    "stage 2 (motion): skipped, the scene has no view off the central row, whose views are read in step and so show no motion; the result is not compensated",
                );
            } else if scene.is_rolling_shutter() {
                log.push("stage 2 (motion): skipped, stage2.iterations = 0; the result is not compensated");
            } else if camera.is_none() {
                log.push("stage 2 (motion): skipped, no parameters.cfg (no camera, so no motion or depth)");
            } else {
                log.push("stage 2 (motion): skipped, global-shutter scene (no [rolling_shutter] in parameters.cfg)");
            }
            let (central, disparity) = render_central(&gaussians, scene, &render, &initial, device);
            // With no motion the Gaussians are already the scene at t = 0.
            let points = match (&camera, &motion_model) {
                (Some(cam), Some(model)) => {
                    let zero = vec![0.0; model.parameters().len()];
                    Some(PointCloud::of_shape(&static_shape(&gaussians, cam, model.as_ref(), &zero, device)))
                }
                _ => None,
            };
            // FORMAT: no motion.toml for a global-shutter scene, nor when none was estimated.
            (central, disparity, None, points, gaussians)
        }
    };
    let result = RunResult { disparity, central, motion, gaussians: Some(gaussians.to_set()), points, curves };
    Ok((result, log))
}

/// Stage 1: plane sweep, sampling and fit. Returns the Gaussians, the initial disparity map
/// (the fallback where the render is transparent) and the loss curve.
fn stage1(
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
            "stage 1 fit: {} Adam steps over {}-row bands of {} central-row and {} central-column views, loss ({}) {:.4} -> {:.4} over the first and the last round of bands, {:.1} s",
            s.iterations,
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

/// Stage 2: the motion, fitted against the off-row views and checked against the cues measured
/// between them. With the check on, the measured-cue term (`cue_weight`) joins only after it:
/// the photometric fit alone is judged (a fit to the cues would pass any check against them). A
/// motion the cues confirm is fitted again from the start, with the term; one they do not
/// confirm is set to none (a still camera unless the cues show otherwise). The loss curves go to
/// `curves`: `stage2`, then `stage2_cues` when the second fit runs.
#[allow(clippy::too_many_arguments)]
fn stage2(
    config: &Config,
    scene: &Scene,
    camera: &Camera,
    model: &dyn MotionModel,
    gaussians: Gaussians,
    start_values: &[f64],
    losses: &WeightedLosses,
    device: &Device,
    stage1_disparity: Option<&Raster>,
    initial_disparity: &Raster,
    log: &mut RunLog,
    curves: &mut LossCurves,
) -> MotionFit {
    let s = &config.stage2;
    // The cue check judges a fitted motion; a motion given with no iterations is used as it is.
    let check = s.min_cue_support > 0.0 && s.iterations > 0;
    let cues = (s.cue_weight > 0.0 || check).then(|| {
        let start = Instant::now();
        let cue_views = stage2_views(scene, s.cue_views);
        let TrackedCues { mut cues, base_lever, large_lever } =
            tracked_cues(scene, initial_disparity, &cue_views, s.cue_edges, s.cue_lever_bound);
        let tracked = cues.len();
        let bound = drop_outlying_matches(&mut cues, s.cue_outlier_bound);
        let measured_in: std::collections::BTreeSet<ViewId> = cues.iter().map(|c| c.view).collect();
        log.push(format!(
            "stage 2 cues: {} measured in {} views off the central row and column ({:?}), {} of them across an edge or a stripe only, textured patches of the central-row view of each one's column tracked into the farthest view of the central row and into it, {:.1} s",
            cues.len(),
            measured_in.len(),
            s.cue_views,
            cues.iter().filter(|c| c.across.is_some()).count(),
            start.elapsed().as_secs_f64()
        ));
        if let Some(bound) = bound {
            log.push(format!(
                "stage 2 cues left out: {} of {tracked} tracked, patches textured both ways whose matches leave over {bound:.3} of their contrast unexplained ({} times the median)",
                tracked - cues.len(),
                s.cue_outlier_bound
            ));
        }
        if s.cue_lever_bound > 0.0 {
            log.push(format!(
                "stage 2 cues not tracked: {} of {} base and {} of {} larger patches textured both ways pin their two displacements over {} x the tracking grid's step apart",
                base_lever.left_out, base_lever.judged, large_lever.left_out, large_lever.judged, s.cue_lever_bound
            ));
        }
        cues
    });
    // The term is built where a fit uses it: a motion the check sets to none needs none.
    let cue_term = || {
        cues.as_ref()
            .filter(|_| s.cue_weight > 0.0)
            .map(|cues| CueTerm::new(cues, camera, s.cue_weight as f32, CUE_HUBER_PX, s.timing_iterations, s.cue_residual_weights, device))
    };
    let mut views = stage2_views(scene, s.views);
    if s.views == ViewSelection::Corners && views != scene.grid.corners() {
        let names: Vec<String> = views.iter().map(|&v| scene.grid.index(v).to_string()).collect();
        log.push(format!(
            "stage 2 views: the grid's four corners are not all present; views {} stand in for them (each quadrant's outermost)",
            names.join(", ")
        ));
    }
    let refine = (s.refine_gaussians > 0.0).then(|| {
        let (k, s1) = (s.refine_gaussians, &config.stage1);
        views.extend(stage1_views(scene, s1.views, column_views(config, scene)));
        let lr =
            LearningRates { position: k * s1.lr_position, disparity: k * s1.lr_disparity, size: k * s1.lr_size, colour: k * s1.lr_colour };
        (lr, s1.adam_epsilon as f32)
    });
    let fit = Stage2Fit {
        iterations: s.iterations,
        timing: rs_timing(config),
        band_height: s.band_height,
        bands_per_step: s.bands_per_step,
        lr: s.lr,
        lr_final: s.lr_final,
        adam_epsilon: s.adam_epsilon as f32,
        seed: config.seed,
        render: render_settings(config),
        refine,
        disocclusion_margin: s.mask_disocclusions.then_some(s.disocclusion_margin),
        aperture_weighting: s.aperture_weighting,
        // No Adam steps, no estimation: a given `initial_motion` is used as it is.
        newton: NewtonSettings {
            iterations: if s.iterations > 0 { s.newton_iterations } else { 0 },
            fd_step: NEWTON_FD_STEP,
            max_step: NEWTON_MAX_STEP,
            min_curvature_ratio: NEWTON_MIN_CURVATURE_RATIO,
        },
    };
    // One phase of the fit, with its progress bar and its line in the log. The Newton steps go to
    // the last (`last`), whose motion is kept: the second when the check may confirm the motion
    // for one, so the check judges the same fit with or without them.
    let phase = |what: &str, g: Gaussians, cue_term: Option<&CueTerm>, last: bool, log: &mut RunLog| {
        let bar = crate::progress::bar(s.iterations as u64, &format!("stage 2: {what}"));
        let start = Instant::now();
        let fit = if last { fit.clone() } else { Stage2Fit { newton: NewtonSettings { iterations: 0, ..fit.newton }, ..fit.clone() } };
        let fitted = fit_stage2(
            g,
            scene,
            camera,
            &views,
            model,
            start_values,
            &fit,
            losses,
            device,
            stage1_disparity,
            cue_term,
            |done, of, loss| {
                bar.set_position(done.min(of) as u64);
                bar.set_message(match done.checked_sub(of).filter(|&k| k > 0) {
                    None => format!("stage 2 ({what}): loss {loss:.4}"),
                    Some(k) => format!("stage 2 ({what}): Newton steps, objective {loss:.5} ({k} evaluations)"),
                });
            },
        );
        bar.finish_and_clear();
        // Each step scores `bands_per_step` bands drawn across the image.
        let bands = row_bands(0..scene.height(), s.band_height).len();
        let stage2_ends = curve_ends(&fitted.curve, bands.div_ceil(s.bands_per_step.clamp(1, bands.max(1))));
        log.push(format!(
            "stage 2 {what}: `{}` motion, {} Adam steps, {} bands of {} rows in each of {} views per step ({:?} timing), {}{}{}, loss ({}) {:.4} -> {:.4} over the first and the last round of bands{}, {:.1} s; estimate {}",
            model.name(),
            s.iterations,
            s.bands_per_step,
            s.band_height,
            views.len(),
            s.timing,
            if fit.disocclusion_margin.is_some() {
                format!("{:.1}% of the pixels compared (disocclusions masked)", 100.0 * fitted.kept)
            } else {
                "every pixel compared".to_string()
            },
            if fit.aperture_weighting { ", off-row pixels weighted by their horizontal gradient share" } else { "" },
            cue_term.map_or(String::new(), |c| format!(", measured-cue term ×{} over {} cues", c.weight, c.len)),
            losses.names().join(" + "),
            stage2_ends.0,
            stage2_ends.1,
            fitted.newton.map_or(String::new(), |r| format!(
                ", then {} of {} Newton steps taken over every band{}, {:.5} -> {:.5} ({} evaluations)",
                r.taken,
                s.newton_iterations,
                if cue_term.is_some() { " (their objective leaves the motion prior out)" } else { "" },
                r.start,
                r.end,
                r.evaluations
            )),
            start.elapsed().as_secs_f64(),
            estimate_line(model, &fitted.parameters)
        ));
        fitted
    };
    let checked_cues = cues.as_ref().filter(|_| check);
    let first_cue_term = if checked_cues.is_some() { None } else { cue_term() };
    let second_fit = checked_cues.is_some() && s.cue_weight > 0.0;
    let mut fitted = phase("fit", gaussians.clone(), first_cue_term.as_ref(), !second_fit, log);
    curves.push(("stage2".to_string(), fitted.curve.clone()));
    let Some(checked) = checked_cues else { return fitted };
    // The check judges with the patches textured both ways alone: the cues of edges and stripes
    // carry biases of a few percent, enough to bear out a still scene's drift
    // (`objects_static`: 0.55 ± 0.01 with them, -0.01 ± 0.02 without; docs/results.md).
    let two_way: Vec<Cue> = checked.iter().copied().filter(|c| c.across.is_none()).collect();
    let confirmed = check_motion(&mut fitted, model, camera, &two_way, s.min_cue_support, log);
    if let Some(term) = confirmed.then(cue_term).flatten() {
        // Only a motion the cues clearly show: fitted to the cues, a still scene's drift does not
        // shrink (the 256 px suite's still scenes end 0.22-0.81 px off; docs/results.md). From the
        // start again, not from the photometric estimate: started there, the fit stays near it
        // (objects_accel, constant_acceleration: 1.22 px against 0.51 px).
        fitted = phase("fit with the measured cues", gaussians, Some(&term), true, log);
        curves.push(("stage2_cues".to_string(), fitted.curve.clone()));
    }
    fitted
}

/// A motion's parameters as `motion.toml` names them, five significant digits each, for the log:
/// `omega_rad_s [6.2191e-2, 0, 0], velocity_m_s [0, -2.4877e-1, 0]`.
fn estimate_line(model: &dyn MotionModel, parameters: &[f64]) -> String {
    let number = |x: f64| if x == 0.0 { "0".to_string() } else { format!("{x:.4e}") };
    model
        .record(parameters)
        .groups()
        .into_iter()
        .map(|(name, values)| format!("{name} [{}]", values.into_iter().map(number).collect::<Vec<_>>().join(", ")))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Keeps the fitted motion only when the cues measured between the views confirm it at
/// `min_support` ([`CueSupport::confirms`]), else sets it to none, and says in the log what they
/// show either way. A motion they neither refute nor confirm goes too: on the 128 px suite only
/// still scenes came out so (docs/results.md). Returns whether they confirm it; with too few cues
/// to judge, the motion is kept as fitted and `false` returned.
fn check_motion(
    fitted: &mut MotionFit,
    model: &dyn MotionModel,
    camera: &Camera,
    cues: &[Cue],
    min_support: f64,
    log: &mut RunLog,
) -> bool {
    let Some(support) = cue_support(camera, &model.record(&fitted.parameters), cues) else {
        log.push(format!("stage 2 check: not made ({} measured cues; at least 100 imaged and a motion are needed)", cues.len()));
        return false;
    };
    let shown = format!(
        "the {} measured cues of patches textured both ways bear out {:.2} (± {:.2}) of the motion's predicted ones",
        support.cues, support.share, support.standard_error
    );
    if support.confirms(min_support) {
        log.push(format!("stage 2 check: {shown}, clearly over {min_support}: kept"));
        return true;
    }
    fitted.parameters.iter_mut().for_each(|p| *p = 0.0);
    let verdict = if support.refutes(min_support) { "clearly under" } else { "not clearly over" };
    log.push(format!("stage 2 check: {shown}, {verdict} {min_support}: taken for a drift of the fit, no motion kept"));
    false
}

/// The mean loss of a fit's first and last `round` steps (NaN for an empty curve). Each step
/// scores some bands of rows only, so one step's loss against another's compares different
/// rows: a stage-1 fit at 512 px read 0.044 -> 0.050 (its top band against its fourth) while
/// every band's loss fell 2-3x, the round's mean 0.093 -> 0.040. A round of steps covers the
/// image.
fn curve_ends(curve: &[f32], round: usize) -> (f32, f32) {
    let n = round.max(1).min(curve.len());
    let mean = |steps: &[f32]| if steps.is_empty() { f32::NAN } else { steps.iter().sum::<f32>() / steps.len() as f32 };
    (mean(&curve[..n]), mean(&curve[curve.len() - n..]))
}

/// The plane sweep over the central row (and the stage-1 views of the central column): the
/// initial disparity map.
fn sweep(config: &Config, scene: &Scene, log: &mut RunLog) -> Raster {
    let settings = sweep_settings(config, scene);
    let row_views = scene.central_row_views();
    let column = stage1_views(scene, 0, column_views(config, scene));
    let views: Vec<ViewId> = row_views.iter().chain(&column).copied().collect();
    let labels = ((settings.range.1 - settings.range.0) / settings.step).round() as u64 + 1;
    let bar = crate::progress::bar(labels, "stage 1: sweep");
    let start = Instant::now();
    let estimate = plane_sweep(scene, &views, &settings, |done, _| bar.set_position(done as u64));
    bar.finish_and_clear();
    log.push(format!(
        "stage 1 initialisation: plane sweep over {} central-row and {} central-column views, disparity {:.2}..{:.2} px in {} steps, {:.1} s",
        row_views.len(),
        column.len(),
        settings.range.0,
        settings.range.1,
        labels,
        start.elapsed().as_secs_f64()
    ));

    estimate.disparity
}

#[cfg(test)]
mod tests {
    use super::{curve_ends, row_bands};

    #[test]
    fn a_round_of_bands_compares_the_whole_image_at_both_ends() {
        // Four bands taken in turn, each loss falling by half over three rounds, the last band
        // the hardest: its last step reads higher than the first band's first step.
        let per_band = [0.1_f32, 0.2, 0.3, 0.8];
        let curve: Vec<f32> = (0..12).map(|step| per_band[step % 4] * 0.5_f32.powi((step / 4) as i32)).collect();
        assert!(curve[11] > curve[0]);
        let (first, last) = curve_ends(&curve, row_bands(0..64, 16).len());
        assert!((first - 0.35).abs() < 1e-6 && (last - 0.0875).abs() < 1e-6, "{first} -> {last}");
        // A curve shorter than a round is compared with itself; an empty one gives NaN.
        let (a, b) = curve_ends(&curve[..3], 4);
        assert!(a == b && (a - 0.2).abs() < 1e-6, "{a} -> {b}");
        assert!(curve_ends(&[], 4).0.is_nan());
        assert_eq!(row_bands(0..100, 16).len(), 7);
        assert_eq!(row_bands(0..100, 0).len(), 100);
    }
}
