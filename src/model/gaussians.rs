//! The scene model of stage 1: N isotropic 2D Gaussians on the central view, five parameters
//! each (centre u, v; disparity; size; intensity or colour), as a burn `Module`.

use crate::device::host_values;
use burn::module::{Module, Param};
use burn::tensor::{Device, Tensor, TensorData};

/// The Gaussians as trainable parameters. Size is stored as its logarithm so that it stays
/// positive and its steps are relative.
#[derive(Module, Debug)]
pub struct Gaussians {
    /// Centres `(u, v)` on the central view, pixels: `[N, 2]`.
    pub centre: Param<Tensor<2>>,
    /// Disparity, pixels (FORMAT sign): `[N]`.
    pub disparity: Param<Tensor<1>>,
    /// `ln σ`, σ the standard deviation in pixels: `[N]`.
    pub log_size: Param<Tensor<1>>,
    /// Intensity (1 channel) or colour (3 channels): `[N, C]`.
    pub colour: Param<Tensor<2>>,
}

/// The same Gaussians on the host, for the discrete bookkeeping, saving and inspection.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GaussianSet {
    /// `u` per Gaussian.
    pub u: Vec<f32>,
    /// `v` per Gaussian.
    pub v: Vec<f32>,
    /// Disparity per Gaussian.
    pub disparity: Vec<f32>,
    /// σ per Gaussian, pixels.
    pub size: Vec<f32>,
    /// `channels` values per Gaussian, interleaved.
    pub colour: Vec<f32>,
    /// 1 or 3.
    pub channels: usize,
}

impl GaussianSet {
    /// Number of Gaussians.
    pub fn len(&self) -> usize {
        self.u.len()
    }

    /// `true` when there are none.
    pub fn is_empty(&self) -> bool {
        self.u.is_empty()
    }

    /// The trainable module on `device`.
    pub fn to_module(&self, device: &Device) -> Gaussians {
        let n = self.len();
        let centre: Vec<f32> = self.u.iter().zip(&self.v).flat_map(|(&u, &v)| [u, v]).collect();
        let log_size: Vec<f32> = self.size.iter().map(|s| s.ln()).collect();
        Gaussians {
            centre: Param::from_data(TensorData::new(centre, [n, 2]), device),
            disparity: Param::from_data(TensorData::new(self.disparity.clone(), [n]), device),
            log_size: Param::from_data(TensorData::new(log_size, [n]), device),
            colour: Param::from_data(TensorData::new(self.colour.clone(), [n, self.channels]), device),
        }
    }
}

impl Gaussians {
    /// Number of Gaussians.
    pub fn len(&self) -> usize {
        self.disparity.val().dims()[0]
    }

    /// `true` when there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Colour channels.
    pub fn channels(&self) -> usize {
        self.colour.val().dims()[1]
    }

    /// A host copy of the current values.
    pub fn to_set(&self) -> GaussianSet {
        let centre = host_values(self.centre.val());
        GaussianSet {
            u: centre.iter().step_by(2).copied().collect(),
            v: centre.iter().skip(1).step_by(2).copied().collect(),
            disparity: host_values(self.disparity.val()),
            size: host_values(self.log_size.val()).into_iter().map(f32::exp).collect(),
            colour: host_values(self.colour.val()),
            channels: self.channels(),
        }
    }
}
