//! Stage 2 as a run carries it out: the cues measured between the views, the photometric fit of
//! the motion ([`super::fit_stage2`]), the check of its estimate against the cues, the fit again
//! with them of a motion they confirm, and the check of the kept motion's roll and forward motion
//! ([`super::axial_support`]), each with its line in the run's log.

use super::run_log::{RunLog, curve_ends, estimate_line};
use super::{
    Cue, CueTerm, LearningRates, LossCurves, MotionFit, Stage2Context, Stage2Fit, TrackedCues, axial_support, column_views, cue_support,
    drop_outlying_matches, fit_stage2, render_settings, rs_timing, stage1_views, stage2_views, tracked_cues,
};
use crate::config::{Config, Stage2Config, ViewSelection};
use crate::geometry::{Camera, ViewId};
use crate::io::{MotionRecord, Raster};
use crate::model::Gaussians;
use crate::model::motion::MotionModel;
use crate::optim::NewtonSettings;
use crate::render::row_bands;
use std::time::Instant;

/// Residual (px) beyond which a measured cue counts linearly in the cue term. At 0.05 or 0.2 px
/// `vegetation_slow2` (256 px) comes out within 0.005 px of its figure at 0.1 (docs/results.md).
const CUE_HUBER_PX: f32 = 0.1;

/// Finite-difference step (scaled units: about a pixel of image motion each) of the stage-2
/// Newton steps' Hessian, and their longest step.
const NEWTON_FD_STEP: f64 = 0.05;
const NEWTON_MAX_STEP: f64 = 2.0;
/// The stage-2 Newton steps hold the directions whose curvature is under this share of the
/// steepest's. On the 256 px suite the two flattest (about 1/300 of the steepest, mostly the
/// motion prior's own curvature: tilt against vertical translation, pan against sideways
/// translation) carried the steps that made the slow scenes worse, while the roll and v_z
/// directions (1/80 and more) carried the gains (docs/results.md). After the steps the held
/// directions are set to rest where `[stage2] newton_rest_tolerance` allows.
const NEWTON_MIN_CURVATURE_RATIO: f64 = 5e-3;

/// How the run log's line with stage 2's cue check's verdict begins; readers of a log, such as
/// `rslf ablation`, find the verdict by it.
pub const CHECK_LINE: &str = "stage 2 check: ";
/// How the line with the verdict on the roll and forward motion of the kept motion begins.
pub const AXIAL_CHECK_LINE: &str = "stage 2 check of the roll and forward motion: ";
/// How the line with the verdict on the fit with the cues, after a check that did not confirm
/// the motion, begins.
pub const REFIT_CHECK_LINE: &str = "stage 2 check of the fit with the measured cues: ";
/// How the line with the verdict on the move of the held directions to the cue term's least
/// (`[stage2] held_by_cues`) begins.
pub const HELD_CHECK_LINE: &str = "stage 2 check of the held directions' move: ";

/// Stage 2: the motion, fitted against the off-row views and checked against the cues measured
/// between them. With the check on, the measured-cue term (`cue_weight`) joins only after it:
/// the photometric fit alone is judged (a fit to the cues would pass any check against them). A
/// motion the cues confirm is fitted again from the start, with the term, and kept. One they do
/// not confirm is set to none (a still camera unless the cues show otherwise), unless its fit
/// with the term, run too when `min_cue_signal` is over 0, stands clear of the cues' scatter
/// ([`keep_refit`]). The loss curves go to `curves`: `stage2`, then `stage2_cues` when the
/// second fit runs.
/// The cues are tracked with `initial_disparity`, the stage-1 initialisation's.
pub(super) fn run(
    config: &Config,
    ctx: &Stage2Context,
    gaussians: Gaussians,
    start_values: &[f64],
    initial_disparity: &Raster,
    log: &mut RunLog,
    curves: &mut LossCurves,
) -> MotionFit {
    let Stage2Context { scene, camera, model, .. } = *ctx;
    let s = &config.stage2;
    // The cue check judges a fitted motion; a motion given with no iterations is used as it is.
    let check = s.min_cue_support > 0.0 && s.iterations > 0;
    let check_axial_part = s.min_axial_support > 0.0 && s.iterations > 0;
    let cues = (s.cue_weight > 0.0 || check || check_axial_part).then(|| {
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
    let mut fitted = fit_and_check(config, ctx, gaussians, start_values, cues.as_deref(), log, curves);
    if let Some(cues) = &cues {
        check_held_move(&mut fitted, model, camera, cues, s.min_axial_support, log);
    }
    match cues {
        Some(cues) if check_axial_part => check_axial(fitted, model, camera, &two_way(&cues), s.min_axial_support, log),
        _ => fitted,
    }
}

/// Keeps the move of the held directions to the cue term's least ([`super::HeldByCues`]) only
/// where the two kinds of evidence both ask for it: the views, whose photometric terms must not
/// rise with it ([`super::HeldByCues::photometric_rise`]), and the cues, which must bear out
/// `min_support` of it by two standard errors of the block jackknife ([`super::part_support`]:
/// every cue the term holds, judged over 4 x 4 blocks of the view; with `min_support` 0 they
/// are not asked). Otherwise the motion goes back where the Newton steps left it, as it does
/// where the blocks cannot judge the move; the log says which.
fn check_held_move(fitted: &mut MotionFit, model: &dyn MotionModel, camera: &Camera, cues: &[Cue], min_support: f64, log: &mut RunLog) {
    let Some(held) = fitted.held_by_cues.as_ref() else { return };
    let rise = held.photometric_rise();
    let views = format!("the views' photometric terms {} by {:.4} % with it", if rise > 0.0 { "rise" } else { "fall" }, 100.0 * rise.abs());
    let (cues_confirm, cues_said) = if min_support > 0.0 {
        let support = super::part_support(camera, &model.record(&held.unmoved), &model.record(&fitted.parameters), cues);
        let shown = support.map_or("no judgement (too few cues or blocks)".to_string(), |s| {
            format!("{:.2} (± {:.2} over {} blocks of the image)", s.share, s.standard_error, s.blocks)
        });
        let confirmed = support.is_some_and(|s| s.confirms(min_support));
        let clearly = if confirmed { "clearly over" } else { "not clearly over" };
        (confirmed, format!(", and the measured cues bear out {shown} of it, {clearly} {min_support}"))
    } else {
        (true, String::new())
    };
    let kept = rise <= 0.0 && cues_confirm;
    if !kept {
        fitted.parameters = held.unmoved.clone();
    }
    let verdict = if kept { "kept" } else { "put back" };
    log.push(format!("{HELD_CHECK_LINE}{views}{cues_said}: {verdict}"));
}

/// The patches textured both ways alone: the cues of edges and stripes carry biases of a few
/// percent, enough to bear out a still scene's drift (`objects_static`: 0.55 ± 0.01 with them,
/// -0.01 ± 0.02 without; docs/results.md), so the checks judge without them.
fn two_way(cues: &[Cue]) -> Vec<Cue> {
    cues.iter().copied().filter(|c| c.across.is_none()).collect()
}

/// The fits of [`run`] and the cue check between them, with the cues `cues` measured where
/// the config asks for them.
fn fit_and_check(
    config: &Config,
    ctx: &Stage2Context,
    gaussians: Gaussians,
    start_values: &[f64],
    cues: Option<&[Cue]>,
    log: &mut RunLog,
    curves: &mut LossCurves,
) -> MotionFit {
    let Stage2Context { scene, camera, model, losses, device, .. } = *ctx;
    let s = &config.stage2;
    let check = s.min_cue_support > 0.0 && s.iterations > 0;
    // The term is built where a fit uses it: a motion the check sets to none needs none.
    let cue_term = || {
        cues.filter(|_| s.cue_weight > 0.0)
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
        mask_motion: s.mask_motion_residual,
        aperture_weighting: s.aperture_weighting,
        // No Adam steps, no estimation: a given `initial_motion` is used as it is.
        newton: NewtonSettings {
            iterations: if s.iterations > 0 { s.newton_iterations } else { 0 },
            fd_step: NEWTON_FD_STEP,
            max_step: NEWTON_MAX_STEP,
            min_curvature_ratio: NEWTON_MIN_CURVATURE_RATIO,
            rest_tolerance: s.newton_rest_tolerance,
        },
        held_by_cues: s.held_by_cues,
    };
    // One phase of the fit, with its progress bar and its line in the log. The Newton steps go to
    // the last (`last`), whose motion is kept: the second when the check may confirm the motion
    // for one, so the check judges the same fit with or without them.
    let phase = |what: &str, g: Gaussians, cue_term: Option<&CueTerm>, last: bool, log: &mut RunLog| {
        let bar = crate::progress::bar(s.iterations as u64, &format!("stage 2: {what}"));
        let start = Instant::now();
        let fit = if last { fit.clone() } else { Stage2Fit { newton: NewtonSettings { iterations: 0, ..fit.newton }, ..fit.clone() } };
        let fitted = fit_stage2(g, ctx, &views, start_values, &fit, cue_term, |done, of, loss| {
            bar.set_position(done.min(of) as u64);
            bar.set_message(match done.checked_sub(of).filter(|&k| k > 0) {
                None => format!("stage 2 ({what}): loss {loss:.4}"),
                Some(k) => format!("stage 2 ({what}): Newton steps, objective {loss:.5} ({k} evaluations)"),
            });
        });
        bar.finish_and_clear();
        // Each step scores `bands_per_step` bands drawn across the image.
        let bands = row_bands(0..scene.height(), s.band_height).len();
        let stage2_ends = curve_ends(&fitted.curve, bands.div_ceil(s.bands_per_step.clamp(1, bands.max(1))));
        log.push(format!(
            "stage 2 {what}: `{}` motion, {} Adam steps, {} bands of {} rows in each of {} views per step ({:?} timing), {}{}{}, loss ({}) {:.4} -> {:.4} over the first and the last round of bands{}{}, {:.1} s; estimate {}",
            model.name(),
            s.iterations,
            s.bands_per_step,
            s.band_height,
            views.len(),
            s.timing,
            match (fit.disocclusion_margin.is_some(), fit.mask_motion, fitted.kept_by_gaussians) {
                (true, true, by_gaussians) => format!(
                    "{:.1}% of the pixels compared (disocclusions masked){}",
                    100.0 * fitted.kept,
                    by_gaussians.map_or(String::new(), |k| format!(
                        " in the motion's residual, {:.1}% in the Gaussians' (the strips entering at the border left out too)",
                        100.0 * k
                    ))
                ),
                (true, false, Some(k)) => format!(
                    "every pixel compared in the motion's residual, {:.1}% in the Gaussians' (disocclusions and the strips entering at the border left out)",
                    100.0 * k
                ),
                _ => "every pixel compared".to_string(),
            },
            if fit.aperture_weighting { ", off-row pixels weighted by their horizontal gradient share" } else { "" },
            cue_term.map_or(String::new(), |c| format!(", measured-cue term ×{} over {} cues", c.weight, c.len)),
            losses.names().join(" + "),
            stage2_ends.0,
            stage2_ends.1,
            fitted.newton.map_or(String::new(), |r| format!(
                ", then {} of {} Newton steps taken over every band{}, {:.5} -> {:.5} ({} evaluations){}",
                r.taken,
                s.newton_iterations,
                if cue_term.is_some() { " (their objective leaves the motion prior out)" } else { "" },
                r.start,
                r.rest.map_or(r.end, |rest| rest.before),
                r.evaluations,
                r.rest.map_or(String::new(), |rest| format!(
                    ", the directions they hold {} rest ({:.3} scaled units away, objective {:+.4} %, tolerance {} %)",
                    if rest.taken { "set to" } else { "not set to" },
                    rest.distance,
                    100.0 * (rest.after - rest.before) / rest.before.abs().max(f64::MIN_POSITIVE),
                    100.0 * s.newton_rest_tolerance
                ))
            )),
            fitted.held_by_cues.as_ref().map_or(String::new(), |h| format!(
                ", then the {} direction{} they hold set where the cue term alone is least ({:.3} scaled units away, cue term {:.5e} -> {:.5e}, objective {:+.4} %)",
                h.directions,
                if h.directions == 1 { "" } else { "s" },
                h.distance,
                h.cue_before,
                h.cue_after,
                100.0 * (h.objective_after - h.objective_before) / h.objective_before.abs().max(f64::MIN_POSITIVE)
            )),
            start.elapsed().as_secs_f64(),
            estimate_line(model, &fitted.parameters)
        ));
        fitted
    };
    let checked_cues = cues.filter(|_| check);
    let first_cue_term = if checked_cues.is_some() { None } else { cue_term() };
    let second_fit = checked_cues.is_some() && s.cue_weight > 0.0;
    let mut fitted = phase("fit", gaussians.clone(), first_cue_term.as_ref(), !second_fit, log);
    curves.push(("stage2".to_string(), fitted.curve.clone()));
    let Some(checked) = checked_cues else { return fitted };
    let two_way = two_way(checked);
    let second_chance = s.min_cue_signal > 0.0 && s.cue_weight > 0.0;
    let verdict = check_motion(&mut fitted, model, camera, &two_way, s.min_cue_support, second_chance, log);
    let refit_due = verdict == Some(true) || (verdict == Some(false) && second_chance);
    let Some(term) = refit_due.then(cue_term).flatten() else { return fitted };
    // Fitted to the cues, a motion keeps what they show: from the start again, not from the
    // photometric estimate, where the fit stays near it (objects_accel, constant_acceleration:
    // 1.22 px against 0.51 px).
    let refit = phase("fit with the measured cues", gaussians, Some(&term), true, log);
    curves.push(("stage2_cues".to_string(), refit.curve.clone()));
    if verdict == Some(true) {
        return refit;
    }
    // The check refuted the photometric estimate or could not confirm it, but that fit can
    // overshoot a true motion (checkerboards_slow2 at 512 px: its tilt 2.2 times the truth's,
    // support 0.42): the motion fitted with the cues is kept where the cues it predicts stand
    // clear of their scatter. A still scene's do not: its drift shrinks to what the cues'
    // biases bear out (docs/results.md).
    keep_refit(refit, fitted, model, camera, &two_way, s, log)
}

/// The motion fitted with the measured cues after the check did not confirm the photometric
/// one (`still`, set to none): kept when the cues confirm it at `min_cue_support` and its
/// predicted cues stand at least `min_cue_signal` times the cues' scatter clear of none, per cue
/// ([`super::CueSupport::signal`]), else `still`.
fn keep_refit(
    refit: MotionFit,
    still: MotionFit,
    model: &dyn MotionModel,
    camera: &Camera,
    cues: &[Cue],
    settings: &Stage2Config,
    log: &mut RunLog,
) -> MotionFit {
    let (min_support, min_signal) = (settings.min_cue_support, settings.min_cue_signal);
    let support = cue_support(camera, &model.record(&refit.parameters), cues);
    let shown = support.map_or("no judgement (too few cues imaged, or no motion)".to_string(), |c| {
        format!(
            "{:.2} (± {:.2}) of it, its predicted cues {:.2} times their scatter clear of none (per cue)",
            c.share,
            c.standard_error,
            c.signal()
        )
    });
    let kept = support.is_some_and(|c| c.confirms(min_support) && c.signal() >= min_signal);
    log.push(format!(
        "{REFIT_CHECK_LINE}they bear out {shown}; {}",
        if kept {
            format!("clearly over {min_support}, and at least {min_signal} times: kept")
        } else {
            format!("not both clearly over {min_support} and at least {min_signal} times: no motion kept")
        }
    ));
    if kept { refit } else { still }
}

/// Keeps the fitted motion only when the cues measured between the views confirm it at
/// `min_support` ([`super::CueSupport::confirms`], with the larger of the cues' standard error
/// and the block jackknife's over 4 x 4 blocks of the image, [`super::part_support`]: a still
/// `checkerboards` at 128 px bears out 0.78 ± 0.06 of its drift by the first, ± 0.73 by the
/// second; docs/results.md), else sets it to none, and says in the log
/// what they show either way, and whether the fit with the cues will have a `second_chance`
/// ([`keep_refit`]). A motion they neither refute nor confirm goes too: on the 128 px suite
/// only still scenes came out so (docs/results.md). Returns whether they confirm it, `None`
/// where too few cues are imaged to judge (the motion is then kept as fitted).
pub(super) fn check_motion(
    fitted: &mut MotionFit,
    model: &dyn MotionModel,
    camera: &Camera,
    cues: &[Cue],
    min_support: f64,
    second_chance: bool,
    log: &mut RunLog,
) -> Option<bool> {
    let Some(support) = cue_support(camera, &model.record(&fitted.parameters), cues) else {
        log.push(format!("{CHECK_LINE}not made ({} measured cues; at least 100 imaged and a motion are needed)", cues.len()));
        return None;
    };
    // The cues' errors are not independent from patch to patch (a periodic texture's matches
    // share one bias over a region), so the support is judged with the block jackknife's
    // standard error where it is the larger.
    let blocks = super::part_support(camera, &MotionRecord::zero(), &model.record(&fitted.parameters), cues);
    let judged = super::CueSupport { standard_error: support.standard_error.max(blocks.map_or(0.0, |b| b.standard_error)), ..support };
    let shown = format!(
        "the {} measured cues of patches textured both ways bear out {:.2} (± {:.2} from their scatter, ± {} of the image) of the motion's predicted ones",
        support.cues,
        support.share,
        support.standard_error,
        blocks.map_or("n/a over blocks".to_string(), |b| format!("{:.2} over {} blocks", b.standard_error, b.blocks))
    );
    if judged.confirms(min_support) {
        log.push(format!("{CHECK_LINE}{shown}, clearly over {min_support}: kept"));
        return Some(true);
    }
    fitted.parameters.iter_mut().for_each(|p| *p = 0.0);
    let verdict = if judged.refutes(min_support) { "clearly under" } else { "not clearly over" };
    let then = if second_chance { "unless the fit with the measured cues stands clear of their scatter" } else { "no motion kept" };
    log.push(format!("{CHECK_LINE}{shown}, {verdict} {min_support}: taken for a drift of the fit, {then}"));
    Some(false)
}

/// Keeps each group of the kept motion's rates along and about the optical axis (one per
/// segment of `piecewise_constant`, [`super::axial_groups`]) only when the cues confirm it at
/// `min_support` with the block jackknife's standard error ([`super::AxialSupport::confirms`]),
/// else sets it to 0, and says in the log what they show. A group that is 0, or that too few
/// cues or blocks judge, is kept as it is.
fn check_axial(
    mut fitted: MotionFit,
    model: &dyn MotionModel,
    camera: &Camera,
    cues: &[Cue],
    min_support: f64,
    log: &mut RunLog,
) -> MotionFit {
    let judgements = axial_support(camera, model, &fitted.parameters, cues);
    let sets = super::axial_groups(model).len();
    let mut verdicts = Vec::new();
    let mut changed = false;
    for judgement in &judgements {
        let set = if sets > 1 { format!("{}: ", judgement.group + 1) } else { String::new() };
        let Some(support) = judgement.support else {
            if sets > 1 {
                verdicts.push(format!("{set}too few cues or blocks to judge, kept"));
            }
            continue;
        };
        let confirmed = support.confirms(min_support);
        if !confirmed {
            judgement.entries.iter().for_each(|&i| fitted.parameters[i] = 0.0);
            changed = true;
        }
        let shown = format!("{set}{:.2} (± {:.2} over {} blocks of the image)", support.share, support.standard_error, support.blocks);
        verdicts.push(match (confirmed, sets > 1) {
            (true, false) => format!("{shown} of the roll and forward motion, the rest held; clearly over {min_support}: kept"),
            (false, false) => format!("{shown} of the roll and forward motion, the rest held; not clearly over {min_support}: set to 0"),
            (true, true) => format!("{shown}, clearly over {min_support}: kept"),
            (false, true) => format!("{shown}, not clearly over {min_support}: set to 0"),
        });
    }
    if verdicts.is_empty() {
        return fitted;
    }
    log.push(format!(
        "{AXIAL_CHECK_LINE}the measured cues of patches textured both ways bear out {}{}{}",
        if sets > 1 {
            format!("of each of the {sets} sets of roll and forward rates (one per segment), the rest held, over the blocks of the rows it moves: ")
        } else {
            String::new()
        },
        verdicts.join("; "),
        if changed { format!("; estimate {}", estimate_line(model, &fitted.parameters)) } else { String::new() }
    ));
    fitted
}
