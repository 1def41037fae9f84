//! The measured cues as a term of the stage-2 objective: how far the cues the current motion
//! predicts lie from those tracked between the views ([`super::measured_cues`]).
//!
//! Each cue's point (its central-view position and measured disparity, the scene at its row's
//! read-out time) is moved back to t = 0 under the motion and re-imaged, each at its own row's
//! time, into its off-row view: the same tensor program that places the Gaussians, so the
//! gradient with respect to the motion comes from the framework. The term is the mean Huber
//! penalty of the difference, in pixels.

use super::measured_cues::Cue;
use crate::geometry::{Camera, TensorCamera, ViewOffset};
use crate::model::motion::MotionModel;
use crate::model::{GaussianSet, Gaussians};
use crate::render::StaticShape;
use burn::module::Module;
use burn::nn::loss::{HuberLoss, HuberLossConfig};
use burn::tensor::{Device, Tensor, TensorData};

/// The measured cues as tensors, all views together.
struct CuePoints {
    /// The cue points as zero-size Gaussians of the central view (no gradient).
    points: Gaussians,
    /// Each point's off-row view.
    views: ViewOffset,
    /// Where no motion puts each point in its view, plus its measured cue: `[N]` each way.
    target_u: Tensor<1>,
    target_v: Tensor<1>,
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
        let tensor =
            |f: &dyn Fn(&Cue) -> f64| Tensor::<1>::from_data(TensorData::new(cues.iter().map(|c| f(c) as f32).collect(), [n]), device);
        let still = |c: &Cue| camera.grid.position_in_view(c.view, c.at.0, c.at.1, c.disparity);
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
                views: ViewOffset::PerPoint(tensor(&|c| camera.grid.offset(c.view).0), tensor(&|c| camera.grid.offset(c.view).1)),
                target_u: tensor(&|c| still(c).0 + c.offset.0),
                target_v: tensor(&|c| still(c).1 + c.offset.1),
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
        let sum = self.huber.forward_no_reduction(splats.u, cues.target_u.clone()).sum()
            + self.huber.forward_no_reduction(splats.v, cues.target_v.clone()).sum();
        sum * (self.weight / self.len as f32)
    }
}
