//! Piecewise constant velocity: the read-out interval cut into K equal segments, each with its
//! own (ω_k, v_k). The pose is continuous and composed segment by segment outwards from t = 0:
//! rotations compose (`R <- R(Δ_k ω_k) R`), translations add (`T <- T + Δ_k v_k`), as in
//! [`crate::geometry::pose_at`]; the first and last segments extend beyond the interval.

use super::{MotionModel, ParamKind, scale_rows, three, vec3};
use crate::geometry::{PoseBatch, rotation_matrices};
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
        // Signed time spent in each segment going from 0 to t: forward (t > 0) or back (t < 0).
        let forward = |lo: f64, hi: f64| (times.clone().clamp_max(hi) - lo.max(0.0)).clamp_min(0.0);
        let back = |lo: f64, hi: f64| (times.clone().clamp_min(lo).neg() + hi.min(0.0)).clamp_min(0.0).neg();
        let mut rotation_forward: Option<Tensor<3>> = None;
        let mut rotation_back: Option<Tensor<3>> = None;
        let mut translation: Option<Tensor<2>> = None;
        for j in 0..self.segments {
            let (lo, hi) = self.span(j);
            let (dt_f, dt_b) = (forward(lo, hi), back(lo, hi));
            let (omega, velocity) = (vec3(&params, 6 * j), vec3(&params, 6 * j + 3));
            // Going forward, later segments act last (left); going back, earlier segments do.
            let rf = rotation_matrices(scale_rows(&dt_f, omega.clone()));
            let rb = rotation_matrices(scale_rows(&dt_b, omega));
            rotation_forward = Some(match rotation_forward {
                Some(r) => rf.matmul(r),
                None => rf,
            });
            rotation_back = Some(match rotation_back {
                Some(r) => r.matmul(rb),
                None => rb,
            });
            let step = scale_rows(&(dt_f + dt_b), velocity);
            translation = Some(match translation {
                Some(t) => t + step,
                None => step,
            });
        }
        let (rf, rb, t) = (rotation_forward.expect("K ≥ 1"), rotation_back.expect("K ≥ 1"), translation.expect("K ≥ 1"));
        // For each time one of the two products is the identity.
        PoseBatch { rotation: rf.matmul(rb), translation: t }
    }

    fn record(&self, p: &[f64]) -> MotionRecord {
        MotionRecord::PiecewiseConstant {
            omega_rad_s: (0..self.segments).map(|j| three(p, 6 * j)).collect(),
            velocity_m_s: (0..self.segments).map(|j| three(p, 6 * j + 3)).collect(),
        }
    }

    fn parameters_of(&self, record: &MotionRecord) -> Option<Vec<f64>> {
        match record {
            MotionRecord::PiecewiseConstant { omega_rad_s, velocity_m_s } if omega_rad_s.len() == self.segments => {
                Some(omega_rad_s.iter().zip(velocity_m_s).flat_map(|(w, v)| [*w, *v].concat()).collect())
            }
            MotionRecord::ConstantVelocity { omega_rad_s, velocity_m_s } => Some([*omega_rad_s, *velocity_m_s].concat().repeat(self.segments)),
            _ => None,
        }
    }
}
