//! The rolling-shutter deformation of the scene model (the paper's Eqs. 2-3), as tensor programs.
//!
//! Each Gaussian was observed in the central view at the read-out time of its row. Lifted to 3D
//! and moved back to t = 0 by the inverse pose, it gives the static shape ([`StaticShape`]). A view
//! is then rendered either
//! - band by band ([`RsTiming::Bands`]): every Gaussian moved to the read-out time of the band's
//!   centre row, projected, and the band's rows rendered (the paper's scheme); or
//! - in one pass ([`RsTiming::PerGaussian`]): each Gaussian moved to the time of the row where
//!   it lands in that view, found by a short fixed-point iteration.

use super::splat::{RenderOutput, RenderSettings, Splats, splat};
use crate::geometry::{TensorCamera, ViewOffset};
use crate::model::Gaussians;
use crate::model::motion::MotionModel;
use burn::tensor::{Device, Tensor};
use std::ops::Range;

/// How read-out time is assigned when rendering a rolling-shutter view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RsTiming {
    /// All Gaussians at the time of each band's centre row; bands of this many rows.
    Bands(usize),
    /// Each Gaussian at the time of its own row, this many fixed-point iterations.
    PerGaussian(usize),
}

/// The Gaussians as 3D blobs at t = 0, for one value of the motion parameters.
#[derive(Debug, Clone)]
pub struct StaticShape {
    /// Centres at t = 0, central camera frame, metres: `[N, 3]`.
    pub points: Tensor<2>,
    /// Radius in metres (`σ Z / f`), so that the size in a view is `σ_m f / Z`: `[N]`.
    pub radius_m: Tensor<1>,
    /// Colour: `[N, C]`.
    pub colour: Tensor<2>,
    /// The camera constants.
    pub camera: TensorCamera,
}

impl StaticShape {
    /// Lifts the central-view Gaussians `g` and moves each back from the time of its row to
    /// t = 0 with `model` at parameters `params` (SI).
    pub fn new(g: &Gaussians, camera: TensorCamera, model: &dyn MotionModel, params: Tensor<1>) -> Self {
        let n = g.len();
        let centre = g.centre.val();
        let u = centre.clone().slice([0..n, 0..1]).reshape([n]);
        let v = centre.slice([0..n, 1..2]).reshape([n]);
        let d = g.disparity.val();
        let observed = camera.lift(u, v.clone(), d.clone());
        let z = camera.depth(d);
        let pose = model.poses(params, camera.row_time(v));
        Self { points: pose.apply_inverse(observed), radius_m: g.log_size.val().exp() * z / camera.f_px, colour: g.colour.val(), camera }
    }

    /// The splats of the view at `offset = (c - cc, r - rc)` (or each Gaussian's own view) with
    /// every Gaussian at its own time `times` (`[N]`, seconds).
    pub fn splats_at(&self, model: &dyn MotionModel, params: Tensor<1>, offset: impl Into<ViewOffset>, times: Tensor<1>) -> Splats {
        let moved = model.poses(params, times).apply(self.points.clone());
        let n = moved.dims()[0];
        let z = moved.clone().slice([0..n, 2..3]).reshape([n]);
        let (u, v, disparity) = self.camera.project(moved, offset);
        Splats { u, v, disparity, sigma: self.radius_m.clone() * self.camera.f_px / z, colour: self.colour.clone() }
    }

    /// The splats of the view at `offset`, all Gaussians at time `tau`.
    pub fn splats_at_time(&self, model: &dyn MotionModel, params: Tensor<1>, offset: impl Into<ViewOffset>, tau: f32) -> Splats {
        let n = self.points.dims()[0];
        let times = Tensor::<1>::full([n], tau, &self.points.device());
        self.splats_at(model, params, offset, times)
    }

    /// The splats of the view at `offset`, each Gaussian at the read-out time of the row where
    /// it lands: `y <- v(P(t(y)))`, `iterations` times from the row it has at t = 0.
    pub fn splats_rolling(&self, model: &dyn MotionModel, params: Tensor<1>, offset: impl Into<ViewOffset>, iterations: usize) -> Splats {
        let offset = offset.into();
        let (_, mut row, _) = self.camera.project(self.points.clone(), offset.clone());
        for _ in 0..iterations {
            let s = self.splats_at(model, params.clone(), offset.clone(), self.camera.row_time(row));
            row = s.v;
        }
        self.splats_at(model, params, offset, self.camera.row_time(row))
    }
}

/// `rows` cut into consecutive bands of `height` rows (at least one), the last one shorter
/// where they do not divide.
pub fn row_bands(rows: Range<usize>, height: usize) -> Vec<Range<usize>> {
    let height = height.max(1);
    (rows.start..rows.end).step_by(height).map(|y| y..(y + height).min(rows.end)).collect()
}

/// The bands of `rows` for `timing`: row ranges, each with the read-out time of its centre row
/// (`None` for per-Gaussian timing, where one set of splats serves all rows).
pub fn bands(rows: Range<usize>, timing: RsTiming, camera: &TensorCamera) -> Vec<(Range<usize>, Option<f32>)> {
    match timing {
        RsTiming::Bands(height) => row_bands(rows, height)
            .into_iter()
            .map(|r| {
                let centre = (r.start + r.end - 1) as f32 / 2.0;
                (r, Some((centre - camera.v0) * camera.line_time_s))
            })
            .collect(),
        RsTiming::PerGaussian(_) => vec![(rows, None)],
    }
}

/// The part of a view to render: the view's offset `(c - cc, r - rc)` from the central view, its
/// width in pixels, and the rows.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewWindow {
    /// `(c - cc, r - rc)`, in views.
    pub offset: (f32, f32),
    /// Pixels per row.
    pub width: usize,
    /// The rows rendered, top to bottom.
    pub rows: Range<usize>,
}

/// Renders `window` of the rolling-shutter view of `shape` moved by `model` at `params` (SI):
/// band by band or in one pass, as `timing` says. Outputs are row-major over the window's rows.
pub fn render_rolling_shutter(
    shape: &StaticShape,
    model: &dyn MotionModel,
    params: Tensor<1>,
    window: ViewWindow,
    timing: RsTiming,
    settings: &RenderSettings,
    device: &Device,
) -> RenderOutput {
    let ViewWindow { offset, width, rows } = window;
    let parts: Vec<RenderOutput> = match timing {
        RsTiming::PerGaussian(iterations) => {
            let s = shape.splats_rolling(model, params, offset, iterations);
            vec![splat(&s, &s.bins(width, rows, settings), device)]
        }
        RsTiming::Bands(_) => bands(rows, timing, &shape.camera)
            .into_iter()
            .map(|(r, tau)| {
                let s = shape.splats_at_time(model, params.clone(), offset, tau.expect("bands have a time"));
                splat(&s, &s.bins(width, r, settings), device)
            })
            .collect(),
    };
    concat_outputs(parts)
}

/// Band outputs stacked in row order.
pub fn concat_outputs(mut parts: Vec<RenderOutput>) -> RenderOutput {
    if parts.len() == 1 {
        return parts.pop().expect("one part");
    }
    RenderOutput {
        colour: Tensor::cat(parts.iter().map(|p| p.colour.clone()).collect(), 0),
        disparity: Tensor::cat(parts.iter().map(|p| p.disparity.clone()).collect(), 0),
        alpha: Tensor::cat(parts.iter().map(|p| p.alpha.clone()).collect(), 0),
    }
}
