//! Constant acceleration: `P(t) = R(t ω + t²/2 α) P0 + t v + t²/2 a`.

use super::{MotionModel, ParamKind, Quantity, scale_rows, three, vec3};
use crate::geometry::{PoseBatch, rotation_matrices};
use crate::io::MotionRecord;
use burn::tensor::Tensor;

/// Parameters `[ω (rad/s), v (m/s), α (rad/s²), a (m/s²)]`.
#[derive(Debug, Clone, Copy, Default)]
pub struct ConstantAcceleration;

impl MotionModel for ConstantAcceleration {
    fn name(&self) -> &str {
        "constant_acceleration"
    }

    fn parameters(&self) -> Vec<ParamKind> {
        [ParamKind::velocities(), ParamKind::xyz(Quantity::Rotation, 2).to_vec(), ParamKind::xyz(Quantity::Translation, 2).to_vec()]
            .concat()
    }

    fn poses(&self, params: Tensor<1>, times: Tensor<1>) -> PoseBatch {
        let half_t2 = times.clone() * times.clone() * 0.5;
        let rotvec = scale_rows(&times, vec3(&params, 0)) + scale_rows(&half_t2, vec3(&params, 6));
        let translation = scale_rows(&times, vec3(&params, 3)) + scale_rows(&half_t2, vec3(&params, 9));
        PoseBatch { rotation: rotation_matrices(rotvec), translation }
    }

    fn record(&self, p: &[f64]) -> MotionRecord {
        MotionRecord::ConstantAcceleration {
            omega_rad_s: three(p, 0),
            velocity_m_s: three(p, 3),
            alpha_rad_s2: three(p, 6),
            accel_m_s2: three(p, 9),
        }
    }

    fn parameters_of(&self, record: &MotionRecord) -> Option<Vec<f64>> {
        match record {
            MotionRecord::ConstantAcceleration { omega_rad_s, velocity_m_s, alpha_rad_s2, accel_m_s2 } => {
                Some([*omega_rad_s, *velocity_m_s, *alpha_rad_s2, *accel_m_s2].concat())
            }
            MotionRecord::ConstantVelocity { omega_rad_s, velocity_m_s } => {
                Some([*omega_rad_s, *velocity_m_s, [0.0; 3], [0.0; 3]].concat())
            }
            _ => None,
        }
    }
}
