//! Structural dissimilarity `(1 - SSIM) / 2` over 3x3 windows.

use super::{LossInput, LossTerm, as_image};
use burn::tensor::Tensor;
use burn::tensor::module::avg_pool2d;
use burn::tensor::ops::AvgPoolOptions;

/// SSIM stabilisers for intensities in [0, 1].
const C1: f32 = 0.01 * 0.01;
const C2: f32 = 0.03 * 0.03;

/// D-SSIM with 3x3 box windows inside the band (bands shorter than 3 rows give `None`).
#[derive(Debug, Clone, Copy, Default)]
pub struct DSsim;

impl LossTerm for DSsim {
    fn name(&self) -> &str {
        "dssim"
    }

    fn evaluate(&self, input: &LossInput) -> Option<Tensor<1>> {
        if input.rows < 3 || input.width < 3 {
            return None;
        }
        let x = as_image(input.rendered.colour.clone(), input.rows, input.width);
        let y = as_image(input.target.clone(), input.rows, input.width);
        let mean = |t: Tensor<4>| avg_pool2d(t, AvgPoolOptions::new([3, 3]).with_stride([1, 1]));
        let (mx, my) = (mean(x.clone()), mean(y.clone()));
        let sxx = mean(x.clone() * x.clone()) - mx.clone() * mx.clone();
        let syy = mean(y.clone() * y.clone()) - my.clone() * my.clone();
        let sxy = mean(x * y) - mx.clone() * my.clone();
        let num = (mx.clone() * my.clone() * 2.0 + C1) * (sxy * 2.0 + C2);
        let den = (mx.clone() * mx + my.clone() * my + C1) * (sxx + syy + C2);
        let ssim = num / den;
        Some((ssim.neg() + 1.0).mean() / 2.0)
    }
}
