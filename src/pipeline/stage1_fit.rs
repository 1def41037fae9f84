//! Stage-1 fit: Adam on every Gaussian parameter against views of the central row (which hold no
//! motion) and, if asked, of the central column, one learning rate per parameter group.

use super::targets::{ViewTarget, band_tensor, view_targets};
use crate::geometry::ViewId;
use crate::io::{Raster, Scene};
use crate::loss::{LossInput, WeightedLosses};
use crate::model::Gaussians;
use crate::optim::{GroupPlan, MeanLoss, Plan, Schedule, Stage, StepReport, mean_over_parts, optimise_by_gradients, weighted_sum};
use crate::render::{RenderSettings, bins_for_view, render, row_bands};
use burn::tensor::{Device, Tensor, TensorData};

/// Learning rates of the four parameter groups (units of the parameter per step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LearningRates {
    /// Centres, pixels.
    pub position: f64,
    /// Disparity, pixels.
    pub disparity: f64,
    /// `ln σ`.
    pub size: f64,
    /// Colour.
    pub colour: f64,
}

/// The schedule of a stage-1 rate `lr` over a fit of `steps`: a half cosine to `final_share`
/// of it, or constant where that share is 1.
pub fn decaying(lr: f64, final_share: f64, steps: usize) -> Schedule {
    if final_share >= 1.0 { Schedule::Constant(lr) } else { Schedule::Cosine { start: lr, end: lr * final_share, steps } }
}

/// Settings of the stage-1 fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Stage1Fit {
    /// Adam steps; each renders one band of rows in every view, bands taken in turn.
    pub iterations: usize,
    /// Rows per band.
    pub band_height: usize,
    /// Learning rates (the disparities' at the first step).
    pub lr: LearningRates,
    /// The disparities' rate at the last step as a share of `lr.disparity`, reached along a
    /// half cosine ([`decaying`]; 1: constant). The other groups keep their rates.
    pub disparity_final_share: f64,
    /// Adam's epsilon. Near 0 Adam steps by the sign of the gradient, so parameters with
    /// noise-level gradients (disparity in flat regions) random-walk at the full rate.
    pub adam_epsilon: f32,
    /// Renderer settings.
    pub render: RenderSettings,
}

/// A view's pixels as a `[P, C]` tensor.
pub fn image_tensor(img: &Raster, device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(img.data.clone(), [img.pixels(), img.channels]), device)
}

/// The learning-rate schedules of the Gaussians' four parameter groups.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussianSchedules {
    /// Centres.
    pub position: Schedule,
    /// Disparities.
    pub disparity: Schedule,
    /// `ln σ`.
    pub size: Schedule,
    /// Colours.
    pub colour: Schedule,
}

impl GaussianSchedules {
    /// Every group at its constant rate.
    pub fn constant(lr: &LearningRates) -> Self {
        Self {
            position: Schedule::Constant(lr.position),
            disparity: Schedule::Constant(lr.disparity),
            size: Schedule::Constant(lr.size),
            colour: Schedule::Constant(lr.colour),
        }
    }
}

/// `plan` with the Gaussians' four parameter groups added: constant rates, one epsilon.
pub fn with_gaussian_groups(plan: Plan, g: &Gaussians, lr: &LearningRates, adam_epsilon: f32) -> Plan {
    with_gaussian_schedules(plan, g, &GaussianSchedules::constant(lr), adam_epsilon)
}

/// `plan` with the Gaussians' four parameter groups added, each on its schedule, one epsilon.
pub fn with_gaussian_schedules(plan: Plan, g: &Gaussians, schedules: &GaussianSchedules, adam_epsilon: f32) -> Plan {
    let group = |schedule| GroupPlan { schedule, adam_epsilon };
    plan.with_group([g.centre.id], group(schedules.position))
        .with_group([g.disparity.id], group(schedules.disparity))
        .with_group([g.log_size.id], group(schedules.size))
        .with_group([g.colour.id], group(schedules.colour))
}

/// Fits `g` to `views` of `scene` under `losses`; returns the fitted Gaussians and the loss of
/// each step.
/// Each step renders the same band of rows in every view (the views of the central row see a
/// point on the same row, those of the central column within a few rows of it), so that every
/// step weighs all the disparity cues; bands are taken in turn. `progress(step, total, loss)` is
/// called after each step.
pub fn fit_stage1(
    g: Gaussians,
    scene: &Scene,
    views: &[ViewId],
    fit: &Stage1Fit,
    losses: &WeightedLosses,
    device: &Device,
    mut progress: impl FnMut(usize, usize, f32),
) -> (Gaussians, Vec<f32>) {
    let (w, h) = (scene.width(), scene.height());
    assert!(!views.is_empty(), "stage 1 needs at least one view");
    let targets = view_targets(scene, views);
    let bands = row_bands(0..h, fit.band_height);
    // Band targets are cut once: `[P, C]` per (band, view).
    let band_targets: Vec<Vec<Tensor<2>>> =
        bands.iter().map(|rows| targets.iter().map(|t| band_tensor(t.image, rows.clone(), device)).collect()).collect();
    // The disparities settle: at a constant rate Adam moves each by about that rate a step up
    // to the last one, while decaying the other groups' rates leaves the colours less fitted
    // (docs/results.md).
    let schedules = GaussianSchedules {
        disparity: decaying(fit.lr.disparity, fit.disparity_final_share, fit.iterations),
        ..GaussianSchedules::constant(&fit.lr)
    };
    let default = GroupPlan { schedule: schedules.position, adam_epsilon: fit.adam_epsilon };
    let plan = with_gaussian_schedules(Plan::new(default), &g, &schedules, fit.adam_epsilon);
    let stage = Stage { iterations: fit.iterations, plan };
    // The views' gradients are taken one by one ([`mean_over_parts`]): one view's graph at a
    // time on each core.
    let objective = |g: &Gaussians, step: usize| {
        let b = step % bands.len();
        let set = g.to_set();
        let view = |g: &Gaussians, v: usize| {
            let (ViewTarget { offset, .. }, target) = (&targets[v], &band_targets[b][v]);
            let bins = bins_for_view(&set, *offset, w, bands[b].clone(), &fit.render);
            let out = render(g, *offset, &bins, device);
            let mut loss = MeanLoss::default();
            loss.add(losses.evaluate(&LossInput { rendered: &out, target, rows: bands[b].len(), width: w, motion: None }));
            loss
        };
        let (value, parts) = mean_over_parts(g, targets.len(), device, view)?;
        Some((value, weighted_sum(g, parts)))
    };
    optimise_by_gradients(g, &stage, objective, |r: StepReport| progress(r.step, r.of, r.loss))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rate_decays_to_its_final_share_at_the_last_step_or_stays_constant_at_a_share_of_one() {
        let s = decaying(0.01, 0.1, 100);
        assert!((s.at(0) - 0.01).abs() < 1e-15 && (s.at(100) - 0.001).abs() < 1e-15, "{s:?}");
        assert!(s.at(50) < s.at(49) && s.at(99) > 0.001, "falls all the way");
        assert_eq!(decaying(0.01, 1.0, 100), Schedule::Constant(0.01));
    }
}
