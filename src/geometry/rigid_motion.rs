//! Host-side rigid motion: the pose of the scene at time t under each motion model, for the
//! generator, the evaluation and the tests. (The differentiable versions live with the models.)
//!
//! A point P0 (its position at t = 0, central camera frame) is at `P(t) = R(t) P0 + T(t)`.

use crate::io::MotionRecord;
use nalgebra::{Point3, Rotation3, Vector3};

/// A rigid transform `P -> R P + T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Rotation.
    pub rotation: Rotation3<f64>,
    /// Translation, metres.
    pub translation: Vector3<f64>,
}

impl Pose {
    /// The identity.
    pub fn identity() -> Self {
        Self { rotation: Rotation3::identity(), translation: Vector3::zeros() }
    }

    /// `R p + T`.
    pub fn apply(&self, p: &Point3<f64>) -> Point3<f64> {
        self.rotation * p + self.translation
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Self {
        let r = self.rotation.inverse();
        Self { rotation: r, translation: -(r * self.translation) }
    }

    /// Constant velocity over a time `dt`: `R(dt ω)`, `dt v`.
    fn constant_velocity(omega: &[f64; 3], velocity: &[f64; 3], dt: f64) -> Self {
        Self { rotation: Rotation3::new(Vector3::from(*omega) * dt), translation: Vector3::from(*velocity) * dt }
    }
}

/// The read-out interval of an image of `height` rows: `[t(0), t(H-1)]`, centred on t = 0.
pub fn readout_interval(height: usize, line_time_s: f64) -> (f64, f64) {
    let half = (height as f64 - 1.0) / 2.0 * line_time_s;
    (-half, half)
}

/// The pose at time `t`. `readout` is the read-out interval, which `piecewise_constant` cuts into
/// equal segments; its pose is composed segment by segment outwards from t = 0 (the first and
/// last segments extend beyond the interval). As in the constant-velocity law, where `t v` is
/// not rotated by `R(t ω)`, rotations compose (`R <- R(Δ ω_k) R`) and translations add
/// (`T <- T + Δ v_k`): the pose is continuous, and equal segments give exactly constant velocity.
pub fn pose_at(motion: &MotionRecord, t: f64, readout: (f64, f64)) -> Pose {
    match motion {
        MotionRecord::ConstantVelocity { omega_rad_s, velocity_m_s } => Pose::constant_velocity(omega_rad_s, velocity_m_s, t),
        MotionRecord::ConstantAcceleration { omega_rad_s, velocity_m_s, alpha_rad_s2, accel_m_s2 } => {
            let h = 0.5 * t * t;
            Pose {
                rotation: Rotation3::new(Vector3::from(*omega_rad_s) * t + Vector3::from(*alpha_rad_s2) * h),
                translation: Vector3::from(*velocity_m_s) * t + Vector3::from(*accel_m_s2) * h,
            }
        }
        MotionRecord::PiecewiseConstant { omega_rad_s, velocity_m_s } => {
            let k = omega_rad_s.len();
            let (start, end) = readout;
            let length = (end - start) / k as f64;
            if k == 1 || length <= 0.0 {
                return Pose::constant_velocity(&omega_rad_s[0], &velocity_m_s[0], t);
            }
            let boundary = |j: usize| start + j as f64 * length;
            // Position of t = 0 in segment units; the first segment travelled is the one just
            // after 0 going forward, just before 0 going back (0 may sit on a boundary).
            let x0 = -start / length;
            let forward = t >= 0.0;
            let first = if forward { x0.floor() } else { x0.ceil() - 1.0 };
            let mut seg = first.clamp(0.0, (k - 1) as f64) as usize;
            let mut pose = Pose::identity();
            let mut now = 0.0;
            loop {
                let limit = if forward {
                    if seg + 1 < k { boundary(seg + 1).min(t) } else { t }
                } else if seg > 0 {
                    boundary(seg).max(t)
                } else {
                    t
                };
                let step = Pose::constant_velocity(&omega_rad_s[seg], &velocity_m_s[seg], limit - now);
                pose = Pose { rotation: step.rotation * pose.rotation, translation: pose.translation + step.translation };
                now = limit;
                if now == t {
                    return pose;
                }
                if forward { seg += 1 } else { seg -= 1 }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close_within(a: &Pose, b: &Pose, tol: f64) -> bool {
        (a.rotation.matrix() - b.rotation.matrix()).norm() < tol && (a.translation - b.translation).norm() < tol
    }

    fn close(a: &Pose, b: &Pose) -> bool {
        close_within(a, b, 1e-12)
    }

    #[test]
    fn constant_velocity_follows_rodrigues() {
        let m = MotionRecord::ConstantVelocity { omega_rad_s: [0.0, 0.0, 2.0], velocity_m_s: [1.0, 0.0, 0.0] };
        let pose = pose_at(&m, 0.25, (-1.0, 1.0));
        let p = pose.apply(&Point3::new(1.0, 0.0, 5.0));
        let a = 0.5f64; // 0.25 s at 2 rad/s about Z
        assert!((p - Point3::new(a.cos() + 0.25, a.sin(), 5.0)).norm() < 1e-12);
        assert!(close(&pose_at(&m, 0.0, (-1.0, 1.0)), &Pose::identity()));
    }

    #[test]
    fn one_segment_is_constant_velocity_and_equal_segments_too() {
        let (w, v) = ([0.1, -0.2, 0.3], [0.5, 0.0, -0.4]);
        let cv = MotionRecord::ConstantVelocity { omega_rad_s: w, velocity_m_s: v };
        for k in [1, 2, 3, 4] {
            let pw = MotionRecord::PiecewiseConstant { omega_rad_s: vec![w; k], velocity_m_s: vec![v; k] };
            for t in [-0.9, -0.5, -0.1, 0.0, 0.2, 0.5, 0.77, 1.3] {
                assert!(close(&pose_at(&pw, t, (-1.0, 1.0)), &pose_at(&cv, t, (-1.0, 1.0))), "k={k} t={t}");
            }
        }
    }

    #[test]
    fn piecewise_pose_is_continuous_and_uses_each_segment() {
        let turning = MotionRecord::PiecewiseConstant {
            omega_rad_s: vec![[0.3, 0.0, 0.0], [0.0, -0.4, 0.0], [0.0, 0.0, 0.5]],
            velocity_m_s: vec![[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]],
        };
        for b in [-0.5, 0.5] {
            let (a, c) = (pose_at(&turning, b - 1e-9, (-1.5, 1.5)), pose_at(&turning, b + 1e-9, (-1.5, 1.5)));
            assert!(close_within(&a, &c, 1e-8), "jump at {b}");
        }
        // Rotation composed outwards from 0: at t = 1, 0.5 s of segment 1 then 0.5 s of segment 2.
        let expected = Rotation3::new(Vector3::new(0.0, 0.0, 0.25)) * Rotation3::new(Vector3::new(0.0, -0.2, 0.0));
        assert!((pose_at(&turning, 1.0, (-1.5, 1.5)).rotation.matrix() - expected.matrix()).norm() < 1e-12);
        let pw = MotionRecord::PiecewiseConstant {
            omega_rad_s: vec![[0.0; 3], [0.0; 3], [0.0; 3]],
            velocity_m_s: vec![[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]],
        };
        let r = (-1.5, 1.5); // segments [-1.5,-0.5], [-0.5,0.5], [0.5,1.5]
        let at = |t: f64| pose_at(&pw, t, r).translation;
        assert!((at(0.5) - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-12);
        assert!((at(1.0) - Vector3::new(0.0, 1.0, 1.5)).norm() < 1e-12);
        assert!((at(-1.0) - Vector3::new(-0.5, -1.0, 0.0)).norm() < 1e-12);
        for b in [-0.5, 0.5] {
            assert!((at(b - 1e-9) - at(b + 1e-9)).norm() < 1e-8, "jump at {b}");
        }
    }

    #[test]
    fn even_segment_counts_split_at_zero() {
        let pw = MotionRecord::PiecewiseConstant { omega_rad_s: vec![[0.0; 3]; 2], velocity_m_s: vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] };
        let r = (-1.0, 1.0);
        assert!((pose_at(&pw, 0.5, r).translation - Vector3::new(0.0, 0.5, 0.0)).norm() < 1e-12);
        assert!((pose_at(&pw, -0.5, r).translation - Vector3::new(-0.5, 0.0, 0.0)).norm() < 1e-12);
    }
}
