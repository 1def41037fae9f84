//! The motion models as tensor programs: they give the poses of FORMAT's laws (checked against
//! the host implementation used by the generator and the evaluation), their gradients match
//! finite differences through the whole rolling-shutter render, and the registry builds them by
//! name, each from the shipped config named after it.

mod common;

use burn::tensor::{Device, Tensor, TensorData};
use rslf::config::{Config, MotionConfig};
use rslf::geometry::{Camera, Pose, TensorCamera, ViewGrid, pose_at};
use rslf::io::MotionRecord;
use rslf::model::GaussianSet;
use rslf::model::motion::{MotionModel, MotionRegistry, MotionSetup, Tabulated};
use rslf::pipeline::Registries;
use rslf::render::{RenderSettings, RsTiming, StaticShape, ViewWindow, render_rolling_shutter};

const READOUT: (f64, f64) = (-0.02, 0.02);

use rslf::device::host_values as host;

fn model(name: &str, segments: usize) -> Box<dyn MotionModel> {
    let config = MotionConfig { model: name.into(), segments };
    MotionRegistry::default().build(&config, &MotionSetup { readout: READOUT }).unwrap()
}

fn records() -> Vec<(Box<dyn MotionModel>, MotionRecord)> {
    vec![
        (model("constant_velocity", 1), MotionRecord::ConstantVelocity { omega_rad_s: [0.3, -0.5, 1.2], velocity_m_s: [0.8, -0.4, 2.0] }),
        (
            model("constant_acceleration", 1),
            MotionRecord::ConstantAcceleration {
                omega_rad_s: [0.3, -0.5, 0.2],
                velocity_m_s: [0.8, -0.4, 1.0],
                alpha_rad_s2: [20.0, 5.0, -30.0],
                accel_m_s2: [-40.0, 10.0, 25.0],
            },
        ),
        (
            model("piecewise_constant", 3),
            MotionRecord::PiecewiseConstant {
                omega_rad_s: vec![[0.3, 0.0, 0.0], [0.0, -4.0, 0.0], [0.0, 0.0, 5.0]],
                velocity_m_s: vec![[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]],
            },
        ),
        (
            model("piecewise_constant", 4),
            MotionRecord::PiecewiseConstant {
                omega_rad_s: vec![[0.3, 0.1, 0.0], [0.0, -4.0, 0.2], [1.0, 0.0, 5.0], [-2.0, 1.0, 0.0]],
                velocity_m_s: vec![[1.0, 0.0, 0.5], [0.0, 2.0, 0.0], [0.0, -1.0, 3.0], [2.0, 0.0, 0.0]],
            },
        ),
    ]
}

#[test]
fn tensor_poses_follow_the_host_laws_of_every_model() {
    let device = Device::flex();
    let times = [-0.03, -0.02, -0.011, -0.0067, 0.0, 0.004, 0.0067, 0.013, 0.02, 0.025];
    for (m, record) in records() {
        let params = m.parameters_of(&record).expect("the model expresses its own record");
        assert_eq!(params.len(), m.parameters().len(), "{}", m.name());
        assert_eq!(m.record(&params), record, "{}: parameters round-trip", m.name());
        let p = Tensor::<1>::from_data(TensorData::new(params.iter().map(|&x| x as f32).collect::<Vec<_>>(), [params.len()]), &device);
        let t = Tensor::<1>::from_data(TensorData::new(times.iter().map(|&x| x as f32).collect::<Vec<_>>(), [times.len()]), &device);
        let poses = m.poses(p, t);
        let (r, tr) = (host(poses.rotation), host(poses.translation));
        for (i, &time) in times.iter().enumerate() {
            let expected: Pose = pose_at(&record, time, READOUT);
            for a in 0..3 {
                for b in 0..3 {
                    let got = r[i * 9 + a * 3 + b] as f64;
                    assert!(
                        (got - expected.rotation[(a, b)]).abs() < 2e-6,
                        "{} t={time} R[{a}{b}] {got} vs {}",
                        m.name(),
                        expected.rotation[(a, b)]
                    );
                }
                let got = tr[i * 3 + a] as f64;
                assert!((got - expected.translation[a]).abs() < 2e-6, "{} t={time} T[{a}] {got} vs {}", m.name(), expected.translation[a]);
            }
        }
    }
}

/// The times of the table tests: inside the read-out, beside the piecewise models' segment
/// boundaries (-0.01, 0 and 0.01 with four segments, on knots of the table; ±0.00667 with three,
/// inside an interval of it), and just beyond the table at both ends (half a millisecond).
const TABLE_TIMES: [f64; 13] = [-0.0255, -0.02, -0.0101, -0.00999, -0.00668, -0.0031, 0.0, 0.00417, 0.00668, 0.0099, 0.0102, 0.019, 0.0254];

/// The piecewise models' segment boundaries, all of them.
const BOUNDARIES: [f64; 5] = [-0.01, -0.02 / 3.0, 0.0, 0.02 / 3.0, 0.01];

/// `Σ w · (R, T)` of the poses at `times` for fixed weights: one number that every entry of
/// every pose moves.
fn pose_sum(m: &dyn MotionModel, p: Tensor<1>, times: Tensor<1>) -> Tensor<1> {
    let poses = m.poses(p, times);
    let n = poses.translation.dims()[0];
    let device = poses.translation.device();
    let weights = |k: usize| {
        Tensor::<1>::from_data(TensorData::new((0..k).map(|i| ((i * 7 % 13) as f32 - 6.0) / 6.0).collect::<Vec<_>>(), [k]), &device)
    };
    (poses.rotation.reshape([n * 9]) * weights(n * 9)).sum() + (poses.translation.reshape([n * 3]) * weights(n * 3)).sum()
}

#[test]
fn a_tabulated_model_gives_the_poses_and_gradients_of_the_model_it_reads() {
    let device = Device::flex().autodiff();
    // Four samples per row of a 256-row read-out of 0.04 s, 0.005 s beyond it each side.
    let step = (READOUT.1 - READOUT.0) / (4.0 * 256.0);
    let to_tensor =
        |v: &[f64]| Tensor::<1>::from_data(TensorData::new(v.iter().map(|&x| x as f32).collect::<Vec<_>>(), [v.len()]), &device);
    for (m, record) in records() {
        let table = Tabulated::with_step(m.as_ref(), (READOUT.0 - 0.005, READOUT.1 + 0.005), step);
        let params = m.parameters_of(&record).unwrap();
        let (direct, tabulated) =
            (m.poses(to_tensor(&params), to_tensor(&TABLE_TIMES)), table.poses(to_tensor(&params), to_tensor(&TABLE_TIMES)));
        // A change of rate inside an interval of the table is blended over it: off by at most
        // the jump (here up to 6.4 rad/s, 3.6 m/s) times a quarter step, 6e-5.
        for (a, b, what) in [
            (direct.rotation.reshape([-1]), tabulated.rotation.reshape([-1]), "R"),
            (direct.translation.reshape([-1]), tabulated.translation.reshape([-1]), "T"),
        ] {
            let (a, b) = (host(a), host(b));
            for (i, (x, y)) in a.iter().zip(&b).enumerate() {
                assert!(
                    (x - y).abs() < 1e-4,
                    "{} {what}[{i}] at t = {}: model {x}, table {y}",
                    m.name(),
                    TABLE_TIMES[i / if what == "R" { 9 } else { 3 }]
                );
            }
        }
        // Gradients with respect to the parameters and to the times (the rows' read-out
        // times carry the per-Gaussian timing's fixed point).
        let grads = |model: &dyn MotionModel| {
            let (p, t) = (to_tensor(&params).require_grad(), to_tensor(&TABLE_TIMES).require_grad());
            let g = pose_sum(model, p.clone(), t.clone()).backward();
            (host(p.grad(&g).unwrap()), host(t.grad(&g).unwrap()))
        };
        let ((dp, dt), (tp, tt)) = (grads(m.as_ref()), grads(&table));
        let scale = dp.iter().fold(0f32, |a, x| a.max(x.abs()));
        for (i, (x, y)) in dp.iter().zip(&tp).enumerate() {
            assert!((x - y).abs() < 1e-3 * scale, "{} d/dparam {i}: model {x}, table {y}", m.name());
        }
        // With respect to time the table's slope is its interval's: off by the rate's change
        // over one step, except next to a change of rate, where it is the blend of both sides.
        for (i, (x, y)) in dt.iter().zip(&tt).enumerate() {
            let near_boundary = BOUNDARIES.iter().any(|b| (TABLE_TIMES[i] - b).abs() < step) && m.name() == "piecewise_constant";
            if !near_boundary {
                assert!((x - y).abs() < 1e-2 * x.abs().max(1.0), "{} d/dt at t = {}: model {x}, table {y}", m.name(), TABLE_TIMES[i]);
            }
        }
    }
}

#[test]
fn the_registry_names_its_models_and_refuses_unknown_ones() {
    let registry = MotionRegistry::default();
    assert_eq!(registry.names(), vec!["constant_acceleration", "constant_velocity", "piecewise_constant"]);
    let setup = MotionSetup { readout: READOUT };
    let err = registry.build(&MotionConfig { model: "helical".into(), segments: 1 }, &setup).err().unwrap().to_string();
    assert!(err.contains("helical") && err.contains("constant_velocity"), "{err}");
    let err = registry.build(&MotionConfig { model: "piecewise_constant".into(), segments: 0 }, &setup).err().unwrap().to_string();
    assert!(err.contains("segments"), "{err}");
}

#[test]
fn each_built_in_model_has_a_shipped_config_named_after_it_that_reads_and_builds() {
    let mut names = Vec::new();
    for entry in std::fs::read_dir(common::project_path("configs")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let config = Config::read(&path).unwrap_or_else(|e| panic!("{e}"));
        // Every loss term and the model it names exist and take their settings.
        Registries::default().check(&config).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap().to_string();
        assert_eq!(config.motion.model, stem, "{}", path.display());
        names.push(stem);
    }
    names.sort();
    assert_eq!(names, MotionRegistry::default().names());
}

fn camera() -> Camera {
    Camera { grid: ViewGrid { rows: 9, cols: 9 }, width: 24, height: 20, f_px: 60.0, baseline_m: 0.02, focus_m: 2.0, line_time_s: 2e-3 }
}

fn gaussians() -> GaussianSet {
    let mut set = GaussianSet { u: vec![], v: vec![], disparity: vec![], size: vec![], colour: vec![], channels: 1 };
    for i in 0..30 {
        let f = i as f32;
        set.u.push(2.0 + (f * 7.3) % 20.0);
        set.v.push(2.0 + (f * 5.1) % 16.0);
        set.disparity.push(-0.5 + (f * 0.37) % 1.2);
        set.size.push(1.2 + (f * 0.23) % 1.0);
        set.colour.push(0.1 + (f * 0.31) % 0.8);
    }
    set
}

/// Mean colour and disparity of a corner view with rolling shutter, against a fixed pattern.
fn objective(m: &dyn MotionModel, params: &[f64], timing: RsTiming, device: &Device) -> (Tensor<1>, Tensor<1>) {
    let cam = camera();
    let g = gaussians().to_module(device);
    let p = Tensor::<1>::from_data(TensorData::new(params.iter().map(|&x| x as f32).collect::<Vec<_>>(), [params.len()]), device)
        .require_grad();
    let shape = StaticShape::new(&g, TensorCamera::new(&cam), m, p.clone());
    // Every Gaussian in every bin and a footprint out to 6σ: the bins, recomputed in each
    // evaluation, then cannot change the value (a 3σ cut-off would add jumps of e^-4.5).
    let settings = RenderSettings { max_per_pixel: 32, cutoff_sigma: 6.0 };
    let window = ViewWindow { offset: (4.0, 4.0), width: cam.width, rows: 0..cam.height };
    let out = render_rolling_shutter(&shape, m, p.clone(), window, timing, &settings, device);
    let n = out.colour.dims()[0];
    let pattern = Tensor::<1>::from_data(TensorData::new((0..n).map(|i| ((i * 37 % 11) as f32) / 11.0).collect::<Vec<_>>(), [n]), device);
    let value = (out.colour.reshape([n]) * pattern.clone()).mean() + (out.disparity * pattern).mean() * 0.1;
    (value, p)
}

#[test]
fn motion_gradients_through_the_rolling_shutter_render_match_finite_differences() {
    let device = Device::flex().autodiff();
    let m = model("constant_velocity", 1);
    let params = [4.0, -3.0, 6.0, 0.5, 0.8, -1.0];
    for timing in [RsTiming::PerGaussian(3), RsTiming::Bands(4)] {
        let (value, p) = objective(m.as_ref(), &params, timing, &device);
        let grad = host(p.grad(&value.backward()).unwrap());
        for i in 0..params.len() {
            // A step that moves the image by a few hundredths of a pixel.
            let h = if i < 3 { 0.05 } else { 0.01 };
            let at = |s: f64| {
                let mut q = params;
                q[i] += s;
                objective(m.as_ref(), &q, timing, &device).0.into_scalar::<f32>() as f64
            };
            let fd = (at(h) - at(-h)) / (2.0 * h);
            let err = (fd - grad[i] as f64).abs();
            assert!(err <= 2e-2 * fd.abs() + 1e-5, "{timing:?} parameter {i}: autodiff {} vs finite difference {fd}", grad[i]);
            assert!(fd.abs() > 1e-5, "{timing:?} parameter {i} has no effect: the check would be empty");
        }
    }
}

#[test]
fn without_motion_the_rolling_shutter_render_is_the_static_light_field_render() {
    let device = Device::flex();
    let cam = camera();
    let m = model("constant_velocity", 1);
    let g = gaussians().to_module(&device);
    let zero = Tensor::<1>::zeros([6], &device);
    let shape = StaticShape::new(&g, TensorCamera::new(&cam), m.as_ref(), zero.clone());
    let settings = RenderSettings { max_per_pixel: 8, cutoff_sigma: 3.0 };
    let offset = (-4.0f32, 4.0f32);
    let window = ViewWindow { offset, width: cam.width, rows: 0..cam.height };
    let rs = render_rolling_shutter(&shape, m.as_ref(), zero, window, RsTiming::Bands(5), &settings, &device);
    let plain = rslf::render::render_rows(&g, offset, cam.width, 0..cam.height, &settings, &device);
    let (a, b) = (host(rs.colour), host(plain.colour));
    let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0f32, f32::max);
    assert!(worst < 1e-4, "largest difference {worst}");
}
