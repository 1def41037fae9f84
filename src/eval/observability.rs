//! Which directions of constant-velocity motion a scene lets stage 2 see.
//!
//! Stage 2 never sees the rolling-shutter shift itself, only its *cue*: where a point lands in a
//! corner view relative to where the central row (read at one time) predicts it, two read-outs
//! a few rows apart.
//! The image-space error measures the shift, which is much larger. For each direction of the
//! six parameters (ω, v) this module compares the two on the scene's true geometry, linearised
//! at the true motion: the ratio (px of cue per px of image-space effect) says how well that
//! direction is observed. Directions with a small ratio are the ones stage 2 cannot pin down;
//! their errors show at full size in the image-space error.

use crate::geometry::{Camera, ViewId, rs_project};
use crate::io::{MotionRecord, Raster};
use crate::model::motion::{ConstantVelocity, MotionModel};
use nalgebra::{SMatrix, SVector};
use serde::Serialize;

/// Names of the six constant-velocity parameters, in order.
pub const PARAMETER_NAMES: [&str; 6] = ["omega_x", "omega_y", "omega_z", "v_x", "v_y", "v_z"];

/// Finite-difference step of each parameter (rad/s and m/s).
const STEP: f64 = 1e-3;

/// How strongly the cue observes each direction of constant-velocity motion.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Observability {
    /// Per parameter (see [`PARAMETER_NAMES`]): px of cue per px of image-space effect.
    pub per_parameter: Vec<(String, f64)>,
    /// Eigen-directions, weakest first: the ratio, and the direction as the image-space share of
    /// each parameter (signed, unit length; a parameter's share is its change times its
    /// image-space effect per unit).
    pub directions: Vec<(f64, [f64; 6])>,
}

/// Where `p0` lands in each of `views` under the motion `theta`.
fn images(camera: &Camera, theta: &[f64; 6], views: &[ViewId; 6], p0: &nalgebra::Point3<f64>) -> Option<[(f64, f64); 6]> {
    let m = ConstantVelocity.record(theta);
    let mut out = [(0.0, 0.0); 6];
    for (o, &view) in out.iter_mut().zip(views) {
        let (x, y, _) = rs_project(camera, &m, view, p0)?;
        *o = (x, y);
    }
    Some(out)
}

/// What stage 2 sees of a point: its position in each corner minus the position the central
/// row predicts there (its central-view position shifted by the disparity the central row
/// measures, both read at the same time), 8 numbers; and what the image-space error measures:
/// its positions in the central view and the corners, 10 numbers.
fn cue_and_effect(camera: &Camera, theta: &[f64; 6], views: &[ViewId; 6], p0: &nalgebra::Point3<f64>) -> Option<([f64; 8], [f64; 10])> {
    let [c, n, k @ ..] = images(camera, theta, views, p0)?;
    // The central-row neighbour sees the point on the same row at the same time.
    let per_disparity = camera.grid.position_in_view(views[1], 0.0, 0.0, 1.0).0;
    let d = (n.0 - c.0) / per_disparity;
    let (mut cue, mut effect) = ([0.0; 8], [0.0; 10]);
    effect[0] = c.0;
    effect[1] = c.1;
    for (i, (&view, p)) in views[2..].iter().zip(k).enumerate() {
        let predicted = camera.grid.position_in_view(view, c.0, c.1, d);
        cue[2 * i] = p.0 - predicted.0;
        cue[2 * i + 1] = p.1 - predicted.1;
        effect[2 * i + 2] = p.0;
        effect[2 * i + 3] = p.1;
    }
    Some((cue, effect))
}

/// The observability of constant-velocity motion on the t = 0 points of `gt_depth` (every
/// `stride`-th pixel each way), linearised at `truth` (at zero motion when `truth` is not a
/// constant-velocity motion). `None` when no point can be imaged.
pub fn observability(camera: &Camera, truth: &MotionRecord, gt_depth: &Raster, stride: usize) -> Option<Observability> {
    let stride = stride.max(1);
    let centre = camera.grid.central()?;
    if camera.grid.cols < 2 {
        return None;
    }
    let neighbour = ViewId { col: centre.col + 1, ..centre };
    let c = camera.grid.corners();
    let views = [centre, neighbour, c[0], c[1], c[2], c[3]];
    let at: [f64; 6] = ConstantVelocity.parameters_of(truth).and_then(|p| p.try_into().ok()).unwrap_or([0.0; 6]);
    // Gram matrices of the cue (corner positions minus the central row's predictions, 8 rows
    // per point) and of the image-space effect (all five positions, 10 rows per point), over
    // the parameters, from central differences.
    let (mut cue, mut effect) = (SMatrix::<f64, 6, 6>::zeros(), SMatrix::<f64, 6, 6>::zeros());
    let mut points = 0usize;
    for v in (0..gt_depth.height).step_by(stride) {
        for u in (0..gt_depth.width).step_by(stride) {
            let z = gt_depth.data[v * gt_depth.width + u] as f64;
            if !(z.is_finite() && z > 0.0) {
                continue;
            }
            let p0 = camera.back_project(u as f64, v as f64, z);
            let mut jac_cue = SMatrix::<f64, 8, 6>::zeros();
            let mut jac_effect = SMatrix::<f64, 10, 6>::zeros();
            let mut ok = true;
            for j in 0..6 {
                let (mut plus, mut minus) = (at, at);
                plus[j] += STEP;
                minus[j] -= STEP;
                let (Some(a), Some(b)) = (cue_and_effect(camera, &plus, &views, &p0), cue_and_effect(camera, &minus, &views, &p0)) else {
                    ok = false;
                    break;
                };
                for r in 0..8 {
                    jac_cue[(r, j)] = (a.0[r] - b.0[r]) / (2.0 * STEP);
                }
                for r in 0..10 {
                    jac_effect[(r, j)] = (a.1[r] - b.1[r]) / (2.0 * STEP);
                }
            }
            if ok {
                cue += jac_cue.transpose() * jac_cue / 4.0;
                effect += jac_effect.transpose() * jac_effect / 5.0;
                points += 1;
            }
        }
    }
    if points == 0 {
        return None;
    }
    let per_parameter = (0..6).map(|j| (PARAMETER_NAMES[j].to_string(), (cue[(j, j)] / effect[(j, j)]).sqrt())).collect();
    // Parameters in image-space units (one unit: 1 px RMS effect), then the generalised
    // eigenproblem cue x = λ effect x through a Cholesky factor of the effect.
    let unit = SVector::<f64, 6>::from_fn(|j, _| effect[(j, j)].sqrt().recip());
    let scale = SMatrix::<f64, 6, 6>::from_diagonal(&unit);
    let (cue_n, effect_n) = (scale * cue * scale, scale * effect * scale);
    let chol = effect_n.cholesky()?;
    let l_inv = chol.l().try_inverse()?;
    let eig = (l_inv * cue_n * l_inv.transpose()).symmetric_eigen();
    let mut directions: Vec<(f64, [f64; 6])> = (0..6)
        .map(|i| {
            let x = l_inv.transpose() * eig.eigenvectors.column(i);
            let norm = x.norm();
            let mut share = [0.0; 6];
            for (s, v) in share.iter_mut().zip(x.iter()) {
                *s = v / norm;
            }
            // Sign: the largest share positive.
            let sign = share.iter().copied().fold(0.0f64, |m, v| if v.abs() > m.abs() { v } else { m }).signum();
            share.iter_mut().for_each(|s| *s *= sign);
            (eig.eigenvalues[i].max(0.0).sqrt(), share)
        })
        .collect();
    directions.sort_by(|a, b| a.0.total_cmp(&b.0));
    Some(Observability { per_parameter, directions })
}

impl Observability {
    /// A direction in words: its two largest shares, e.g. `0.71 omega_y - 0.70 v_x`.
    pub fn describe(share: &[f64; 6]) -> String {
        let mut order: Vec<usize> = (0..6).collect();
        order.sort_by(|&a, &b| share[b].abs().total_cmp(&share[a].abs()));
        order
            .iter()
            .take(2)
            .filter(|&&j| share[j].abs() >= 0.2)
            .enumerate()
            .map(|(k, &j)| {
                let s = share[j];
                match (k, s < 0.0) {
                    (0, _) => format!("{s:.2} {}", PARAMETER_NAMES[j]),
                    (_, true) => format!("- {:.2} {}", -s, PARAMETER_NAMES[j]),
                    (_, false) => format!("+ {s:.2} {}", PARAMETER_NAMES[j]),
                }
            })
            .collect::<Vec<_>>()
            .join(" ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::ViewGrid;

    fn camera() -> Camera {
        Camera {
            grid: ViewGrid { rows: 9, cols: 9 },
            width: 64,
            height: 64,
            f_px: 180.0,
            baseline_m: 0.025,
            focus_m: 4.5,
            line_time_s: 4e-4,
        }
    }

    /// Depth `z(u, v)` at every pixel.
    fn depth(z: impl Fn(usize, usize) -> f32) -> Raster {
        Raster::from_fn(64, 64, z)
    }

    #[test]
    fn the_cue_is_a_small_fraction_of_the_shift_and_grows_with_disparity() {
        let cam = camera();
        let near = depth(|_, _| 2.0);
        let nearer = depth(|_, _| 1.0);
        let zero = MotionRecord::zero();
        let a = observability(&cam, &zero, &near, 4).unwrap();
        let b = observability(&cam, &zero, &nearer, 4).unwrap();
        for ((name, ra), (_, rb)) in a.per_parameter.iter().zip(&b.per_parameter) {
            assert!(*ra > 0.0 && *ra < 0.5, "{name}: {ra}");
            // The cue spans 4 d rows; d grows as the scene comes nearer the camera.
            assert!(rb > ra, "{name}: {rb} <= {ra}");
        }
    }

    #[test]
    fn a_plane_at_the_focus_distance_gives_no_cue() {
        // Zero disparity: every view images a point on the same row, read at the same time, so
        // no motion moves the corners against the central row.
        let cam = camera();
        let o = observability(&cam, &MotionRecord::zero(), &depth(|_, _| cam.focus_m as f32), 4).unwrap();
        for (name, r) in &o.per_parameter {
            assert!(*r < 1e-3, "{name}: {r}");
        }
        assert!(o.directions.windows(2).all(|w| w[0].0 <= w[1].0), "weakest first: {:?}", o.directions);
        assert!(o.directions.iter().all(|(_, d)| (d.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-9));
    }
}
