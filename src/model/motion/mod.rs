//! Motion models: the rigid pose of the scene at time t, as burn tensor programs of a flat
//! parameter vector, behind one trait; a registry maps the config's `[motion] model = "..."` to
//! a constructor. A new model is a new file plus one `register` line (or, outside the crate, one
//! `MotionRegistry::register` call: see `examples/custom_motion.rs`).

mod constant_acceleration;
mod constant_velocity;
mod piecewise_constant;
mod registry;
mod tabulated;

pub use constant_acceleration::ConstantAcceleration;
pub use constant_velocity::ConstantVelocity;
pub use piecewise_constant::PiecewiseConstant;
pub use registry::{MotionConstructor, MotionRegistry, MotionSetup, UnknownMotion};
pub use tabulated::Tabulated;

use crate::geometry::PoseBatch;
use crate::io::MotionRecord;
use burn::module::{Module, Param};
use burn::tensor::{Device, Tensor, TensorData};

/// What one entry of a model's parameter vector measures; it sets the entry's scale (the
/// change that moves the image by about one pixel over half the read-out).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParamKind {
    /// Rotation (rad/s, rad/s², ...) or translation (m/s, m/s², ...).
    pub quantity: Quantity,
    /// Time derivative: 1 for a velocity, 2 for an acceleration.
    pub order: u32,
    /// Axis of the central camera frame: 0 = X, 1 = Y, 2 = Z.
    pub axis: usize,
}

/// Rotation or translation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Radians per second (per second, ...).
    Rotation,
    /// Metres per second (per second, ...).
    Translation,
}

impl ParamKind {
    /// The three entries `[X, Y, Z]` of a rotation or translation rate of `order`.
    pub fn xyz(quantity: Quantity, order: u32) -> [ParamKind; 3] {
        [0, 1, 2].map(|axis| ParamKind { quantity, order, axis })
    }

    /// `[ω, v]`: angular then linear velocity, six entries.
    pub fn velocities() -> Vec<ParamKind> {
        [Self::xyz(Quantity::Rotation, 1), Self::xyz(Quantity::Translation, 1)].concat()
    }
}

/// A motion model: `P(t) = R(t) P0 + T(t)` for a point `P0` at t = 0 (central camera frame at
/// t = 0, FORMAT's convention), with the pose a differentiable function of the parameters.
pub trait MotionModel: Send + Sync {
    /// The registry name; also the `model` written to `motion.toml` when the model is one of
    /// FORMAT's.
    fn name(&self) -> &str;

    /// The kind of each entry of the parameter vector, in order.
    fn parameters(&self) -> Vec<ParamKind>;

    /// The poses at `times` (`[N]`, seconds) for the parameter vector `params` (`[P]`, SI
    /// units): rotations `[N, 3, 3]`, translations `[N, 3]`.
    fn poses(&self, params: Tensor<1>, times: Tensor<1>) -> PoseBatch;

    /// The motion file of a parameter vector.
    fn record(&self, params: &[f64]) -> MotionRecord;

    /// The parameter vector of a motion file, when this model can express it exactly.
    fn parameters_of(&self, record: &MotionRecord) -> Option<Vec<f64>>;

    /// How far a motion is from the smoothest this model can express, as residuals that vanish
    /// on those (the `motion_smoothness` loss term's `mean r²`): `piecewise_constant`'s second
    /// differences of its segments' rates, zero when the rates change linearly in time. `scaled`
    /// is the scaled parameter vector `[P]`; a residual combines entries of one [`ParamKind`]
    /// only, so it reads in that kind's scaled units. `None` (the default): the model has no
    /// freedom beyond its smoothest motions.
    fn roughness(&self, scaled: Tensor<1>) -> Option<Tensor<1>> {
        let _ = scaled;
        None
    }
}

/// The trainable motion: a parameter vector in scaled units (one unit ≈ one pixel of image
/// effect over the read-out), so that Adam's steps weigh every direction alike.
#[derive(Module, Debug)]
pub struct MotionParams {
    /// Scaled parameters, `[P]`.
    pub scaled: Param<Tensor<1>>,
}

impl MotionParams {
    /// Scaled parameters with the SI values `values` and per-entry `scales`.
    pub fn new(values: &[f64], scales: &[f64], device: &Device) -> Self {
        let scaled: Vec<f32> = values.iter().zip(scales).map(|(v, s)| (v / s) as f32).collect();
        let n = scaled.len();
        Self { scaled: Param::from_data(TensorData::new(scaled, [n]), device) }
    }

    /// The SI parameter vector as a tensor: `scaled * scales`.
    pub fn si(&self, scales: &[f64]) -> Tensor<1> {
        Self::to_si(self.scaled.val(), scales)
    }

    /// The SI values of a scaled parameter vector `[P]` (on its autodiff graph, if any).
    pub fn to_si(scaled: Tensor<1>, scales: &[f64]) -> Tensor<1> {
        let s: Vec<f32> = scales.iter().map(|&s| s as f32).collect();
        let n = s.len();
        let device = scaled.device();
        scaled * Tensor::<1>::from_data(TensorData::new(s, [n]), &device)
    }

    /// The SI parameter vector on the host.
    pub fn si_values(&self, scales: &[f64]) -> Vec<f64> {
        let v = crate::device::host_values(self.scaled.val());
        v.iter().zip(scales).map(|(&x, s)| x as f64 * s).collect()
    }
}

/// Where the scale of the parameters comes from: the image and the scene's typical depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaleContext {
    /// Focal length, pixels.
    pub f_px: f64,
    /// Half the image diagonal, pixels (the lever arm of rotation about and motion along Z).
    pub half_diagonal_px: f64,
    /// Typical depth of the scene, metres.
    pub depth_m: f64,
    /// Half the read-out time, seconds.
    pub half_readout_s: f64,
}

/// The scale of each parameter: the value that moves the image of a point at the typical depth
/// by about one pixel over half the read-out. Rotation about X or Y moves every pixel by
/// `f ω t`; about Z, a pixel at radius r by `r ω t`. Translation along X or Y moves it by
/// `f v t / Z`; along Z, by `r v t / Z`. An acceleration acts over `t² / 2`.
pub fn parameter_scales(kinds: &[ParamKind], ctx: &ScaleContext) -> Vec<f64> {
    let t = ctx.half_readout_s.max(1e-9);
    kinds
        .iter()
        .map(|k| {
            let lever = if k.axis == 2 { ctx.half_diagonal_px } else { ctx.f_px };
            let per_unit = match k.quantity {
                Quantity::Rotation => lever,
                Quantity::Translation => lever / ctx.depth_m,
            };
            let time = (1..=k.order).fold(1.0, |acc, i| acc * t / i as f64);
            1.0 / (per_unit * time)
        })
        .collect()
}

/// Entries `at..at + 3` of a parameter vector as a `[1, 3]` row.
pub fn vec3(params: &Tensor<1>, at: usize) -> Tensor<2> {
    params.clone().slice(at..at + 3).reshape([1, 3])
}

/// `times ⊗ row`: `[N]` times a `[1, 3]` row gives `[N, 3]`.
pub fn scale_rows(times: &Tensor<1>, row: Tensor<2>) -> Tensor<2> {
    let n = times.dims()[0];
    times.clone().reshape([n, 1]) * row
}

/// Three SI values from a host vector.
pub fn three(v: &[f64], at: usize) -> [f64; 3] {
    [v[at], v[at + 1], v[at + 2]]
}
