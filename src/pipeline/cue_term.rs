//! The measured cues as a term of the stage-2 objective: how far the cues the current motion
//! predicts lie from those tracked between the views ([`super::measured_cues`]).
//!
//! Each cue's point (its central-view position and measured disparity, the scene at its row's
//! read-out time) is moved back to t = 0 under the motion and re-imaged, each at its own row's
//! time, into its off-row view: the same tensor program that places the Gaussians, so the
//! gradient with respect to the motion comes from the framework. The term is the mean Huber
//! penalty of the difference, in pixels. The fit hands it the model read from its pose table
//! ([`super::stage2_fit::pose_table`]), so the model's pose program runs on the table's times, not
//! on every cue at each of its fixed-point iterations.

use super::measured_cues::Cue;
use super::params_tensor;
use crate::geometry::{Camera, TensorCamera, ViewOffset};
use crate::model::motion::MotionModel;
use crate::model::{GaussianSet, Gaussians};
use crate::render::StaticShape;
use burn::module::Module;
use burn::nn::loss::{HuberLoss, HuberLossConfig};
use burn::tensor::{Device, Int, Tensor, TensorData};

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
}

/// One measured component of a cue.
struct Component {
    /// The cue it belongs to.
    point: usize,
    /// The unit image direction it is measured along.
    axis: (f64, f64),
    /// Where no motion puts the cue's point along `axis`, plus the measured cue.
    target: f64,
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
    /// The term for `cues` of a scene seen by `camera`, on `device`.
    pub fn new(cues: &[Cue], camera: &Camera, weight: f32, huber_px: f32, timing_iterations: usize, device: &Device) -> Self {
        let n = cues.len();
        // The measured components, with the point each belongs to.
        let components: Vec<Component> = cues
            .iter()
            .enumerate()
            .flat_map(|(point, c)| {
                let still = camera.grid.position_in_view(c.view, c.at.0, c.at.1, c.disparity);
                let target = (still.0 + c.offset.0, still.1 + c.offset.1);
                c.measured_axes().into_iter().map(move |(_, axis)| Component { point, axis, target: axis.0 * target.0 + axis.1 * target.1 })
            })
            .collect();
        let k = components.len();
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
        let sum = self.huber.forward_no_reduction(along, cues.target.clone()).sum();
        sum * (self.weight / self.len as f32)
    }
}

/// One value of each item as a tensor `[N]`.
fn column<T>(items: &[T], value: impl Fn(&T) -> f64, device: &Device) -> Tensor<1> {
    params_tensor(&items.iter().map(value).collect::<Vec<_>>(), device)
}
