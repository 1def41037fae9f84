//! Damped Newton steps on a handful of parameters, for the directions first-order steps barely
//! move along: where an objective is nearly flat one way and steep another, Adam's steps (scaled
//! per parameter, not per direction) and a decaying rate leave the estimate short along the
//! flat one. The Hessian comes from finite differences of the gradient (one gradient per
//! parameter), so any objective that has a gradient will do; each step is damped
//! (Levenberg–Marquardt) and taken only where it lowers the objective, so the steps never leave
//! the result worse than the start. Directions far flatter than the steepest can be held: there the
//! objective hardly tells one point from another, and a Newton step would go a long way on the
//! strength of a gradient that is mostly noise or bias. Held directions can then be set to rest
//! (their components put to 0, the value a prior centred on rest would pick) where the objective
//! hardly rises: the minimum-norm answer to what it cannot tell apart.

use nalgebra::{DMatrix, DVector};

/// How the Newton steps are taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonSettings {
    /// Newton steps (each one Hessian).
    pub iterations: usize,
    /// Finite-difference step of the Hessian, in the parameters' units.
    pub fd_step: f64,
    /// Longest step (Euclidean, in the parameters' units); a longer one is shortened.
    pub max_step: f64,
    /// Eigen-directions of the Hessian whose curvature is under this share of the steepest's
    /// are held where they are (0 holds none).
    pub min_curvature_ratio: f64,
    /// After the steps, the held directions' components are set to 0 (rest) if that raises the
    /// objective by at most this share of it; one more Hessian at the end (0 or less: never).
    pub rest_tolerance: f64,
}

/// What the steps did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonReport {
    /// The objective at the start.
    pub start: f64,
    /// The objective at the end: at most `start`, or at most `rest_tolerance` over the lowest
    /// the steps reached where the held directions were set to rest.
    pub end: f64,
    /// Steps taken (lowering the objective).
    pub taken: usize,
    /// Evaluations of the objective and its gradient.
    pub evaluations: usize,
    /// Whether the held directions were tried at rest, and how that went.
    pub rest: Option<RestReport>,
}

/// The held directions set to rest after the steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestReport {
    /// The objective after the steps.
    pub before: f64,
    /// The objective with the held directions at rest.
    pub after: f64,
    /// How far that moves the parameters (Euclidean, in their units).
    pub distance: f64,
    /// Whether the move was kept (`after` within the tolerance of `before`).
    pub taken: bool,
}

/// Damping relative to the Hessian's mean absolute diagonal: first try (small enough to leave
/// directions 10^4 times flatter than the mean nearly undamped), least, and most.
const DAMPING_START: f64 = 1e-6;
const DAMPING_MIN: f64 = 1e-9;
const DAMPING_MAX: f64 = 1e3;
/// Damping grows by this after a rejected step and shrinks by it after a taken one.
const DAMPING_FACTOR: f64 = 10.0;

/// The symmetrised Hessian at `x` (gradient `g`) from forward differences of the gradient, one
/// evaluation per parameter.
fn hessian_at(x: &DVector<f64>, g: &DVector<f64>, fd_step: f64, eval: &mut impl FnMut(&[f64]) -> (f64, Vec<f64>)) -> DMatrix<f64> {
    let n = x.len();
    let mut hessian = DMatrix::zeros(n, n);
    for k in 0..n {
        let mut probe = x.clone();
        probe[k] += fd_step;
        let (_, gk) = eval(probe.as_slice());
        hessian.set_column(k, &((DVector::from_vec(gk) - g) / fd_step));
    }
    (&hessian + hessian.transpose()) * 0.5
}

/// Minimises `eval` (the objective and its gradient at a point) from `x0` by at most
/// `settings.iterations` damped Newton steps; returns the lowest point found (or that point with
/// its held directions at rest, where `settings.rest_tolerance` allows) and a report. It stops
/// early when no damping up to the most gives a lower objective.
pub fn newton_minimise(x0: &[f64], settings: &NewtonSettings, mut eval: impl FnMut(&[f64]) -> (f64, Vec<f64>)) -> (Vec<f64>, NewtonReport) {
    let n = x0.len();
    let mut x = DVector::from_column_slice(x0);
    let (mut f, g0) = eval(x.as_slice());
    let mut g = DVector::from_vec(g0);
    let mut report = NewtonReport { start: f, end: f, taken: 0, evaluations: 1, rest: None };
    let mut damping = DAMPING_START;
    if n == 0 || !f.is_finite() {
        return (x0.to_vec(), report);
    }
    for _ in 0..settings.iterations {
        let hessian = hessian_at(&x, &g, settings.fd_step, &mut eval);
        report.evaluations += n;
        let diagonal_scale = (hessian.diagonal().abs().sum() / n as f64).max(f64::MIN_POSITIVE);
        let eigen = hessian.symmetric_eigen();
        let floor = settings.min_curvature_ratio * eigen.eigenvalues.max();
        let free: Vec<usize> = (0..n).filter(|&k| settings.min_curvature_ratio <= 0.0 || eigen.eigenvalues[k] >= floor).collect();
        let mut taken = false;
        while damping <= DAMPING_MAX && !taken {
            // The damped Newton step within the free directions; where the damping leaves one of
            // them without positive curvature, more damping.
            let shift = damping * diagonal_scale;
            if free.iter().any(|&k| eigen.eigenvalues[k] + shift <= 0.0) {
                damping *= DAMPING_FACTOR;
                continue;
            }
            let mut step = DVector::zeros(n);
            for &k in &free {
                let direction = eigen.eigenvectors.column(k);
                step -= direction * (direction.dot(&g) / (eigen.eigenvalues[k] + shift));
            }
            let length = step.norm();
            if length > settings.max_step {
                step *= settings.max_step / length;
            }
            let candidate = &x + step;
            let (fc, gc) = eval(candidate.as_slice());
            report.evaluations += 1;
            if fc.is_finite() && fc < f {
                (x, f, g) = (candidate, fc, DVector::from_vec(gc));
                damping = (damping / DAMPING_FACTOR).max(DAMPING_MIN);
                report.taken += 1;
                taken = true;
            } else {
                damping *= DAMPING_FACTOR;
            }
        }
        if !taken {
            break;
        }
    }
    if settings.rest_tolerance > 0.0 && settings.min_curvature_ratio > 0.0 {
        let eigen = hessian_at(&x, &g, settings.fd_step, &mut eval).symmetric_eigen();
        report.evaluations += n;
        let floor = settings.min_curvature_ratio * eigen.eigenvalues.max();
        let mut candidate = x.clone();
        for k in (0..n).filter(|&k| eigen.eigenvalues[k] < floor) {
            let direction = eigen.eigenvectors.column(k);
            candidate -= direction * direction.dot(&x);
        }
        let distance = (&candidate - &x).norm();
        if distance > 0.0 {
            let (fc, _) = eval(candidate.as_slice());
            report.evaluations += 1;
            let taken = fc.is_finite() && fc <= f + settings.rest_tolerance * f.abs();
            report.rest = Some(RestReport { before: f, after: fc, distance, taken });
            if taken {
                (x, f) = (candidate, fc);
            }
        }
    }
    report.end = f;
    (x.as_slice().to_vec(), report)
}

/// The directions [`newton_minimise`] would hold at `x`: the unit eigenvectors of the Hessian of
/// `eval` there whose curvature is under `min_curvature_ratio` of the steepest's (none where that
/// ratio is 0 or less). One gradient at `x` and one per parameter.
pub fn held_directions(
    x: &[f64],
    fd_step: f64,
    min_curvature_ratio: f64,
    mut eval: impl FnMut(&[f64]) -> (f64, Vec<f64>),
) -> Vec<Vec<f64>> {
    if min_curvature_ratio <= 0.0 || x.is_empty() {
        return Vec::new();
    }
    let at = DVector::from_column_slice(x);
    let (_, g) = eval(x);
    let eigen = hessian_at(&at, &DVector::from_vec(g), fd_step, &mut eval).symmetric_eigen();
    let floor = min_curvature_ratio * eigen.eigenvalues.max();
    (0..x.len()).filter(|&k| eigen.eigenvalues[k] < floor).map(|k| eigen.eigenvectors.column(k).iter().copied().collect()).collect()
}

/// Minimises `eval` over the points `x0 + Σ a_k directions[k]` alone, by at most
/// `settings.iterations` damped Newton steps on the coefficients `a` from 0 (none of them held,
/// none set to rest): another objective's say along the directions one objective cannot tell
/// apart, the rest of `x0` kept. Returns the point reached and the report (its objective
/// values are `eval`'s).
pub fn newton_within(
    x0: &[f64],
    directions: &[Vec<f64>],
    settings: &NewtonSettings,
    mut eval: impl FnMut(&[f64]) -> (f64, Vec<f64>),
) -> (Vec<f64>, NewtonReport) {
    let point = |a: &[f64]| -> Vec<f64> {
        let mut x = x0.to_vec();
        for (d, &t) in directions.iter().zip(a) {
            x.iter_mut().zip(d).for_each(|(xi, di)| *xi += t * di);
        }
        x
    };
    let within = NewtonSettings { min_curvature_ratio: 0.0, rest_tolerance: 0.0, ..*settings };
    let (a, report) = newton_minimise(&vec![0.0; directions.len()], &within, |a| {
        let (f, g) = eval(&point(a));
        (f, directions.iter().map(|d| d.iter().zip(&g).map(|(di, gi)| di * gi).sum()).collect())
    });
    (point(&a), report)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SETTINGS: NewtonSettings =
        NewtonSettings { iterations: 5, fd_step: 1e-4, max_step: 10.0, min_curvature_ratio: 0.0, rest_tolerance: 0.0 };

    /// The offsets of `x` from the valley's minimum (1, 2) along its steep and its flat
    /// direction.
    fn offsets(x: &[f64]) -> (f64, f64) {
        ((x[0] - 1.0 + x[1] - 2.0) / 2f64.sqrt(), (x[0] - 1.0 - (x[1] - 2.0)) / 2f64.sqrt())
    }

    /// `0.5 (x - c)^T A (x - c)` with a valley 10^4 times flatter one way than the other, along
    /// a diagonal, where per-parameter steps do worst.
    fn valley(x: &[f64]) -> (f64, Vec<f64>) {
        let (a, b) = (1.0, 1e-4);
        let (p, q) = offsets(x);
        let f = 0.5 * (a * p * p + b * q * q);
        let (dp, dq) = (a * p, b * q);
        (f, vec![(dp + dq) / 2f64.sqrt(), (dp - dq) / 2f64.sqrt()])
    }

    #[test]
    fn a_diagonal_valley_ten_thousand_times_flatter_one_way_is_crossed_in_one_step() {
        let distance = |x: &[f64]| (x[0] - 1.0).hypot(x[1] - 2.0);
        let one = NewtonSettings { iterations: 1, ..SETTINGS };
        let (x, report) = newton_minimise(&[-3.0, 5.0], &one, valley);
        // From 5 away along the valley, the damping leaves under 1 % of the way.
        assert!(distance(&x) < 0.05 && report.taken == 1 && report.evaluations == 4, "{x:?} {report:?}");
        let (x, report) = newton_minimise(&[-3.0, 5.0], &SETTINGS, valley);
        assert!(distance(&x) < 1e-4 && report.end < 1e-9 && report.start > 0.25, "{x:?} {report:?}");
    }

    #[test]
    fn a_direction_flatter_than_the_floor_is_held_while_the_steep_one_is_solved() {
        // The valley's flat direction is 10^-4 of the steep one's curvature: under a floor of
        // 10^-3 it keeps its offset, while the steep offset goes.
        let held = NewtonSettings { min_curvature_ratio: 1e-3, ..SETTINGS };
        let start = [-3.0, 5.0];
        let (x, report) = newton_minimise(&start, &held, valley);
        let ((p, q), (_, q0)) = (offsets(&x), offsets(&start));
        assert!(p.abs() < 1e-6 && (q - q0).abs() < 1e-9 && report.taken >= 1, "{x:?} {report:?}");
        // Under a floor of 10^-5 both are free, and the minimum is reached.
        let (x, _) = newton_minimise(&start, &NewtonSettings { min_curvature_ratio: 1e-5, ..SETTINGS }, valley);
        assert!((x[0] - 1.0).hypot(x[1] - 2.0) < 1e-4, "{x:?}");
    }

    #[test]
    fn a_held_direction_is_set_to_rest_only_where_the_objective_hardly_rises() {
        // 1 + 0.5 (p^2 + 1e-4 (q - q_min)^2), p and q the valley's steep and flat offsets from
        // (1, 2); rest (the origin) lies at p = -2.12, q = 0.71 from there. With the valley's
        // minimum on the flat line through rest, rest costs nothing along it; off it, setting
        // the flat offset to rest's costs 0.5e-4 (q_min - 0.71)^2.
        let shifted = |q_min: f64| {
            move |x: &[f64]| {
                let (p, q) = offsets(x);
                let (a, b) = (1.0, 1e-4);
                let (dp, dq) = (a * p, b * (q - q_min));
                (1.0 + 0.5 * (a * p * p + b * (q - q_min).powi(2)), vec![(dp + dq) / 2f64.sqrt(), (dp - dq) / 2f64.sqrt()])
            }
        };
        let at_rest = offsets(&[0.0, 0.0]).1;
        let rest = NewtonSettings { min_curvature_ratio: 1e-3, rest_tolerance: 1e-3, ..SETTINGS };
        // The flat offset starts 3 from rest and the minimum is on rest's flat coordinate: set
        // to rest, the objective falls.
        let start = [-3.0, 5.0];
        let (x, report) = newton_minimise(&start, &rest, shifted(at_rest));
        let (p, q) = offsets(&x);
        let rested = report.rest.expect("tried");
        assert!(rested.taken && p.abs() < 1e-6 && (q - at_rest).abs() < 1e-6 && report.end <= 1.0 + 1e-9, "{x:?} {report:?}");
        // The minimum 10 along the flat line from rest, and the start on its flat coordinate:
        // rest costs 0.5e-4 x 100 = 5e-3 of 1, over the tolerance, so the held offset stays.
        let (p0, q0) = (1.0, at_rest + 10.0);
        let start = [1.0 + (p0 + q0) / 2f64.sqrt(), 2.0 + (p0 - q0) / 2f64.sqrt()];
        let (x, report) = newton_minimise(&start, &rest, shifted(q0));
        let rested = report.rest.expect("tried");
        assert!(!rested.taken && (rested.after - rested.before - 5e-3).abs() < 1e-4, "{report:?}");
        assert!((offsets(&x).1 - q0).abs() < 1e-9 && report.end == rested.before, "{x:?} {report:?}");
    }

    #[test]
    fn the_held_direction_is_set_by_a_second_objective_and_the_steep_one_is_kept() {
        // The valley (minimum (1, 2), flat along (1, -1)) holds its flat direction under a floor
        // of 10^-3. A second objective, least at (4, 1), decides that direction alone: from a
        // point off the valley floor, the step moves along (1, -1) only, to where the second
        // objective is least along that line, not to its minimum.
        let held = held_directions(&[1.0, 2.0], 1e-4, 1e-3, valley);
        assert_eq!(held.len(), 1);
        let d = &held[0];
        assert!((d[0] + d[1]).abs() < 1e-6 && (d[0].abs() - 0.5f64.sqrt()).abs() < 1e-6, "{held:?}");
        let second = |x: &[f64]| ((x[0] - 4.0).powi(2) + (x[1] - 1.0).powi(2), vec![2.0 * (x[0] - 4.0), 2.0 * (x[1] - 1.0)]);
        let start = [1.5, 2.5];
        let (x, report) = newton_within(&start, &held, &SETTINGS, second);
        // Along (1, -1) from (1.5, 2.5), the point nearest (4, 1) is (3.5, 0.5): the valley's
        // steep coordinate x + y stays 4.
        assert!((x[0] - 3.5).abs() < 1e-6 && (x[1] - 0.5).abs() < 1e-6, "{x:?} {report:?}");
        assert!(report.end < report.start && report.taken >= 1, "{report:?}");
        // No floor, nothing held.
        assert!(held_directions(&[1.0, 2.0], 1e-4, 0.0, valley).is_empty());
    }

    #[test]
    fn rosenbrock_only_ever_goes_down_and_ends_near_its_minimum() {
        let rosenbrock = |x: &[f64]| {
            let (a, b) = (1.0 - x[0], x[1] - x[0] * x[0]);
            (a * a + 100.0 * b * b, vec![-2.0 * a - 400.0 * x[0] * b, 200.0 * b])
        };
        let settings = NewtonSettings { iterations: 40, ..SETTINGS };
        let mut last = f64::INFINITY;
        let (x, report) = newton_minimise(&[-1.2, 1.0], &settings, |x| {
            let out = rosenbrock(x);
            last = last.min(out.0);
            out
        });
        assert!(report.end <= report.start && report.end <= last + 1e-15, "{report:?}");
        assert!((x[0] - 1.0).abs() < 1e-3 && (x[1] - 1.0).abs() < 2e-3, "{x:?} {report:?}");
    }

    #[test]
    fn a_step_is_never_longer_than_the_limit_and_a_flat_objective_is_left_where_it_is() {
        let settings = NewtonSettings { iterations: 1, fd_step: 1e-3, max_step: 0.5, min_curvature_ratio: 0.0, rest_tolerance: 0.0 };
        let (x, report) = newton_minimise(&[0.0, 0.0], &settings, valley);
        assert!((x[0].hypot(x[1]) - 0.5).abs() < 1e-9 && report.taken == 1, "{x:?}");
        let (x, report) = newton_minimise(&[3.0, -1.0], &SETTINGS, |_| (2.0, vec![0.0, 0.0]));
        assert_eq!((x, report.taken, report.end), (vec![3.0, -1.0], 0, 2.0));
    }
}
