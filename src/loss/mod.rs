//! Loss terms: one trait, one file per term, and a registry that maps the names a config lists
//! (`[[loss]] kind = "l1"`) to constructors. A new term is a new file plus one `register` line
//! (or, outside the crate, one `LossRegistry::register` call: see `examples/custom_loss.rs`).
//!
//! Every term sees one rendered band of rows of one view ([`LossInput`]); a stage averages the
//! weighted sum of the terms over the bands and views of a step.

mod dssim;
mod l1;
mod l2;
mod motion_prior;
mod motion_smoothness;
mod registry;
mod smoothness;
#[cfg(test)]
mod tests;

pub use dssim::DSsim;
pub use l1::L1;
pub use l2::L2;
pub use motion_prior::MotionPrior;
pub use motion_smoothness::MotionSmoothness;
pub use registry::{LossRegistry, UnknownLoss, WeightedLoss, WeightedLosses};
pub use smoothness::EdgeAwareSmoothness;

use crate::model::motion::MotionModel;
use crate::render::RenderOutput;
use burn::tensor::Tensor;
use std::fmt;

/// What a loss term may look at: one band of `rows x width` pixels of one view.
#[derive(Debug, Clone)]
pub struct LossInput<'a> {
    /// The render of the band.
    pub rendered: &'a RenderOutput,
    /// The observed pixels of the band, `[P, C]`, row-major.
    pub target: &'a Tensor<2>,
    /// Rows in the band.
    pub rows: usize,
    /// Pixels per row.
    pub width: usize,
    /// The motion being fitted (`None` in stages without motion, and in stage 2's Newton steps
    /// when the measured cues are in their objective).
    pub motion: Option<MotionInput<'a>>,
}

/// The motion a loss term may look at: its parameters and the model that reads them.
#[derive(Clone, Copy)]
pub struct MotionInput<'a> {
    /// The parameter vector `[P]`, scaled so that one unit moves the image by about one pixel
    /// over the read-out.
    pub scaled: &'a Tensor<1>,
    /// The motion model the parameters belong to.
    pub model: &'a dyn MotionModel,
}

impl fmt::Debug for MotionInput<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("MotionInput").field("scaled", self.scaled).field("model", &self.model.name()).finish()
    }
}

/// One term of the objective.
pub trait LossTerm: Send + Sync {
    /// The registry name (`l1`, `smoothness`, ...).
    fn name(&self) -> &str;

    /// The term's value for one band (a one-element tensor), or `None` when it does not apply
    /// (e.g. a motion prior in a stage without motion).
    fn evaluate(&self, input: &LossInput) -> Option<Tensor<1>>;

    /// Whether the term scores the motion alone (a prior on it), so that it has nothing to score
    /// in stage 1, which fits no motion: such a term is left out of stage 1's objective and log.
    fn scores_motion_only(&self) -> bool {
        false
    }
}

/// `[P, C]` band pixels as `[1, C, rows, width]` images, for window operations.
pub(crate) fn as_image(t: Tensor<2>, rows: usize, width: usize) -> Tensor<4> {
    let c = t.dims()[1];
    t.reshape([rows, width, c]).permute([2, 0, 1]).unsqueeze::<4>()
}
