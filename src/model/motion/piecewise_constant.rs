//! Piecewise constant velocity: the read-out interval cut into K equal segments, each with its
//! own (ω_k, v_k). The pose is continuous and composed segment by segment outwards from t = 0:
//! rotations compose (`R <- R(Δ_k ω_k) R`), translations add (`T <- T + Δ_k v_k`), as in
//! [`crate::geometry::pose_at`]; the first and last segments extend beyond the interval.

use super::{MotionModel, ParamKind, scale_rows, three, vec3};
use crate::geometry::{PoseBatch, compose, rotation_matrices};
use crate::io::MotionRecord;
use burn::tensor::Tensor;

/// Stands for ±∞ at the open ends of the first and last segments, seconds.
const FAR: f64 = 1e9;

/// Parameters `[ω_0, v_0, ω_1, v_1, ...]`, six per segment.
#[derive(Debug, Clone, Copy)]
pub struct PiecewiseConstant {
    /// Number of segments K ≥ 1.
    pub segments: usize,
    /// The read-out interval `[t(0), t(H-1)]`, seconds.
    pub readout: (f64, f64),
}

impl PiecewiseConstant {
    /// Segment `j`'s time span, open at the ends.
    fn span(&self, j: usize) -> (f64, f64) {
        let (s, e) = self.readout;
        let length = (e - s) / self.segments as f64;
        let lo = if j == 0 { -FAR } else { s + j as f64 * length };
        let hi = if j + 1 == self.segments { FAR } else { s + (j + 1) as f64 * length };
        (lo, hi)
    }
}

impl MotionModel for PiecewiseConstant {
    fn name(&self) -> &str {
        "piecewise_constant"
    }

    fn parameters(&self) -> Vec<ParamKind> {
        ParamKind::velocities().repeat(self.segments)
    }

    fn poses(&self, params: Tensor<1>, times: Tensor<1>) -> PoseBatch {
        // Time spent in each segment going from 0 to t, forward (t > 0) or back (t < 0); at most
        // one of the two is non-zero for a given t.
        let forward = |lo: f64, hi: f64| (times.clone().clamp_max(hi) - lo.max(0.0)).clamp_min(0.0);
        let back = |lo: f64, hi: f64| (times.clone().clamp_min(lo).neg() + hi.min(0.0)).clamp_min(0.0);
        // Going forward the rotation is `A_{K-1} ⋯ A_0` with `A_j = R(Δ_j ω_j)`, later segments
        // acting last; going back it is `R(-Δ_0 ω_0) ⋯ R(-Δ_{K-1} ω_{K-1})`, the transpose of
        // the same product. One product serves both: K rotations instead of 2K.
        let mut product: Option<Tensor<3>> = None;
        let mut translation: Option<Tensor<2>> = None;
        for j in 0..self.segments {
            let (lo, hi) = self.span(j);
            let (dt_f, dt_b) = (forward(lo, hi), back(lo, hi));
            let (omega, velocity) = (vec3(&params, 6 * j), vec3(&params, 6 * j + 3));
            let a = rotation_matrices(scale_rows(&(dt_f.clone() + dt_b.clone()), omega));
            product = Some(match product {
                Some(p) => compose(a, p),
                None => a,
            });
            let step = scale_rows(&(dt_f - dt_b), velocity);
            translation = Some(match translation {
                Some(t) => t + step,
                None => step,
            });
        }
        let (product, translation) = (product.expect("K ≥ 1"), translation.expect("K ≥ 1"));
        let n = times.dims()[0];
        let backwards = times.lower_elem(0.0).reshape([n, 1, 1]).expand([n, 3, 3]);
        let rotation = product.clone().mask_where(backwards, product.swap_dims(1, 2));
        PoseBatch { rotation, translation }
    }

    fn record(&self, p: &[f64]) -> MotionRecord {
        MotionRecord::PiecewiseConstant {
            omega_rad_s: (0..self.segments).map(|j| three(p, 6 * j)).collect(),
            velocity_m_s: (0..self.segments).map(|j| three(p, 6 * j + 3)).collect(),
        }
    }

    /// The rates' second difference across segments, `x_{k+1} - 2 x_k + x_{k-1}` for each of
    /// the six rates: zero when they change linearly from segment to segment (a constant
    /// acceleration), `6 (K - 2)` residuals; `None` with fewer than three segments.
    fn roughness(&self, scaled: Tensor<1>) -> Option<Tensor<1>> {
        let k = self.segments;
        if k < 3 {
            return None;
        }
        let rates = scaled.reshape([k, 6]);
        let second = rates.clone().narrow(0, 2, k - 2) - rates.clone().narrow(0, 1, k - 2) * 2.0 + rates.narrow(0, 0, k - 2);
        Some(second.reshape([6 * (k - 2)]))
    }

    fn parameters_of(&self, record: &MotionRecord) -> Option<Vec<f64>> {
        match record {
            MotionRecord::PiecewiseConstant { omega_rad_s, velocity_m_s } if omega_rad_s.len() == self.segments => {
                Some(omega_rad_s.iter().zip(velocity_m_s).flat_map(|(w, v)| [*w, *v].concat()).collect())
            }
            MotionRecord::ConstantVelocity { omega_rad_s, velocity_m_s } => {
                Some([*omega_rad_s, *velocity_m_s].concat().repeat(self.segments))
            }
            _ => None,
        }
    }
}
