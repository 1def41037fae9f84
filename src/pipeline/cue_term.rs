//! The measured cues as a term of the stage-2 objective: how far the cues the current motion
//! predicts lie from those tracked between the views ([`super::measured_cues`]).
//!
//! Each cue's point (its central-view position and measured disparity, the scene at its row's
//! read-out time) is moved back to t = 0 under the motion and re-imaged, each at its own row's
//! time, into its off-row view: the same tensor program that places the Gaussians, so the
//! gradient with respect to the motion comes from the framework. The term is the weighted mean
//! Huber penalty of the difference, in pixels: a cue whose matches leave more of its patch's
//! contrast unexplained than the median is weighted down by the inverse square of that share
//! ([`residual_weights`]). The fit hands it the model read from its pose table
//! ([`super::stage2_fit::pose_table`]), so the model's pose program runs on the table's times, not
//! on every cue at each of its fixed-point iterations.

use super::measured_cues::{Cue, median_two_way_residual};
use super::params_tensor;
use crate::geometry::{Camera, TensorCamera, ViewOffset};
use crate::model::motion::MotionModel;
use crate::model::{GaussianSet, Gaussians};
use crate::render::StaticShape;
use burn::module::Module;
use burn::nn::loss::{HuberLoss, HuberLossConfig};
use burn::tensor::{Device, Int, Tensor, TensorData};

/// Each cue's weight in the term, relative to a cue of the median residual `m` of the patches
/// textured both ways: `min(1, (m / r)²)` for a cue of residual `r` (its [`Cue::residual`]).
/// A match's error grows with the share of its patch it leaves unexplained (a texture finer
/// than the pixels, two depths in one patch), and the inverse square of that share is the
/// least-squares weight of a noise in proportion to it. Only the cues above the median are
/// weighted down: the cleanest matches are not the surest (on a still `objects` scene the fifth
/// of the cues with the lowest residual has the best median miss and the heaviest tail, a 95th
/// percentile of 0.25 px against 0.13-0.18 px for the other fifths), and weighing them up as
/// well, to four times a median cue, cost the fast scenes of the 256 px suite (a moving mean of
/// 0.135 px against 0.126 px weighed down only, 0.131 px unweighted; docs/results.md). All
/// ones where no patch is textured both ways.
pub fn residual_weights(cues: &[Cue]) -> Vec<f64> {
    let Some(median) = median_two_way_residual(cues).filter(|&m| m > 0.0) else { return vec![1.0; cues.len()] };
    cues.iter().map(|c| (median / c.residual.max(median)).powi(2)).collect()
}

/// The measured cues as tensors, all views together.
struct CuePoints {
    /// The cue points as zero-size Gaussians of the central view (no gradient).
    points: Gaussians,
    /// Each point's off-row view.
    views: ViewOffset,
    /// The measured components, `[K]` each ([`Cue::measured_axes`]: two for a patch textured
    /// both ways, one across an edge or a stripe): the point each belongs to, its unit image
    /// direction, and where no motion puts the point along it plus the measured cue.
    point: Tensor<1, Int>,
    axis_u: Tensor<1>,
    axis_v: Tensor<1>,
    target: Tensor<1>,
    /// Each component's weight ([`residual_weights`], scaled to a mean of one over them).
    weight: Tensor<1>,
}

/// One measured component of a cue.
struct Component {
    /// The cue it belongs to.
    point: usize,
    /// The unit image direction it is measured along.
    axis: (f64, f64),
    /// Where no motion puts the cue's point along `axis`, plus the measured cue.
    target: f64,
    /// Its cue's weight.
    weight: f64,
}

/// The measured-cue term of stage 2.
pub struct CueTerm {
    /// `None` with no cues.
    cues: Option<CuePoints>,
    /// Its weight in the objective.
    pub weight: f32,
    /// The penalty: quadratic within its threshold (px), linear beyond.
    huber: HuberLoss,
    /// Fixed-point iterations of each point's read-out time.
    pub timing_iterations: usize,
    /// Number of cues.
    pub len: usize,
}

impl CueTerm {
    /// The term for `cues` of a scene seen by `camera`, on `device`; with `weighed`, each cue
    /// weighs its [`residual_weights`], else all alike.
    pub fn new(
        cues: &[Cue],
        camera: &Camera,
        weight: f32,
        huber_px: f32,
        timing_iterations: usize,
        weighed: bool,
        device: &Device,
    ) -> Self {
        let n = cues.len();
        let weights = if weighed { residual_weights(cues) } else { vec![1.0; n] };
        // The measured components, with the point each belongs to.
        let components: Vec<Component> = cues
            .iter()
            .zip(weights)
            .enumerate()
            .flat_map(|(point, (c, weight))| {
                let still = camera.grid.position_in_view(c.view, c.at.0, c.at.1, c.disparity);
                let target = (still.0 + c.offset.0, still.1 + c.offset.1);
                c.measured_axes().into_iter().map(move |(_, axis)| Component {
                    point,
                    axis,
                    target: axis.0 * target.0 + axis.1 * target.1,
                    weight,
                })
            })
            .collect();
        let k = components.len();
        let mean_weight = components.iter().map(|c| c.weight).sum::<f64>() / k.max(1) as f64;
        let points = (n > 0).then(|| {
            let set = GaussianSet {
                u: cues.iter().map(|c| c.at.0 as f32).collect(),
                v: cues.iter().map(|c| c.at.1 as f32).collect(),
                disparity: cues.iter().map(|c| c.disparity as f32).collect(),
                size: vec![1.0; n],
                colour: vec![0.0; n],
                channels: 1,
            };
            CuePoints {
                points: set.to_module(device).no_grad(),
                views: ViewOffset::PerPoint(
                    column(cues, |c| camera.grid.offset(c.view).0, device),
                    column(cues, |c| camera.grid.offset(c.view).1, device),
                ),
                point: Tensor::<1, Int>::from_data(TensorData::new(components.iter().map(|c| c.point as i64).collect(), [k]), device),
                axis_u: column(&components, |c| c.axis.0, device),
                axis_v: column(&components, |c| c.axis.1, device),
                target: column(&components, |c| c.target, device),
                weight: column(&components, |c| c.weight / mean_weight, device),
            }
        });
        Self { cues: points, weight, huber: HuberLossConfig::new(huber_px).init(), timing_iterations, len: n }
    }

    /// The weighted mean Huber penalty of the cues predicted by `model` at `params` (SI) against
    /// the measured ones: a one-element tensor.
    pub fn evaluate(&self, camera: TensorCamera, model: &dyn MotionModel, params: Tensor<1>) -> Tensor<1> {
        let Some(cues) = &self.cues else { return Tensor::zeros([1], &params.device()) };
        let shape = StaticShape::new(&cues.points, camera, model, params.clone());
        let splats = shape.splats_rolling(model, params, cues.views.clone(), self.timing_iterations);
        let along =
            splats.u.select(0, cues.point.clone()) * cues.axis_u.clone() + splats.v.select(0, cues.point.clone()) * cues.axis_v.clone();
        let sum = (self.huber.forward_no_reduction(along, cues.target.clone()) * cues.weight.clone()).sum();
        sum * (self.weight / self.len as f32)
    }
}

/// One value of each item as a tensor `[N]`.
fn column<T>(items: &[T], value: impl Fn(&T) -> f64, device: &Device) -> Tensor<1> {
    params_tensor(&items.iter().map(value).collect::<Vec<_>>(), device)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::ViewId;

    fn cue(residual: f64, across: Option<(f64, f64)>) -> Cue {
        Cue { at: (10.0, 10.0), disparity: 0.5, view: ViewId { row: 0, col: 0 }, offset: (0.0, 0.0), across, residual }
    }

    #[test]
    fn a_cue_above_the_median_residual_weighs_the_inverse_square_of_its_share_of_it() {
        // Two-way residuals 0.05, 0.1, 0.2 (median 0.2: the upper of an even count) and 0.4; an
        // edge at 0.8 is weighed on the same scale but does not count towards the median.
        let cues = [cue(0.4, None), cue(0.05, None), cue(0.1, None), cue(0.2, None), cue(0.8, Some((1.0, 0.0)))];
        let weights = residual_weights(&cues);
        let expected = [0.25, 1.0, 1.0, 1.0, 0.0625];
        for (w, e) in weights.iter().zip(expected) {
            assert!((w - e).abs() < 1e-12, "{weights:?}");
        }
        // Edges only: nothing to scale by, every cue weighs the same.
        assert_eq!(residual_weights(&[cue(0.3, Some((0.0, 1.0))), cue(0.1, Some((0.0, 1.0)))]), vec![1.0, 1.0]);
    }
}
