//! A motion model read from a table: its poses at evenly spaced times, interpolated linearly in
//! between. Placing many points (the hundreds of thousands of measured cues, each at its own
//! read-out time, several times per step) then costs the model's pose program on the table's
//! times, and a gather and a blend per point, instead of the whole program per point.
//!
//! At the fit's four samples per image row ([`crate::pipeline::pose_table`]) the pose changes by
//! about 6e-5 rad from one sample to the next at 2 rad/s over a 30 ms read-out, so the blend of
//! two rotations leaves orthonormality by about a square of that, far below `f32` precision;
//! across a piecewise model's segment boundary the blend is off by at most the rate's jump times
//! a quarter of the sample interval. Outside the table the end intervals extend linearly. The
//! tests in `tests/motion_models.rs` hold the table to the model it reads, values and gradients.

use super::{MotionModel, ParamKind};
use crate::geometry::PoseBatch;
use crate::io::MotionRecord;
use burn::tensor::{Int, Tensor};

/// `model`'s poses tabulated at `samples` times evenly spread over `span` (seconds).
#[derive(Clone, Copy)]
pub struct Tabulated<'a> {
    /// The model read.
    pub model: &'a dyn MotionModel,
    /// The first and last tabulated times, seconds.
    pub span: (f64, f64),
    /// Tabulated times, at least 2.
    pub samples: usize,
}

impl<'a> Tabulated<'a> {
    /// `model` tabulated over `span` at one sample per `step` seconds (at least two samples).
    pub fn with_step(model: &'a dyn MotionModel, span: (f64, f64), step: f64) -> Self {
        let length = (span.1 - span.0).abs();
        let samples = if step > 0.0 && length.is_finite() { (length / step).ceil() as usize + 1 } else { 2 };
        Self { model, span, samples: samples.max(2) }
    }
}

impl MotionModel for Tabulated<'_> {
    fn name(&self) -> &str {
        self.model.name()
    }

    fn parameters(&self) -> Vec<ParamKind> {
        self.model.parameters()
    }

    fn poses(&self, params: Tensor<1>, times: Tensor<1>) -> PoseBatch {
        let device = times.device();
        let s = self.samples.max(2);
        let (t0, t1) = self.span;
        let interval = (t1 - t0) / (s - 1) as f64;
        let knots = Tensor::<1, Int>::arange(0..s as i64, &device).float() * interval as f32 + t0 as f32;
        let table = self.model.poses(params, knots);
        // Each time's place in the table: the interval it falls in (the end ones beyond the
        // table) and how far along it; the gradient with respect to the time flows through the
        // fraction, as the interval's slope.
        let n = times.dims()[0];
        let place = if interval != 0.0 { (times - t0 as f32) / interval as f32 } else { times.zeros_like() };
        let lower = place.clone().detach().floor().clamp(0.0, (s - 2) as f32).int();
        let along = (place - lower.clone().float()).reshape([n, 1]);
        let blend = |rows: Tensor<2>| {
            let a = rows.clone().select(0, lower.clone());
            let b = rows.select(0, lower.clone() + 1);
            a.clone() + (b - a) * along.clone()
        };
        let rotation = blend(table.rotation.reshape([s, 9])).reshape([n, 3, 3]);
        let translation = blend(table.translation);
        PoseBatch { rotation, translation }
    }

    fn record(&self, params: &[f64]) -> MotionRecord {
        self.model.record(params)
    }

    fn parameters_of(&self, record: &MotionRecord) -> Option<Vec<f64>> {
        self.model.parameters_of(record)
    }

    fn roughness(&self, scaled: Tensor<1>) -> Option<Tensor<1>> {
        self.model.roughness(scaled)
    }
}
