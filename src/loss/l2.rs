//! Photometric L2: mean squared colour difference.

use super::{LossInput, LossTerm};
use burn::tensor::Tensor;

/// `mean (rendered - observed)²` over the band's pixels and channels.
#[derive(Debug, Clone, Copy, Default)]
pub struct L2;

impl LossTerm for L2 {
    fn name(&self) -> &str {
        "l2"
    }

    fn evaluate(&self, input: &LossInput) -> Option<Tensor<1>> {
        let diff = input.rendered.colour.clone() - input.target.clone();
        Some((diff.clone() * diff).mean())
    }
}
