//! Stage-2 fit: the motion parameters, by Adam, against views off the central row. Each step
//! lifts the Gaussians, moves them back to t = 0 under the current motion, re-images them with
//! rolling shutter into each view and compares a stratified sample of row bands.

use super::aperture::aperture_weights;
use super::cue_term::CueTerm;
use super::stage1_fit::{LearningRates, with_gaussian_groups};
use super::targets::{ViewTarget, band_tensor, view_targets};
use super::visibility::{BorderStrips, explained_mask_moving, masked};
use crate::device::host_values;
use crate::geometry::{Camera, TensorCamera, ViewId};
use crate::io::{MotionRecord, Raster, Scene};
use crate::loss::{LossInput, MotionInput, WeightedLosses};
use crate::model::Gaussians;
use crate::model::motion::{MotionModel, MotionParams, ScaleContext, Tabulated, parameter_scales};
use crate::optim::{
    GroupPlan, MeanLoss, NewtonReport, NewtonSettings, Plan, Schedule, Stage, StepReport, gradients_of, held_directions, mean_over_parts,
    newton_minimise, newton_within, optimise_by_gradients, weighted_sum,
};
use crate::random::Rng;
use crate::render::{RenderSettings, RsTiming, Splats, StaticShape, bands, splat};
use burn::module::Module;
use burn::tensor::{Device, Tensor, TensorData};
use rayon::prelude::*;

/// Settings of the stage-2 fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Stage2Fit {
    /// Adam steps.
    pub iterations: usize,
    /// Read-out timing of the rendered views.
    pub timing: RsTiming,
    /// Rows per compared band (and per read-out time with [`RsTiming::Bands`]).
    pub band_height: usize,
    /// Bands compared per view and step, spread over the image.
    pub bands_per_step: usize,
    /// Starting learning rate, in scaled units (≈ pixels of image motion) per step; it decays
    /// along a half cosine to `lr_final`.
    pub lr: f64,
    /// Final learning rate.
    pub lr_final: f64,
    /// Adam's epsilon.
    pub adam_epsilon: f32,
    /// Seed of the band sampling.
    pub seed: u64,
    /// Renderer settings.
    pub render: RenderSettings,
    /// Joint refinement: when set, the Gaussians are fitted too, at these rates (Adam's epsilon
    /// as in stage 1), against the same views.
    pub refine: Option<(LearningRates, f32)>,
    /// When set, the pixels of each view that no pixel of the central view reaches, widened by
    /// this many pixels, are left out of the loss (see `explained_mask_moving`): in the motion's
    /// residual the background a foreground uncovers, in the Gaussians' (joint refinement) the
    /// strips entering at the image border too.
    pub disocclusion_margin: Option<usize>,
    /// Whether the motion's residual leaves the disocclusions out as well; when not, it compares
    /// every pixel and only the Gaussians' residual (joint refinement) is masked.
    pub mask_motion: bool,
    /// Weigh the pixels of the views off the central row by [`aperture_weights`] in the motion's
    /// residual, so that residuals a disparity error could equally have caused do not pull the
    /// motion; under joint refinement the Gaussians still compare every pixel.
    pub aperture_weighting: bool,
    /// Damped Newton steps on the motion after Adam's, over every band (0 iterations = none).
    pub newton: NewtonSettings,
    /// With a cue term and Newton steps: the directions the steps hold are then set where the
    /// cue term alone is least ([`HeldByCues`]).
    pub held_by_cues: bool,
}

/// The directions the Newton steps held, set where the measured-cue term alone is least.
#[derive(Debug, Clone, PartialEq)]
pub struct HeldByCues {
    /// How many directions were held.
    pub directions: usize,
    /// How far the motion moved along them (scaled units).
    pub distance: f64,
    /// The cue term before and after.
    pub cue_before: f64,
    /// See `cue_before`.
    pub cue_after: f64,
    /// The whole objective of the Newton steps (the photometric terms and the cue term) before
    /// and after.
    pub objective_before: f64,
    /// See `objective_before`.
    pub objective_after: f64,
    /// The motion before the move (SI), for a check of the move against the cues.
    pub unmoved: Vec<f64>,
}

impl HeldByCues {
    /// How much the photometric terms (the whole objective less the cue term) rose with the
    /// move, as a share of the whole objective before it: over 0, the views disagree with the
    /// move the cues ask for.
    pub fn photometric_rise(&self) -> f64 {
        let photometric = (self.objective_after - self.cue_after) - (self.objective_before - self.cue_before);
        photometric / self.objective_before.abs().max(f64::MIN_POSITIVE)
    }
}

/// Newton steps on the cue term alone along the held directions ([`Stage2Fit::held_by_cues`]):
/// it is nearly quadratic there, and 4-5 steps settled it on the `objects` scenes at 512 px.
const HELD_BY_CUES_ITERATIONS: usize = 10;

/// Steps between two redrawings of the disocclusion masks from the current motion.
const MASK_REFRESH: usize = 10;

/// Half-width of the window the aperture weights sum gradients over (a 5x5 window).
const APERTURE_RADIUS: usize = 2;

/// Squared gradient (per window) below which a region counts as flat and gets weight 1/2:
/// an edge of contrast 0.1 summed over a 5x5 window is about 1e-2.
const APERTURE_EPS: f32 = 1e-4;

/// What the fit found.
#[derive(Debug, Clone)]
pub struct MotionFit {
    /// The parameter vector, SI units.
    pub parameters: Vec<f64>,
    /// The scale of each parameter (its change that moves the image by about one pixel).
    pub scales: Vec<f64>,
    /// Loss per step.
    pub curve: Vec<f32>,
    /// The Gaussians: refined with joint refinement, else as given.
    pub gaussians: Gaussians,
    /// The share of the compared views' pixels left in the motion's residual by the last masks
    /// drawn (1 without masks).
    pub kept: f64,
    /// The same share in the Gaussians' residual, under joint refinement with masks.
    pub kept_by_gaussians: Option<f64>,
    /// What the Newton steps after Adam did, when there were any.
    pub newton: Option<NewtonReport>,
    /// The held directions set by the cue term, when they were ([`Stage2Fit::held_by_cues`]).
    pub held_by_cues: Option<HeldByCues>,
}

/// One rendering of the compared views: the static shape and motion parameters it is drawn with
/// (either may be held, i.e. carry no gradient), whether the aperture weights apply, whether the
/// motion prior is counted, and whose disocclusion masks it compares through (the Gaussians',
/// else the motion's).
struct Pass {
    shape: StaticShape,
    params: Tensor<1>,
    weighted: bool,
    prior: bool,
    gaussians_masks: bool,
}

/// Disocclusion masks of the compared views, cut like the targets (`[P, 1]` per view and band),
/// each with the share of the pixels it keeps: the motion's, which compare the strips entering
/// at the image border, and under joint refinement the Gaussians', which leave them out. Left
/// out of the motion's residual, the strips follow the motion estimate the masks are drawn from
/// and the fit hides its misfit along the border in them (objects_slow1 at 128 px: 0.164 px,
/// against 0.050 px compared; docs/results.md); compared in the Gaussians', they pull the
/// Gaussians along the border into them (the README's scene: BadPix(0.07) 20.1 against 18.2 %).
/// The motion's mask is left out altogether when [`Stage2Fit::mask_motion`] is off: the richer
/// models hide their misfit in the interior disocclusions as well (objects_accel 0.265 px
/// masked, 0.231 px not).
struct Masks {
    motion: Option<(f64, Vec<Vec<Tensor<2>>>)>,
    gaussians: Option<(f64, Vec<Vec<Tensor<2>>>)>,
}

impl Masks {
    /// Whether the two residuals' masks differ, so that each view is rendered once for each.
    fn differ(&self) -> bool {
        self.gaussians.is_some()
    }

    /// The masks `pass` compares through, if any.
    fn of(&self, pass: &Pass) -> Option<&[Vec<Tensor<2>>]> {
        match (&self.gaussians, pass.gaussians_masks) {
            (Some((_, cut)), true) => Some(cut),
            _ => self.motion.as_ref().map(|(_, cut)| cut.as_slice()),
        }
    }
}

/// What stage 2 optimises: the scaled motion parameters and the Gaussians (frozen unless the
/// fit refines them).
#[derive(Module, Debug)]
struct MotionAndScene {
    motion: MotionParams,
    gaussians: Gaussians,
}

/// The scales of `model`'s parameters for a scene: one unit moves a point at the Gaussians'
/// median depth by about one pixel over half the read-out.
pub fn motion_scales(model: &dyn MotionModel, g: &Gaussians, camera: &Camera) -> Vec<f64> {
    let mut depths: Vec<f64> =
        g.to_set().disparity.iter().map(|&d| camera.disparity_to_depth(d as f64)).filter(|z| z.is_finite() && *z > 0.0).collect();
    depths.sort_by(f64::total_cmp);
    let median = depths.get(depths.len() / 2).copied().unwrap_or(camera.focus_m);
    let ctx = ScaleContext {
        f_px: camera.f_px,
        half_diagonal_px: 0.5 * ((camera.width * camera.width + camera.height * camera.height) as f64).sqrt(),
        depth_m: median,
        half_readout_s: (camera.height as f64 - 1.0) / 2.0 * camera.line_time_s,
    };
    parameter_scales(&model.parameters(), &ctx)
}

/// `count` band indices out of `total`, one from each of `count` equal strata.
fn stratified(total: usize, count: usize, rng: &mut Rng) -> Vec<usize> {
    let count = count.clamp(1, total);
    (0..count)
        .map(|k| {
            let (lo, hi) = (k * total / count, ((k + 1) * total / count).max(k * total / count + 1));
            lo + (rng.next_u64() % (hi - lo) as u64) as usize
        })
        .collect()
}

/// Rows the pose table of the fit reaches beyond the image, above and below (a Gaussian or a cue
/// may land a little outside its view; beyond the table the poses extend linearly).
const TABLE_MARGIN_ROWS: f64 = 32.0;

/// Pose samples per row in the table: a piecewise model's change of rate at a segment boundary
/// is blended over a quarter row.
const TABLE_SAMPLES_PER_ROW: f64 = 4.0;

/// `model` read from a table of its poses over `camera`'s read-out, as the fit places the
/// Gaussians and the cues: at 100,000 points, 8.3 times as fast as per point for
/// `piecewise_constant` and 1.9 times for `constant_velocity`, placements within 1e-4 px
/// (`rslf bench --cues`; docs/results.md).
pub fn pose_table<'a>(model: &'a dyn MotionModel, camera: &Camera) -> Tabulated<'a> {
    let span = (camera.row_time(-TABLE_MARGIN_ROWS), camera.row_time(camera.height as f64 - 1.0 + TABLE_MARGIN_ROWS));
    Tabulated::with_step(model, span, camera.line_time_s / TABLE_SAMPLES_PER_ROW)
}

/// What a stage-2 fit is posed on: the scene and its camera, the motion model, the loss terms
/// that score a rendering, the device the fit runs on, and the central view's disparity (e.g.
/// the stage-1 render) that disocclusion masks are drawn from, if any.
#[derive(Clone, Copy)]
pub struct Stage2Context<'a> {
    /// The capture the views are compared against.
    pub scene: &'a Scene,
    /// Its camera (from `parameters.cfg`).
    pub camera: &'a Camera,
    /// The motion model whose parameters are fitted.
    pub model: &'a dyn MotionModel,
    /// The loss terms, with their weights.
    pub losses: &'a WeightedLosses,
    /// The device the fit runs on.
    pub device: &'a Device,
    /// The central view's disparity map; without one no pixel is masked, whatever
    /// [`Stage2Fit::disocclusion_margin`] says.
    pub central_disparity: Option<&'a Raster>,
}

/// Fits `ctx.model`'s parameters, starting from `start` (SI), to `views` of `ctx.scene`; the
/// Gaussians `g` are held fixed unless `fit.refine` is set. With `fit.disocclusion_margin` set,
/// the disocclusion masks are derived from `ctx.central_disparity` and the current motion
/// estimate. `cues`, when given, joins the objective. `progress(step, total, loss)` is called
/// after each Adam step, and after each evaluation of the Newton steps (with `step` past
/// `total`).
pub fn fit_stage2(
    g: Gaussians,
    ctx: &Stage2Context,
    views: &[ViewId],
    start: &[f64],
    fit: &Stage2Fit,
    cues: Option<&CueTerm>,
    mut progress: impl FnMut(usize, usize, f32),
) -> MotionFit {
    let Stage2Context { scene, camera, model, losses, device, central_disparity } = *ctx;
    let g = if fit.refine.is_some() { g } else { g.no_grad() };
    let table = pose_table(model, camera);
    let model: &dyn MotionModel = &table;
    let tc = TensorCamera::new(camera);
    let scales = motion_scales(model, &g, camera);
    let w = scene.width();
    let all_bands = bands(0..scene.height(), RsTiming::Bands(fit.band_height), &tc);
    let targets = view_targets(scene, views);
    // Band targets are cut once: `[P, C]` per (view, band).
    let band_targets: Vec<Vec<Tensor<2>>> =
        targets.iter().map(|t| all_bands.iter().map(|(rows, _)| band_tensor(t.image, rows.clone(), device)).collect()).collect();
    // Disocclusion masks, cut like the targets. They follow the motion: redrawn from the current
    // estimate every `MASK_REFRESH` steps.
    let draw_masks = |motion: &MotionRecord| -> Option<Masks> {
        let (margin, disparity) = fit.disocclusion_margin.zip(central_disparity)?;
        let draw = |border: BorderStrips| {
            let maps: Vec<Raster> =
                targets.iter().map(|t| explained_mask_moving(disparity, camera, t.view, motion, margin, border)).collect();
            let values = maps.iter().flat_map(|r| &r.data);
            let kept = values.clone().map(|&x| x as f64).sum::<f64>() / values.count().max(1) as f64;
            let cut = maps.iter().map(|mask| all_bands.iter().map(|(rows, _)| band_tensor(mask, rows.clone(), device)).collect()).collect();
            (kept, cut)
        };
        let motion = fit.mask_motion.then(|| draw(BorderStrips::Explained));
        let gaussians = fit.refine.is_some().then(|| draw(BorderStrips::LeftOut));
        (motion.is_some() || gaussians.is_some()).then_some(Masks { motion, gaussians })
    };
    let mut masks = draw_masks(&model.record(start));
    // Aperture weights of the off-row views, cut like the targets: `[P, 1]` per (view, band).
    let aperture: Vec<Option<Vec<Tensor<2>>>> = targets
        .iter()
        .map(|t| {
            (fit.aperture_weighting && t.offset.1 != 0.0).then(|| {
                let weights = aperture_weights(t.image, APERTURE_RADIUS, APERTURE_EPS);
                all_bands.iter().map(|(rows, _)| band_tensor(&weights, rows.clone(), device)).collect()
            })
        })
        .collect();
    let motion_plan = GroupPlan {
        schedule: Schedule::Cosine { start: fit.lr, end: fit.lr_final, steps: fit.iterations },
        adam_epsilon: fit.adam_epsilon,
    };
    let plan = match &fit.refine {
        Some((lr, eps)) => with_gaussian_groups(Plan::new(motion_plan), &g, lr, *eps),
        None => Plan::new(motion_plan),
    };
    let stage = Stage { iterations: fit.iterations, plan };
    let initial = MotionAndScene { motion: MotionParams::new(start, &scales, device), gaussians: g };
    let mut rng = Rng::new(fit.seed ^ 0x5747_4532);
    // The photometric losses of the bands `bands_of(view)` chooses in each view (in turn; a view
    // with none is not rendered), each view rendered by `joint`, or by both passes of `split`
    // where its aperture weights apply or the two residuals' masks differ.
    let compare = |joint: &Pass,
                   split: Option<&[Pass; 2]>,
                   masks: Option<&Masks>,
                   scaled: &Tensor<1>,
                   bands_of: &mut dyn FnMut(usize) -> Vec<usize>| {
        let mut loss = MeanLoss::default();
        for (v, (ViewTarget { offset, .. }, view_bands)) in targets.iter().zip(&band_targets).enumerate() {
            let chosen = bands_of(v);
            if chosen.is_empty() {
                continue;
            }
            let passes: &[Pass] = match split {
                Some(split) if aperture[v].is_some() || masks.is_some_and(Masks::differ) => split,
                _ => std::slice::from_ref(joint),
            };
            let rolling: Vec<Option<Splats>> = passes
                .iter()
                .map(|p| match fit.timing {
                    RsTiming::PerGaussian(iterations) => Some(p.shape.splats_rolling(model, p.params.clone(), *offset, iterations)),
                    RsTiming::Bands(_) => None,
                })
                .collect();
            for b in chosen {
                let (rows, tau) = all_bands[b].clone();
                let mut band_loss = MeanLoss::default();
                for (pass, rolling) in passes.iter().zip(&rolling) {
                    let splats = match rolling {
                        Some(s) => s.clone(),
                        None => pass.shape.splats_at_time(model, pass.params.clone(), *offset, tau.expect("bands have a time")),
                    };
                    let out = splat(&splats, &splats.bins(w, rows.clone(), &fit.render), device);
                    let (out, target) = match masks.and_then(|m| m.of(pass)) {
                        Some(cut) => masked(out, view_bands[b].clone(), cut[v][b].clone()),
                        None => (out, view_bands[b].clone()),
                    };
                    let (out, target) = match (&aperture[v], pass.weighted) {
                        (Some(weights), true) => masked(out, target, weights[b].clone()),
                        _ => (out, target),
                    };
                    let motion = pass.prior.then_some(MotionInput { scaled, model });
                    band_loss.add(losses.evaluate(&LossInput { rendered: &out, target: &target, rows: rows.len(), width: w, motion }));
                }
                // A band counts once; with two passes, their losses are summed.
                loss.add(band_loss.sum());
            }
        }
        loss
    };
    // The passes each view is rendered by in a step: `joint`, and under joint refinement the
    // two of `split` where the view's aperture weights apply or the two residuals' masks differ.
    let passes = |m: &MotionAndScene, masks: Option<&Masks>| {
        let params = m.motion.si(&scales);
        let joint = Pass {
            shape: StaticShape::new(&m.gaussians, tc, model, params.clone()),
            params: params.clone(),
            weighted: true,
            prior: true,
            gaussians_masks: false,
        };
        // Under joint refinement an aperture-weighted view is rendered twice: the motion's pass
        // (Gaussians held) compares the weighted residual, the Gaussians' pass (motion held)
        // every pixel, so the geometry still learns from the horizontal edges the motion ignores.
        // So is every view where the two residuals' disocclusion masks differ.
        let two_masks = masks.is_some_and(Masks::differ);
        let split = (fit.refine.is_some() && (two_masks || aperture.iter().any(Option::is_some))).then(|| {
            [
                Pass {
                    shape: StaticShape::new(&m.gaussians.clone().no_grad(), tc, model, params.clone()),
                    params: params.clone(),
                    weighted: true,
                    prior: true,
                    gaussians_masks: false,
                },
                Pass {
                    shape: StaticShape::new(&m.gaussians, tc, model, params.clone().detach()),
                    params: params.clone().detach(),
                    weighted: false,
                    prior: false,
                    gaussians_masks: true,
                },
            ]
        });
        (joint, split)
    };
    // A step's loss is the mean over the bands compared in every view, plus the cue term; its
    // gradients are taken view by view ([`mean_over_parts`]), so that one view's graph lives at
    // a time on each core.
    let objective = |m: &MotionAndScene, step: usize| {
        if masks.is_some() && step > 0 && step.is_multiple_of(MASK_REFRESH) {
            masks = draw_masks(&model.record(&m.motion.si_values(&scales)));
        }
        let chosen: Vec<Vec<usize>> = (0..targets.len()).map(|_| stratified(all_bands.len(), fit.bands_per_step, &mut rng)).collect();
        let masks = masks.as_ref();
        let view = |m: &MotionAndScene, v: usize| {
            let (joint, split) = passes(m, masks);
            compare(&joint, split.as_ref(), masks, &m.motion.scaled.val(), &mut |u| if u == v { chosen[v].clone() } else { Vec::new() })
        };
        let (mut value, mut parts) = mean_over_parts(m, targets.len(), device, view)?;
        if let Some(cues) = cues {
            let term = cues.evaluate(tc, model, m.motion.si(&scales));
            value += term.clone().into_scalar::<f32>();
            parts.push((gradients_of(term, m), 1.0));
        }
        Some((value, weighted_sum(m, parts)))
    };
    let (fitted, curve) = optimise_by_gradients(initial, &stage, objective, |r: StepReport| progress(r.step, r.of, r.loss));
    // Newton steps on the motion alone (Gaussians held), over every band of every view: the
    // objective the motion's Adam steps sample, less the motion prior when the measured cues are
    // in it. The steps hold the directions the views barely observe where Adam left them (their
    // curvature is under the floor); along the ones they move, the cues constrain the motion and
    // the prior would only shrink it towards rest, while the photometric terms alone still need
    // it (docs/results.md). Each evaluation is reported as a step beyond Adam's last.
    let (parameters, newton, held_by_cues) = if fit.newton.iterations > 0 {
        let held = fitted.gaussians.clone().no_grad();
        let n = scales.len();
        let every: Vec<usize> = (0..all_bands.len()).collect();
        let masks = masks.as_ref();
        let mut evaluations = 0;
        // The scaled motion `x` as a leaf of a new graph.
        let leaf = |x: &[f64]| Tensor::<1>::from_data(TensorData::new(x.iter().map(|&v| v as f32).collect(), [n]), device).require_grad();
        // The cue term's value and gradient at `x`, for the whole objective and alone.
        let cue_term = |cues: &CueTerm, x: &[f64]| {
            let scaled = leaf(x);
            let term = cues.evaluate(tc, model, MotionParams::to_si(scaled.clone(), &scales));
            let value = term.clone().into_scalar::<f32>() as f64;
            let grad = scaled.grad(&term.backward()).map_or(vec![0.0; n], |g| host_values(g).into_iter().map(f64::from).collect());
            (value, grad)
        };
        let mut eval = |x: &[f64]| {
            // Each view's bands, their summed loss and its gradient, the views on the cores in
            // parallel, each its own graph, freed once its gradient is read (as many graphs live
            // at once as there are cores). The gradient of the mean over every band is the sum of
            // the views' gradients over the number of bands; the sums are added in the views'
            // order, so the result does not depend on how the views are spread over the cores.
            let views = (0..targets.len())
                .into_par_iter()
                .map(|v| {
                    let scaled = leaf(x);
                    let params = MotionParams::to_si(scaled.clone(), &scales);
                    let pass = Pass {
                        shape: StaticShape::new(&held, tc, model, params.clone()),
                        params,
                        weighted: true,
                        prior: cues.is_none(),
                        gaussians_masks: false,
                    };
                    let part = compare(&pass, None, masks, &scaled, &mut |u| if u == v { every.clone() } else { Vec::new() });
                    let count = part.count();
                    let sum = part.sum().map(|sum| {
                        let grad = scaled.grad(&sum.backward()).map_or(vec![0.0; n], host_values);
                        (sum.into_scalar::<f32>(), grad)
                    });
                    (count, sum)
                })
                .collect::<Vec<_>>();
            let mut photometric = (0.0, vec![0.0; n]);
            let mut bands = 0;
            for (count, sum) in views {
                bands += count;
                if let Some((value, grad)) = sum {
                    photometric.0 += value as f64;
                    photometric.1.iter_mut().zip(grad).for_each(|(a, b)| *a += b as f64);
                }
            }
            if bands == 0 {
                return (f64::NAN, vec![0.0; n]);
            }
            let mut total: (f64, Vec<f64>) = (photometric.0 / bands as f64, photometric.1.iter().map(|g| g / bands as f64).collect());
            if let Some(cues) = cues {
                let (value, grad) = cue_term(cues, x);
                total.0 += value;
                total.1.iter_mut().zip(grad).for_each(|(a, b)| *a += b);
            }
            evaluations += 1;
            progress(fit.iterations + evaluations, fit.iterations, total.0 as f32);
            total
        };
        let start: Vec<f64> = host_values(fitted.motion.scaled.val()).into_iter().map(f64::from).collect();
        let (mut end, report) = newton_minimise(&start, &fit.newton, &mut eval);
        // The directions the steps hold, where the photometric objective's minimum lies off the
        // truth, set where the cue term alone is least (docs/results.md), and the whole
        // objective there, by which the run judges whether the views ask for that move too.
        let mut by_cues = None;
        if let Some(cues) = cues.filter(|_| fit.held_by_cues) {
            let held = held_directions(&end, fit.newton.fd_step, fit.newton.min_curvature_ratio, &mut eval);
            if !held.is_empty() {
                let settings = NewtonSettings { iterations: HELD_BY_CUES_ITERATIONS, ..fit.newton };
                let (moved, cue_report) = newton_within(&end, &held, &settings, |x| cue_term(cues, x));
                let distance = moved.iter().zip(&end).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
                let unmoved = end.iter().zip(&scales).map(|(x, s)| x * s).collect();
                let (objective_after, _) = eval(&moved);
                by_cues = Some(HeldByCues {
                    directions: held.len(),
                    distance,
                    cue_before: cue_report.start,
                    cue_after: cue_report.end,
                    objective_before: report.end,
                    objective_after,
                    unmoved,
                });
                end = moved;
            }
        }
        (end.iter().zip(&scales).map(|(x, s)| x * s).collect(), Some(report), by_cues)
    } else {
        (fitted.motion.si_values(&scales), None, None)
    };
    let kept = masks.as_ref().and_then(|m| m.motion.as_ref()).map_or(1.0, |(kept, _)| *kept);
    let kept_by_gaussians = masks.and_then(|m| m.gaussians).map(|(kept, _)| kept);
    MotionFit { parameters, scales, curve, gaussians: fitted.gaussians, kept, kept_by_gaussians, newton, held_by_cues }
}

#[cfg(test)]
mod tests {
    use super::HeldByCues;

    fn moved(objective: (f64, f64), cue_term: (f64, f64)) -> HeldByCues {
        HeldByCues {
            directions: 1,
            distance: 1.0,
            cue_before: cue_term.0,
            cue_after: cue_term.1,
            objective_before: objective.0,
            objective_after: objective.1,
            unmoved: vec![0.0; 6],
        }
    }

    #[test]
    fn the_views_disagree_with_a_move_where_the_whole_objective_falls_by_less_than_the_cue_term() {
        // The cue term falls by 1e-5; the whole objective by 4e-6, so the photometric terms rise
        // by 6e-6: 0.03 % of the objective's 0.02.
        let rise = moved((0.02, 0.02 - 4e-6), (1e-3, 1e-3 - 1e-5)).photometric_rise();
        assert!((rise - 3e-4).abs() < 1e-9, "{rise}");
        // The whole objective falls by more than the cue term: the views ask for the move too.
        let rise = moved((0.02, 0.02 - 1.5e-5), (1e-3, 1e-3 - 1e-5)).photometric_rise();
        assert!((rise + 2.5e-4).abs() < 1e-9, "{rise}");
    }
}
