//! The measured cues as a term of the stage-2 objective: how far the cues the current motion
//! predicts lie from those tracked between the views ([`super::measured_cues`]).
//!
//! Each cue's point (its central-view position and measured disparity, the scene at its row's
//! read-out time) is moved back to t = 0 under the motion and re-imaged, each at its own row's
//! time, into its off-row view: the same tensor program that places the Gaussians, so the
//! gradient with respect to the motion comes from the framework. The term is the mean Huber
//! penalty of the difference, in pixels.

use super::measured_cues::Cue;
use crate::geometry::{Camera, TensorCamera};
use crate::model::GaussianSet;
use crate::model::motion::MotionModel;
use crate::render::StaticShape;
use burn::module::Module;
use burn::nn::loss::{HuberLoss, HuberLossConfig};
use burn::tensor::{Device, Tensor, TensorData};

/// The measured cues of one off-row view, as tensors.
struct ViewCues {
    /// The cue points as zero-size Gaussians of the central view (no gradient).
    points: crate::model::Gaussians,
    /// The view offset `(c - cc, r - rc)`.
    offset: (f32, f32),
    /// Where no motion puts each point in the view, plus its measured cue: `[N]` each way.
    target_u: Tensor<1>,
    target_v: Tensor<1>,
}

/// The measured-cue term of stage 2.
pub struct CueTerm {
    views: Vec<ViewCues>,
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
        // The cues grouped by view in one sort (stable: each view's cues keep their order).
        let mut sorted: Vec<&Cue> = cues.iter().collect();
        sorted.sort_by_key(|c| c.view);
        let per_view = sorted
            .chunk_by(|x, y| x.view == y.view)
            .map(|mine| {
                let (view, n) = (mine[0].view, mine.len());
                let set = GaussianSet {
                    u: mine.iter().map(|c| c.at.0 as f32).collect(),
                    v: mine.iter().map(|c| c.at.1 as f32).collect(),
                    disparity: mine.iter().map(|c| c.disparity as f32).collect(),
                    size: vec![1.0; n],
                    colour: vec![0.0; n],
                    channels: 1,
                };
                let still: Vec<(f64, f64)> = mine.iter().map(|c| camera.grid.position_in_view(view, c.at.0, c.at.1, c.disparity)).collect();
                let target = |k: usize| {
                    let data: Vec<f32> = mine
                        .iter()
                        .zip(&still)
                        .map(|(c, s)| if k == 0 { (s.0 + c.offset.0) as f32 } else { (s.1 + c.offset.1) as f32 })
                        .collect();
                    Tensor::<1>::from_data(TensorData::new(data, [n]), device)
                };
                let (a, b) = camera.grid.offset(view);
                ViewCues { points: set.to_module(device).no_grad(), offset: (a as f32, b as f32), target_u: target(0), target_v: target(1) }
            })
            .collect();
        Self { views: per_view, weight, huber: HuberLossConfig::new(huber_px).init(), timing_iterations, len: cues.len() }
    }

    /// The weighted mean Huber penalty of the cues predicted by `model` at `params` (SI) against
    /// the measured ones: a one-element tensor.
    pub fn evaluate(&self, camera: TensorCamera, model: &dyn MotionModel, params: Tensor<1>) -> Tensor<1> {
        let mut total: Option<Tensor<1>> = None;
        for view in &self.views {
            let shape = StaticShape::new(&view.points, camera, model, params.clone());
            let splats = shape.splats_rolling(model, params.clone(), view.offset, self.timing_iterations);
            let sum = self.huber.forward_no_reduction(splats.u, view.target_u.clone()).sum()
                + self.huber.forward_no_reduction(splats.v, view.target_v.clone()).sum();
            total = Some(match total {
                Some(t) => t + sum,
                None => sum,
            });
        }
        let device = params.device();
        total.unwrap_or_else(|| Tensor::zeros([1], &device)) * (self.weight / self.len.max(1) as f32)
    }
}
