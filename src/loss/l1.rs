//! Photometric L1: mean absolute colour difference.

use super::{LossInput, LossTerm};
use burn::tensor::Tensor;

/// `mean |rendered - observed|` over the band's pixels and channels.
#[derive(Debug, Clone, Copy, Default)]
pub struct L1;

impl LossTerm for L1 {
    fn name(&self) -> &str {
        "l1"
    }

    fn evaluate(&self, input: &LossInput) -> Option<Tensor<1>> {
        Some((input.rendered.colour.clone() - input.target.clone()).abs().mean())
    }
}
