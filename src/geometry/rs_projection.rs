//! Rolling-shutter projection on the host: where a static point is imaged when each row is read
//! at its own time and the scene moves meanwhile.

use super::camera::{Camera, ViewId};
use super::rigid_motion::{pose_at, readout_interval};
use crate::io::MotionRecord;
use nalgebra::Point3;

/// Where the point `p0` (its position at t = 0) appears in `view` of a rolling-shutter capture:
/// `(x, y, t)` such that the point, moved to time `t = row_time(y)`, projects onto `(x, y)`.
/// Found by fixed-point iteration on the row, starting from the central row. `None` when the
/// point is behind the camera or the iteration does not settle (a motion so fast that rows
/// overtake the point).
pub fn rs_project(cam: &Camera, motion: &MotionRecord, view: ViewId, p0: &Point3<f64>) -> Option<(f64, f64, f64)> {
    let readout = readout_interval(cam.height, cam.line_time_s);
    let mut y = cam.v0();
    for _ in 0..60 {
        let t = cam.row_time(y);
        let p = pose_at(motion, t, readout).apply(p0);
        if p.z <= 1e-9 {
            return None;
        }
        let (x, y_new, _) = cam.project(view, &p);
        if (y_new - y).abs() < 1e-7 {
            return Some((x, y_new, cam.row_time(y_new)));
        }
        y = y_new;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::ViewGrid;

    fn camera() -> Camera {
        Camera {
            grid: ViewGrid { rows: 9, cols: 9 },
            width: 512,
            height: 512,
            f_px: 1463.0,
            baseline_m: 0.025,
            focus_m: 4.5,
            line_time_s: 6.5e-5,
        }
    }

    #[test]
    fn without_motion_it_is_the_plain_projection() {
        let cam = camera();
        let p = Point3::new(0.3, -0.2, 4.0);
        let view = ViewId { row: 0, col: 8 };
        let (x, y, _) = rs_project(&cam, &MotionRecord::zero(), view, &p).unwrap();
        let (u, v, _) = cam.project(view, &p);
        assert!((x - u).abs() < 1e-9 && (y - v).abs() < 1e-9);
    }

    #[test]
    fn the_found_row_is_consistent_with_its_time() {
        let cam = camera();
        let motion = MotionRecord::ConstantVelocity { omega_rad_s: [0.3, -0.5, 0.2], velocity_m_s: [0.8, -0.4, 1.0] };
        let p0 = Point3::new(-0.4, 0.5, 3.5);
        let view = ViewId { row: 8, col: 0 };
        let (x, y, t) = rs_project(&cam, &motion, view, &p0).unwrap();
        assert!((t - cam.row_time(y)).abs() < 1e-15);
        let p = pose_at(&motion, t, readout_interval(cam.height, cam.line_time_s)).apply(&p0);
        let (u, v, _) = cam.project(view, &p);
        assert!((u - x).abs() < 1e-6 && (v - y).abs() < 1e-6);
        // The motion moved it: it is not where the static projection puts it.
        let (us, vs, _) = cam.project(view, &p0);
        assert!((us - x).abs() + (vs - y).abs() > 1.0);
    }
}
