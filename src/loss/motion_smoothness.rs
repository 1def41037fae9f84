//! A prior on how the motion changes within the read-out: a camera's rates change smoothly over
//! the few milliseconds of one frame. It asks the motion model how far the motion is from the
//! smoothest it can express ([`MotionModel::roughness`](crate::model::motion::MotionModel::roughness));
//! for `piecewise_constant`, the second difference of the segments' rates, so a constant
//! acceleration costs nothing and a change of acceleration (jerk) does. Models without such
//! freedom (`constant_velocity`, `constant_acceleration`) give no roughness, and the term does
//! not apply to them.

use super::{LossInput, LossTerm};
use burn::tensor::Tensor;

/// `mean r²` of the motion model's roughness residuals `r`, in scaled units.
#[derive(Debug, Clone, Copy, Default)]
pub struct MotionSmoothness;

impl LossTerm for MotionSmoothness {
    fn name(&self) -> &str {
        "motion_smoothness"
    }

    fn scores_motion_only(&self) -> bool {
        true
    }

    fn evaluate(&self, input: &LossInput) -> Option<Tensor<1>> {
        let motion = input.motion?;
        let r = motion.model.roughness(motion.scaled.clone())?;
        Some((r.clone() * r).mean())
    }
}
