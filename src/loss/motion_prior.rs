//! A prior on the motion: small motions are more likely. The parameters are scaled so that one
//! unit moves the image by about one pixel over the read-out, so the prior weighs every
//! direction by its image effect; it settles the directions the images barely observe (a static
//! scene stays static instead of drifting along them).

use super::{LossInput, LossTerm};
use burn::tensor::Tensor;

/// `mean x²` of the scaled motion parameters `x`.
#[derive(Debug, Clone, Copy, Default)]
pub struct MotionPrior;

impl LossTerm for MotionPrior {
    fn name(&self) -> &str {
        "motion_prior"
    }

    fn scores_motion_only(&self) -> bool {
        true
    }

    fn evaluate(&self, input: &LossInput) -> Option<Tensor<1>> {
        input.motion.map(|m| (m.scaled.clone() * m.scaled.clone()).mean())
    }
}
