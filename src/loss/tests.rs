//! Properties of the built-in loss terms on small hand-made bands.

use super::*;
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
    motion: Option<&Tensor<1>>,
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
    let m = Tensor::<1>::from_data(TensorData::new(vec![1.0f32, -2.0, 0.0, 3.0], [4]), &device);
    assert!((value(&MotionPrior, &out, &t, 2, 2, Some(&m)).unwrap() - 3.5).abs() < 1e-6);
}

#[test]
fn the_registry_builds_what_a_config_lists_and_names_what_it_lacks() {
    use crate::config::LossConfig;
    let registry = LossRegistry::default();
    assert_eq!(registry.names(), vec!["dssim", "l1", "l2", "motion_prior", "smoothness"]);
    let built = registry.build(&[LossConfig::new("l2", 2.0), LossConfig::new("l1", 0.5)]).unwrap();
    let device = Device::flex();
    let t = band(vec![0.0; 4], 2, 2, &device);
    let out = output(band(vec![0.2; 4], 2, 2, &device), vec![0.0; 4], &device);
    let total = built.evaluate(&LossInput { rendered: &out, target: &t, rows: 2, width: 2, motion: None }).unwrap().into_scalar::<f32>();
    assert!((total - (2.0 * 0.04 + 0.5 * 0.2)).abs() < 1e-6, "{total}");
    let err = registry.build(&[LossConfig::new("perceptual", 1.0)]).err().unwrap().to_string();
    assert!(err.contains("perceptual") && err.contains("smoothness"), "{err}");
}
