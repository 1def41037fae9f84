//! Constant velocity (the paper's model): `P(t) = R(t ω) P0 + t v`.

use super::{MotionModel, ParamKind, scale_rows, three, vec3};
use crate::geometry::{PoseBatch, rotation_matrices};
use crate::io::MotionRecord;
use burn::tensor::Tensor;

/// Parameters `[ω (rad/s), v (m/s)]`.
#[derive(Debug, Clone, Copy, Default)]
pub struct ConstantVelocity;

impl MotionModel for ConstantVelocity {
    fn name(&self) -> &str {
        "constant_velocity"
    }

    fn parameters(&self) -> Vec<ParamKind> {
        ParamKind::velocities()
    }

    fn poses(&self, params: Tensor<1>, times: Tensor<1>) -> PoseBatch {
        PoseBatch { rotation: rotation_matrices(scale_rows(&times, vec3(&params, 0))), translation: scale_rows(&times, vec3(&params, 3)) }
    }

    fn record(&self, p: &[f64]) -> MotionRecord {
        MotionRecord::ConstantVelocity { omega_rad_s: three(p, 0), velocity_m_s: three(p, 3) }
    }

    fn parameters_of(&self, record: &MotionRecord) -> Option<Vec<f64>> {
        match record {
            MotionRecord::ConstantVelocity { omega_rad_s, velocity_m_s } => Some([*omega_rad_s, *velocity_m_s].concat()),
            _ => None,
        }
    }
}
