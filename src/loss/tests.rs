//! Properties of the built-in loss terms on small hand-made bands.

use super::*;
use crate::model::motion::{ConstantVelocity, MotionModel, PiecewiseConstant};
use crate::render::RenderOutput;
use burn::tensor::{Device, Tensor, TensorData};

fn band(values: Vec<f32>, rows: usize, width: usize, device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(values, [rows * width, 1]), device)
}

fn output(colour: Tensor<2>, disparity: Vec<f32>, device: &Device) -> RenderOutput {
    let n = disparity.len();
    RenderOutput { colour, disparity: Tensor::from_data(TensorData::new(disparity, [n]), device), alpha: Tensor::ones([n], device) }
}

fn value(
    term: &dyn LossTerm,
    out: &RenderOutput,
    target: &Tensor<2>,
    rows: usize,
    width: usize,
    motion: Option<MotionInput>,
) -> Option<f32> {
    term.evaluate(&LossInput { rendered: out, target, rows, width, motion }).map(|t| t.into_scalar::<f32>())
}

#[test]
fn photometric_terms_vanish_on_a_perfect_render_and_grow_with_the_error() {
    let device = Device::flex();
    let (rows, width) = (4, 5);
    let target: Vec<f32> = (0..20).map(|i| ((i * 7) % 10) as f32 / 10.0).collect();
    let t = band(target.clone(), rows, width, &device);
    let perfect = output(t.clone(), vec![0.0; 20], &device);
    let off = output(band(target.iter().map(|v| v + 0.1).collect(), rows, width, &device), vec![0.0; 20], &device);
    for term in [&L1 as &dyn LossTerm, &L2, &DSsim] {
        let a = value(term, &perfect, &t, rows, width, None).unwrap();
        assert!(a.abs() < 1e-6, "{}: {a}", term.name());
    }
    assert!((value(&L1, &off, &t, rows, width, None).unwrap() - 0.1).abs() < 1e-5);
    assert!((value(&L2, &off, &t, rows, width, None).unwrap() - 0.01).abs() < 1e-5);
    // A constant offset barely changes structure; a scrambled image does.
    let scrambled = output(band(target.iter().rev().copied().collect(), rows, width, &device), vec![0.0; 20], &device);
    assert!(value(&DSsim, &scrambled, &t, rows, width, None).unwrap() > 5.0 * value(&DSsim, &off, &t, rows, width, None).unwrap());
}

#[test]
fn smoothness_costs_disparity_steps_less_across_image_edges() {
    let device = Device::flex();
    let (rows, width) = (3, 6);
    // Image: an edge between columns 2 and 3. Disparity: a step at the edge or beside it.
    let image: Vec<f32> = (0..18).map(|i| if i % 6 < 3 { 0.1 } else { 0.9 }).collect();
    let t = band(image, rows, width, &device);
    let step_at = |col: usize| output(t.clone(), (0..18).map(|i| if i % 6 < col { 0.0 } else { 1.0 }).collect(), &device);
    let flat = value(&EdgeAwareSmoothness, &output(t.clone(), vec![0.5; 18], &device), &t, rows, width, None).unwrap();
    let on_edge = value(&EdgeAwareSmoothness, &step_at(3), &t, rows, width, None).unwrap();
    let off_edge = value(&EdgeAwareSmoothness, &step_at(2), &t, rows, width, None).unwrap();
    assert!(flat.abs() < 1e-6 && on_edge > 0.0 && off_edge > 100.0 * on_edge, "flat {flat}, on edge {on_edge}, off edge {off_edge}");
}

#[test]
fn the_motion_prior_applies_only_with_motion() {
    let device = Device::flex();
    let t = band(vec![0.0; 4], 2, 2, &device);
    let out = output(t.clone(), vec![0.0; 4], &device);
    assert!(value(&MotionPrior, &out, &t, 2, 2, None).is_none());
    let m = Tensor::<1>::from_data(TensorData::new(vec![1.0f32, -2.0, 0.0, 3.0, 0.0, 0.0], [6]), &device);
    let motion = MotionInput { scaled: &m, model: &ConstantVelocity };
    assert!((value(&MotionPrior, &out, &t, 2, 2, Some(motion)).unwrap() - 14.0 / 6.0).abs() < 1e-6);
}

/// `piecewise_constant` with `k` segments; the read-out interval does not enter its roughness.
fn piecewise(k: usize) -> PiecewiseConstant {
    PiecewiseConstant { segments: k, readout: (-0.015, 0.015) }
}

/// The scaled parameters of `k` segments whose six rates are `rate(segment, entry)`.
fn segment_rates(k: usize, rate: impl Fn(usize, usize) -> f32, device: &Device) -> Tensor<1> {
    let v: Vec<f32> = (0..k).flat_map(|j| (0..6).map(move |e| (j, e))).map(|(j, e)| rate(j, e)).collect();
    Tensor::from_data(TensorData::new(v, [6 * k]), device)
}

#[test]
fn motion_smoothness_is_free_for_rates_that_change_linearly_and_costs_a_jolt() {
    let device = Device::flex();
    let t = band(vec![0.0; 4], 2, 2, &device);
    let out = output(t.clone(), vec![0.0; 4], &device);
    let eval = |m: &Tensor<1>, model: &dyn MotionModel| value(&MotionSmoothness, &out, &t, 2, 2, Some(MotionInput { scaled: m, model }));
    let (k, model) = (5, piecewise(5));
    // Rates on a line in time (a constant acceleration), each entry its own line: no cost.
    let ramp = segment_rates(k, |j, e| 0.3 * e as f32 - 1.0 + (e as f32 - 2.5) * 0.7 * j as f32, &device);
    assert!(eval(&ramp, &model).unwrap().abs() < 1e-10, "{:?}", eval(&ramp, &model));
    // A jolt: entry 1 steps by 2 between segments 2 and 3. Its second differences over the
    // three inner segments are (0, 2, -2), every other entry's zero: mean over 6 (K - 2) = 18.
    let jolt = segment_rates(k, |j, e| if e == 1 && j >= 3 { 2.0 } else { 0.0 }, &device);
    assert!((eval(&jolt, &model).unwrap() - 8.0 / 18.0).abs() < 1e-6);
    // No roughness to measure: the smooth models, fewer than three segments, no motion.
    let six = segment_rates(1, |_, e| e as f32, &device);
    assert!(eval(&six, &ConstantVelocity).is_none());
    assert!(eval(&segment_rates(2, |j, _| j as f32, &device), &piecewise(2)).is_none());
    assert!(value(&MotionSmoothness, &out, &t, 2, 2, None).is_none());
}

#[test]
fn motion_smoothness_gradients_match_finite_differences() {
    let device = Device::flex().autodiff();
    let t = band(vec![0.0; 4], 2, 2, &device);
    let out = output(t.clone(), vec![0.0; 4], &device);
    let (k, model) = (4, piecewise(4));
    let x: Vec<f32> = (0..6 * k).map(|i| ((i * 37 % 11) as f32 - 5.0) / 3.0).collect();
    let at = |x: &[f32]| Tensor::<1>::from_data(TensorData::new(x.to_vec(), [6 * k]), &device);
    let f = |m: &Tensor<1>| {
        MotionSmoothness.evaluate(&LossInput {
            rendered: &out,
            target: &t,
            rows: 2,
            width: 2,
            motion: Some(MotionInput { scaled: m, model: &model }),
        })
    };
    let leaf = at(&x).require_grad();
    let grad = crate::device::host_values(leaf.grad(&f(&leaf).unwrap().backward()).unwrap());
    let h = 1e-2;
    for i in 0..6 * k {
        let shifted = |d: f32| {
            let mut y = x.clone();
            y[i] += d;
            f(&at(&y)).unwrap().into_scalar::<f32>()
        };
        let numeric = (shifted(h) - shifted(-h)) / (2.0 * h);
        assert!((grad[i] - numeric).abs() < 1e-3 * (1.0 + numeric.abs()), "entry {i}: autodiff {} vs finite difference {numeric}", grad[i]);
    }
}

#[test]
fn the_registry_builds_what_a_config_lists_and_names_what_it_lacks() {
    use crate::config::LossConfig;
    let registry = LossRegistry::default();
    assert_eq!(registry.names(), vec!["dssim", "l1", "l2", "motion_prior", "motion_smoothness", "smoothness"]);
    let built = registry.build(&[LossConfig::new("l2", 2.0), LossConfig::new("l1", 0.5)]).unwrap();
    let device = Device::flex();
    let t = band(vec![0.0; 4], 2, 2, &device);
    let out = output(band(vec![0.2; 4], 2, 2, &device), vec![0.0; 4], &device);
    let total = built.evaluate(&LossInput { rendered: &out, target: &t, rows: 2, width: 2, motion: None }).unwrap().into_scalar::<f32>();
    assert!((total - (2.0 * 0.04 + 0.5 * 0.2)).abs() < 1e-6, "{total}");
    let err = registry.build(&[LossConfig::new("perceptual", 1.0)]).err().unwrap().to_string();
    assert!(err.contains("perceptual") && err.contains("smoothness"), "{err}");
}

#[test]
fn the_terms_that_score_the_motion_alone_are_those_with_nothing_to_score_without_one() {
    use crate::config::LossConfig;
    let registry = LossRegistry::default();
    let device = Device::flex();
    let t = band(vec![0.1, 0.4, 0.3, 0.9, 0.2, 0.6, 0.5, 0.8, 0.7], 3, 3, &device);
    let out = output(band(vec![0.2; 9], 3, 3, &device), vec![0.0, 0.5, 1.0, 0.2, 0.3, 0.9, 1.0, 0.1, 0.4], &device);
    let all: Vec<LossConfig> = registry.names().into_iter().map(|n| LossConfig::new(n, 1.0)).collect();
    for term in registry.build(&all).unwrap().terms {
        let scored = term.term.evaluate(&LossInput { rendered: &out, target: &t, rows: 3, width: 3, motion: None }).is_some();
        assert_eq!(scored, !term.term.scores_motion_only(), "{}", term.term.name());
    }
    let stage1 = registry.build(&all).unwrap().without_motion_terms();
    assert_eq!(stage1.names(), vec!["dssim×1", "l1×1", "l2×1", "smoothness×1"]);
}
