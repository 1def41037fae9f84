//! Disparity to 3D and back (FORMAT's geometry, the paper's Eq. 1) as burn tensor programs:
//! central-view Gaussians lifted to points, points projected into any view, and row times.

use super::camera::Camera;
use burn::tensor::Tensor;

/// The view, or views, points are imaged into, by offset `(c - cc, r - rc)` in the grid.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)] // passed by value once a projection; never stored in bulk
pub enum ViewOffset {
    /// Every point into the same view.
    Shared(f32, f32),
    /// Each point into its own view: the column and row offsets, `[N]` each.
    PerPoint(Tensor<1>, Tensor<1>),
}

impl From<(f32, f32)> for ViewOffset {
    fn from((a, b): (f32, f32)) -> Self {
        Self::Shared(a, b)
    }
}

impl ViewOffset {
    /// The offsets times the points' disparities `d`: their shifts from the central view.
    fn times(self, d: Tensor<1>) -> (Tensor<1>, Tensor<1>) {
        match self {
            Self::Shared(a, b) => (d.clone() * a, d * b),
            Self::PerPoint(a, b) => (d.clone() * a, d * b),
        }
    }
}

/// The camera constants the tensor programs need, as f32.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensorCamera {
    /// Focal length, pixels.
    pub f_px: f32,
    /// Principal point.
    pub u0: f32,
    /// Principal point.
    pub v0: f32,
    /// Baseline times focal length, `b f`, pixel-metres.
    pub bf: f32,
    /// `1 / focus`, 1/m.
    pub inv_focus: f32,
    /// Seconds between two row read-outs.
    pub line_time_s: f32,
}

impl TensorCamera {
    /// The constants of `cam`.
    pub fn new(cam: &Camera) -> Self {
        Self {
            f_px: cam.f_px as f32,
            u0: cam.u0() as f32,
            v0: cam.v0() as f32,
            bf: cam.bf() as f32,
            inv_focus: (1.0 / cam.focus_m) as f32,
            line_time_s: cam.line_time_s as f32,
        }
    }

    /// Depth of disparity `d`: `Z = 1 / (d / (b f) + 1 / focus)`.
    pub fn depth(&self, d: Tensor<1>) -> Tensor<1> {
        (d / self.bf + self.inv_focus).recip()
    }

    /// Disparity of depth `z`: `b f (1/z - 1/focus)`.
    pub fn disparity(&self, z: Tensor<1>) -> Tensor<1> {
        (z.recip() - self.inv_focus) * self.bf
    }

    /// The 3D points (central frame, `[N, 3]`) of central-view pixels `(u, v)` with disparity `d`.
    pub fn lift(&self, u: Tensor<1>, v: Tensor<1>, d: Tensor<1>) -> Tensor<2> {
        let z = self.depth(d);
        let x = (u - self.u0) * z.clone() / self.f_px;
        let y = (v - self.v0) * z.clone() / self.f_px;
        Tensor::stack::<2>(vec![x, y, z], 1)
    }

    /// Where points `[N, 3]` appear in the view at `offset = (c - cc, r - rc)` (one view for all,
    /// or one per point): `(u, v, d)` with `u = u0 + f X/Z - (c-cc) d` and
    /// `v = v0 + f Y/Z - (r-rc) d` (FORMAT's rule).
    pub fn project(&self, points: Tensor<2>, offset: impl Into<ViewOffset>) -> (Tensor<1>, Tensor<1>, Tensor<1>) {
        let n = points.dims()[0];
        let part = |i: usize| points.clone().slice([0..n, i..i + 1]).reshape([n]);
        let (x, y, z) = (part(0), part(1), part(2));
        let d = self.disparity(z.clone());
        let (shift_u, shift_v) = offset.into().times(d.clone());
        let u = x / z.clone() * self.f_px + self.u0 - shift_u;
        let v = y / z * self.f_px + self.v0 - shift_v;
        (u, v, d)
    }

    /// Read-out time of image row `v` (any view): `(v - v0) * line_time_s`.
    pub fn row_time(&self, v: Tensor<1>) -> Tensor<1> {
        (v - self.v0) * self.line_time_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{ViewGrid, ViewId};
    use burn::tensor::{Device, TensorData};
    use nalgebra::Point3;

    #[test]
    fn agrees_with_the_host_camera() {
        let cam = Camera {
            grid: ViewGrid { rows: 9, cols: 9 },
            width: 512,
            height: 384,
            f_px: 1463.0,
            baseline_m: 0.025,
            focus_m: 4.5,
            line_time_s: 6.5e-5,
        };
        let tc = TensorCamera::new(&cam);
        let device = Device::flex();
        let t = |v: Vec<f32>| Tensor::<1>::from_data(TensorData::new(v.clone(), [v.len()]), &device);
        let host = crate::device::host_values::<1>;
        let (us, vs, ds) = (vec![10.0f32, 255.5, 400.0], vec![20.0f32, 191.5, 300.0], vec![-1.5f32, 0.0, 2.25]);
        let points = tc.lift(t(us.clone()), t(vs.clone()), t(ds.clone()));
        let view = ViewId { row: 0, col: 8 };
        let (ox, oy) = cam.grid.offset(view);
        let (pu, pv, pd) = tc.project(points, (ox as f32, oy as f32));
        let (pu, pv, pd) = (host(pu), host(pv), host(pd));
        for i in 0..3 {
            let z = cam.disparity_to_depth(ds[i] as f64);
            let p: Point3<f64> = cam.back_project(us[i] as f64, vs[i] as f64, z);
            let (x, y, d) = cam.project(view, &p);
            assert!((pu[i] as f64 - x).abs() < 1e-3 && (pv[i] as f64 - y).abs() < 1e-3 && (pd[i] as f64 - d).abs() < 1e-4);
        }
    }
}
