//! Edge-aware disparity smoothness: disparity gradients cost less where the observed image has
//! an edge, so depth may jump at object boundaries but not inside surfaces.

use super::{LossInput, LossTerm};
use burn::tensor::Tensor;

/// Intensity difference at which the edge weight falls to 1/e.
const EDGE_SCALE: f32 = 0.05;
/// Opacity added under the division that normalises blended disparity.
const ALPHA_FLOOR: f32 = 1e-3;

/// `mean w |∂d|` over horizontal and vertical neighbours of the rendered (opacity-normalised)
/// disparity, with `w = exp(-|∂I| / EDGE_SCALE)` from the observed image.
#[derive(Debug, Clone, Copy, Default)]
pub struct EdgeAwareSmoothness;

impl LossTerm for EdgeAwareSmoothness {
    fn name(&self) -> &str {
        "smoothness"
    }

    fn evaluate(&self, input: &LossInput) -> Option<Tensor<1>> {
        let (h, w) = (input.rows, input.width);
        if h < 2 || w < 2 {
            return None;
        }
        let out = input.rendered;
        let d = (out.disparity.clone() / (out.alpha.clone() + ALPHA_FLOOR)).reshape([h, w]);
        let c = input.target.dims()[1];
        let image = input.target.clone().reshape([h, w, c]);
        let horizontal = |t: Tensor<2>| t.clone().slice([0..h, 1..w]) - t.slice([0..h, 0..w - 1]);
        let vertical = |t: Tensor<2>| t.clone().slice([1..h, 0..w]) - t.slice([0..h - 1, 0..w]);
        let edge_h =
            (image.clone().slice([0..h, 1..w, 0..c]) - image.clone().slice([0..h, 0..w - 1, 0..c])).abs().mean_dim(2).reshape([h, w - 1]);
        let edge_v = (image.clone().slice([1..h, 0..w, 0..c]) - image.slice([0..h - 1, 0..w, 0..c])).abs().mean_dim(2).reshape([h - 1, w]);
        let weight = |e: Tensor<2>| (e / -EDGE_SCALE).exp();
        let term_h = (horizontal(d.clone()).abs() * weight(edge_h)).mean();
        let term_v = (vertical(d).abs() * weight(edge_v)).mean();
        Some((term_h + term_v) / 2.0)
    }
}
