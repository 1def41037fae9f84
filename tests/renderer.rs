//! The Gaussian renderer: exact gradients (against finite differences), the same images on flex
//! and wgpu, and a deterministic stage 1.

mod common;

use burn::tensor::{Device, Tensor, TensorData};
use rslf::device::host_values;
use rslf::model::{GaussianSet, Gaussians};
use rslf::render::{PixelBins, RenderOutput, RenderSettings, SURFACE_HIDING, Splats, bins_for_view, render, splat_with_surface};

const W: usize = 20;
const H: usize = 14;
const OFFSET: (f32, f32) = (2.0, -1.0); // a corner-like view, so disparity moves the centres

/// Twelve Gaussians whose centres sit between pixel centres (no opacity clamp is active).
fn scene_set() -> GaussianSet {
    let mut rng = rslf::random::Rng::new(7);
    let n = 12;
    let mut set = GaussianSet { u: vec![], v: vec![], disparity: vec![], size: vec![], colour: vec![], channels: 3 };
    for _ in 0..n {
        set.u.push((rng.range(4.0, 16.0).floor() + rng.range(0.3, 0.7)) as f32);
        set.v.push((rng.range(3.0, 11.0).floor() + rng.range(0.3, 0.7)) as f32);
        set.disparity.push(rng.range(-1.0, 1.0) as f32);
        set.size.push(rng.range(1.2, 2.0) as f32);
        for _ in 0..3 {
            set.colour.push(rng.range(0.0, 1.0) as f32);
        }
    }
    set
}

/// A scalar of every output: `Σ wc·colour + Σ wd·disparity + Σ wa·alpha` with fixed weights.
fn objective(out: RenderOutput, device: &Device) -> Tensor<1> {
    let p = W * H;
    let mut rng = rslf::random::Rng::new(3);
    let mut weights = |n: usize| -> Vec<f32> { (0..n).map(|_| rng.range(-1.0, 1.0) as f32).collect() };
    let wc = Tensor::<2>::from_data(TensorData::new(weights(p * 3), [p, 3]), device);
    let wd = Tensor::<1>::from_data(TensorData::new(weights(p), [p]), device);
    let wa = Tensor::<1>::from_data(TensorData::new(weights(p), [p]), device);
    (out.colour * wc).sum() + (out.disparity * wd).sum() + (out.alpha * wa).sum()
}

fn value(set: &GaussianSet, bins: &PixelBins, device: &Device) -> f64 {
    let g = set.to_module(device);
    objective(render(&g, OFFSET, bins, device), device).into_scalar::<f32>() as f64
}

fn grad_vec<const D: usize>(t: Option<Tensor<D>>) -> Vec<f32> {
    host_values(t.expect("gradient present"))
}

#[test]
fn autodiff_gradients_match_central_finite_differences_for_every_parameter_kind() {
    let device = Device::flex().autodiff();
    let set = scene_set();
    let settings = RenderSettings { max_per_pixel: 8, cutoff_sigma: 3.0 };
    // The discrete bookkeeping is held fixed, as it is within one optimisation step.
    let bins = bins_for_view(&set, OFFSET, W, 0..H, &settings);
    let g: Gaussians = set.to_module(&device);
    let grads = objective(render(&g, OFFSET, &bins, &device), &device).backward();
    let centre = grad_vec(g.centre.val().grad(&grads));
    let disparity = grad_vec(g.disparity.val().grad(&grads));
    let log_size = grad_vec(g.log_size.val().grad(&grads));
    let colour = grad_vec(g.colour.val().grad(&grads));

    let h = 1e-2f32;
    let check = |name: &str, i: usize, analytic: f32, perturb: &dyn Fn(&mut GaussianSet, f32)| {
        let (mut plus, mut minus) = (set.clone(), set.clone());
        perturb(&mut plus, h);
        perturb(&mut minus, -h);
        let fd = (value(&plus, &bins, &device) - value(&minus, &bins, &device)) / (2.0 * h as f64);
        let err = (fd - analytic as f64).abs();
        assert!(err <= 2e-3 + 1e-2 * fd.abs(), "{name}[{i}]: autodiff {analytic}, finite difference {fd}");
    };
    let mut checked = 0;
    for i in 0..set.len() {
        check("u", i, centre[2 * i], &|s, e| s.u[i] += e);
        check("v", i, centre[2 * i + 1], &|s, e| s.v[i] += e);
        check("disparity", i, disparity[i], &|s, e| s.disparity[i] += e);
        // Size is parametrised as ln σ: perturb ln σ.
        check("log_size", i, log_size[i], &|s, e| s.size[i] *= e.exp());
        for c in 0..3 {
            check("colour", i, colour[3 * i + c], &|s, e| s.colour[3 * i + c] += e);
        }
        checked += 7;
    }
    assert_eq!(checked, 84);
    assert!(disparity.iter().any(|g| g.abs() > 1e-2), "disparity gradients are exercised");
}

/// The surface disparity and the composited (blended over opacity) one of the 16 pixels of one
/// row under Gaussians on that row at columns `u`, front to back by `disparity`, of sizes `size`.
fn one_row_maps(u: &[f32], disparity: &[f32], size: &[f32]) -> (Vec<f32>, Vec<f32>) {
    let n = u.len();
    let set = GaussianSet {
        u: u.to_vec(),
        v: vec![0.0; n],
        disparity: disparity.to_vec(),
        size: size.to_vec(),
        colour: (0..n).map(|i| (i % 2) as f32).collect(),
        channels: 1,
    };
    let device = Device::flex();
    let g = set.to_module(&device);
    let bins = bins_for_view(&set, (0.0, 0.0), 16, 0..1, &RenderSettings::default());
    let (out, surface) = splat_with_surface(&Splats::of_view(&g, (0.0, 0.0)), &bins, &device);
    let composited = host_values(out.disparity).iter().zip(host_values(out.alpha)).map(|(d, a)| d / a).collect();
    (host_values(surface), composited)
}

#[test]
fn the_surface_disparity_is_the_one_a_foreground_tail_only_tints() {
    // A small near Gaussian (disparity 2) at u = 4 in front of a wide far one (-1) at u = 8, on
    // one row: the blended disparity bleeds the near one's tail over the far surface beside it.
    let (surface, blended) = one_row_maps(&[4.0, 8.0], &[2.0, -1.0], &[1.5, 4.0]);
    assert_eq!(surface[4], 2.0, "the near Gaussian's centre");
    for x in 6..12 {
        assert_eq!(surface[x], -1.0, "pixel {x}: {surface:?}");
    }
    // Two sigmas (3 px) from the near centre the blended map is still over 0.07 px off the far
    // surface's -1 (BadPix(0.07) counts the pixel); the surface map is not.
    assert!(blended[7] > -1.0 + 0.07, "{blended:?}");

    // Two overlapping Gaussians 0.2 px of disparity apart are one surface: between them a pixel
    // takes a weighted mean of their disparities, not the median one's alone.
    let (surface, _) = one_row_maps(&[6.0, 10.0], &[-1.0, -1.2], &[2.0, 2.0]);
    assert!(surface[8] > -1.2 && surface[8] < -1.0 - 0.01, "{surface:?}");
}

#[test]
fn within_a_surface_the_nearer_splat_is_not_favoured_as_compositing_favours_it() {
    // Two splats of one surface at the same centre, 0.2 px of disparity apart (the near one in
    // front). One sigma from the centre each has opacity a = exp(-1/2): compositing weighs them
    // a and a (1 - a); the surface disparity weighs them a and a (1 - a)^SURFACE_HIDING.
    let (surface, composited) = one_row_maps(&[8.0, 8.0], &[-0.9, -1.1], &[1.0, 1.0]);
    let a = (-0.5f32).exp();
    let back = (1.0 - a).powf(SURFACE_HIDING);
    let expected = (-0.9 - 1.1 * back) / (1.0 + back);
    assert!((surface[7] - expected).abs() < 1e-5, "{} against {expected}", surface[7]);
    assert!((composited[7] - (-0.9 - 1.1 * (1.0 - a)) / (2.0 - a)).abs() < 1e-5, "{}", composited[7]);
    assert!(surface[7] < composited[7] - 0.005, "nearer the surface's mean -1 than compositing: {} against {}", surface[7], composited[7]);
    assert_eq!(surface[7], surface[9], "symmetric about the centre");
}

fn render_values(device: &Device) -> Vec<f32> {
    let set = scene_set();
    let settings = RenderSettings::default();
    let bins = bins_for_view(&set, OFFSET, W, 0..H, &settings);
    let out = render(&set.to_module(device), OFFSET, &bins, device);
    let mut v = host_values(out.colour);
    v.extend(host_values(out.disparity));
    v.extend(host_values(out.alpha));
    v
}

#[test]
fn flex_and_wgpu_render_the_same_images() {
    let flex = render_values(&Device::flex());
    let wgpu = render_values(&Device::wgpu(burn::tensor::DeviceKind::DefaultDevice));
    assert_eq!(flex.len(), wgpu.len());
    let worst = flex.iter().zip(&wgpu).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(worst <= 1e-4, "largest difference between flex and wgpu: {worst}");
    assert!(flex.iter().any(|v| v.abs() > 0.1), "the image is not empty");
}

#[test]
fn the_same_config_and_seed_give_the_same_stage_one_result_twice_on_flex() {
    let dir = common::tempdir();
    let scene_dir = dir.path().join("plane");
    common::write_plane_scene(&scene_dir, 48, 32, 5, 0.5, |_| true);
    common::params(48, 32, 5).write(&scene_dir.join("parameters.cfg")).unwrap();
    let scene = rslf::io::Scene::load(&scene_dir).unwrap();
    let config = rslf::config::Config::parse(
        "seed = 11\n[stage1]\ngaussians = 300\niterations = 6\nband_height = 16\ndisparity_step = 0.1\n",
        std::path::Path::new("test.toml"),
    )
    .unwrap();
    let device = rslf::device::device(config.device).unwrap();
    let (a, _) = rslf::pipeline::run(&config, &scene, &device).unwrap();
    let (b, _) = rslf::pipeline::run(&config, &scene, &device).unwrap();
    assert_eq!(a.disparity, b.disparity);
    assert_eq!(a.central, b.central);
    assert_eq!(a.curves, b.curves);
    assert_eq!(a.curves[0].1.len(), 6);
}
