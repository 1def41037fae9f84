//! The RSLF composition: stage 1 (initial disparity, Gaussian sampling, fit: `stage1.rs`), then
//! stage 2 (the motion: `stage2.rs`) where the scene allows it, and the result, with the settings
//! both draw from a config. The optimisation loops are `stage1_fit.rs` and `stage2_fit.rs`; the
//! cues stage 2 measures between the views and weighs are `measured_cues.rs`, `cue_support.rs`,
//! `axial_check.rs` and `cue_term.rs`.

mod aperture;
mod axial_check;
mod box_filter;
mod cue_support;
mod cue_term;
mod gaussian_init;
mod light_field;
mod measured_cues;
mod plane_sweep;
mod results;
mod run_log;
mod spline_image;
mod stage1;
mod stage1_fit;
mod stage2;
mod stage2_fit;
mod targets;
mod view_tracking;
mod visibility;

pub use aperture::aperture_weights;
pub use axial_check::{AxialJudgement, AxialSupport, axial_groups, axial_support, part_support};
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
pub use run_log::RunLog;
pub use spline_image::SplineImage;
pub use stage1_fit::{
    GaussianSchedules, LearningRates, Stage1Fit, decaying, fit_stage1, image_tensor, with_gaussian_groups, with_gaussian_schedules,
};
pub use stage2::{AXIAL_CHECK_LINE, CHECK_LINE, HELD_CHECK_LINE, REFIT_CHECK_LINE};
pub use stage2_fit::{HeldByCues, MotionFit, Stage2Context, Stage2Fit, fit_stage2, motion_scales, pose_table};
pub use view_tracking::{Track, TrackSettings, textured_points, track};
pub use visibility::{BORDER_CONTINUATION_PX, BorderStrips, explained_mask};

use crate::config::{Config, TimingChoice, ViewSelection};
use crate::device::host_values;
use crate::geometry::{Camera, TensorCamera, ViewId, readout_interval};
use crate::io::{MotionRecord, Raster, Scene};
use crate::loss::LossRegistry;
use crate::model::Gaussians;
use crate::model::motion::{MotionModel, MotionRegistry, MotionSetup};
use crate::render::{RenderSettings, RsTiming, Splats, StaticShape, splat_with_surface};
use burn::module::Module;
use burn::tensor::{Device, Tensor, TensorData};

/// Opacity above which a rendered pixel's disparity is trusted over the initial map.
const TRUSTED_ALPHA: f32 = 0.5;

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

/// The views stage 2 compares against: the four corners, the diagonals, or every present view
/// off the central row.
///
/// `Corners` takes, in each quadrant of the grid (off the central row and column), the present
/// view farthest from the central row, and of those the one farthest from the central column:
/// the corner itself when it is there (the paper's choice). A capture that lacks the corners
/// (a plenoptic camera's vignetted corner views are often dropped) gets the outermost views it
/// has; the vertical offset comes first because it alone sets the read-out delay the motion
/// shows in. `Diagonals` takes the present views as far from the central row as from the
/// central column. With none of the views either asks for (only the central row and column),
/// every view off the central row is taken.
pub fn stage2_views(scene: &Scene, selection: ViewSelection) -> Vec<ViewId> {
    let centre = scene.central_id();
    let off_row: Vec<ViewId> = scene.present_views().into_iter().filter(|v| v.row != centre.row).collect();
    let chosen: Vec<ViewId> = match selection {
        ViewSelection::AllOffRow => return off_row,
        ViewSelection::Diagonals => off_row.iter().copied().filter(|v| v.row.abs_diff(centre.row) == v.col.abs_diff(centre.col)).collect(),
        ViewSelection::Corners => [(false, false), (false, true), (true, false), (true, true)]
            .into_iter()
            .filter_map(|(below, right)| {
                off_row
                    .iter()
                    .filter(|v| v.col != centre.col && (v.row > centre.row) == below && (v.col > centre.col) == right)
                    .max_by_key(|v| (v.row.abs_diff(centre.row), v.col.abs_diff(centre.col)))
                    .copied()
            })
            .collect(),
    };
    if chosen.is_empty() { off_row } else { chosen }
}

/// The read-out timing a config asks for.
pub fn rs_timing(config: &Config) -> RsTiming {
    match config.stage2.timing {
        TimingChoice::Bands => RsTiming::Bands(config.stage2.band_height),
        TimingChoice::PerGaussian => RsTiming::PerGaussian(config.stage2.timing_iterations),
    }
}

/// Colour and surface disparity ([`splat_with_surface`]) of a whole-image render of `splats`; the
/// disparity is `fallback`'s where the render is not opaque enough.
fn central_rasters(
    splats: &Splats,
    w: usize,
    h: usize,
    c: usize,
    settings: &RenderSettings,
    fallback: &Raster,
    device: &Device,
) -> (Raster, Raster) {
    let bins = splats.bins(w, 0..h, settings);
    let (out, surface) = splat_with_surface(splats, &bins, device);
    let colour = colour_raster(out.colour, w, h, c);
    let surface = host_values(surface);
    let alpha = host_values(out.alpha);
    let disparity = (0..w * h).map(|i| if alpha[i] > TRUSTED_ALPHA { surface[i] } else { fallback.data[i] }).collect();
    (colour, Raster { width: w, height: h, channels: 1, data: disparity })
}

/// The `[P, C]` colour of a whole-view render as a `w x h` image with `c` channels.
fn colour_raster(colour: Tensor<2>, w: usize, h: usize, c: usize) -> Raster {
    Raster { width: w, height: h, channels: c, data: host_values(colour) }
}

/// Renders the central view of `g`: its colour, and its disparity where opaque enough
/// (elsewhere `fallback`'s). The Gaussians are held (no gradient), so that the whole view's
/// per-pixel tensors are freed as the render goes instead of kept for a backward pass.
pub fn render_central(g: &Gaussians, scene: &Scene, settings: &RenderSettings, fallback: &Raster, device: &Device) -> (Raster, Raster) {
    let (w, h, c) = (scene.width(), scene.height(), scene.channels());
    central_rasters(&Splats::of_view(&g.clone().no_grad(), (0.0, 0.0)), w, h, c, settings, fallback, device)
}

/// A parameter vector as a tensor.
fn params_tensor(params: &[f64], device: &Device) -> Tensor<1> {
    Tensor::from_data(TensorData::new(params.iter().map(|&x| x as f32).collect::<Vec<_>>(), [params.len()]), device)
}

/// The scene at t = 0 under a motion: the Gaussians moved back from their rows' times, held (no
/// gradient: what is rendered from it is an output, not a step of a fit).
pub fn static_shape(g: &Gaussians, camera: &Camera, model: &dyn MotionModel, params: &[f64], device: &Device) -> StaticShape {
    StaticShape::new(&g.clone().no_grad(), TensorCamera::new(camera), model, params_tensor(params, device))
}

/// Renders the central view at t = 0 of `shape`, the static shape under `model` at `params`
/// ([`static_shape`]): the rolling-shutter-compensated colour, and the disparity where opaque
/// enough (elsewhere `fallback`'s).
pub fn render_compensated_central(
    shape: &StaticShape,
    model: &dyn MotionModel,
    params: &[f64],
    scene: &Scene,
    settings: &RenderSettings,
    fallback: &Raster,
    device: &Device,
) -> (Raster, Raster) {
    let (w, h, c) = (scene.width(), scene.height(), scene.channels());
    let splats = shape.splats_at_time(model, params_tensor(params, device), (0.0, 0.0), 0.0);
    central_rasters(&splats, w, h, c, settings, fallback, device)
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
    let (gaussians, initial, mut curves) = stage1::run(config, scene, &stage1_losses, device, &mut log)?;
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
            let ctx = Stage2Context {
                scene,
                camera: cam,
                model: model.as_ref(),
                losses: &stage2_losses,
                device,
                central_disparity: stage1_disparity.as_ref(),
            };
            let fitted = stage2::run(config, &ctx, gaussians.clone(), &start, &initial, &mut log, &mut curves);
            let gaussians = fitted.gaussians.clone();
            let shape = static_shape(&gaussians, cam, model.as_ref(), &fitted.parameters, device);
            let (central, disparity) =
                render_compensated_central(&shape, model.as_ref(), &fitted.parameters, scene, &render, &initial, device);
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
