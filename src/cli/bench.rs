//! `rslf bench`: the renderer's, stage 1's and the cue placement's speed and memory, printed.

use crate::config::{Config, DeviceChoice};
use crate::io::Scene;
use crate::model::GaussianSet;
use crate::random::Rng;
use crate::render::{RenderSettings, bins_for_view, render};
use crate::synth::{GenerateOptions, base_scene, generate};
use burn::module::Module;
use std::time::Instant;

/// Arguments of `rslf bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Image side, pixels.
    #[arg(long, default_value_t = 512)]
    pub size: usize,
    /// Number of Gaussians.
    #[arg(long, default_value_t = 20_000)]
    pub gaussians: usize,
    /// Timed repetitions of each render.
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
    /// Devices to time, comma separated (`flex`, `wgpu`).
    #[arg(long, default_value = "flex,wgpu", value_delimiter = ',')]
    pub devices: Vec<DeviceChoice>,
    /// Skip the whole-stage-1 timing.
    #[arg(long)]
    pub render_only: bool,
    /// Points placed as the measured-cue term places its cues, under each motion model, with its
    /// poses computed per point and read from a table (0 = skip).
    #[arg(long, default_value_t = 100_000)]
    pub cues: usize,
}

/// Peak resident memory of this process so far, MiB (Linux), if known.
fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn random_set(n: usize, size: usize, seed: u64) -> GaussianSet {
    let mut rng = Rng::new(seed);
    let spacing = ((size * size) as f64 / n as f64).sqrt();
    let mut set = GaussianSet { u: vec![], v: vec![], disparity: vec![], size: vec![], colour: vec![], channels: 3 };
    for _ in 0..n {
        set.u.push(rng.range(0.0, size as f64) as f32);
        set.v.push(rng.range(0.0, size as f64) as f32);
        set.disparity.push(rng.range(-2.0, 2.0) as f32);
        set.size.push((spacing * rng.range(0.4, 0.8)) as f32);
        set.colour.extend((0..3).map(|_| rng.unit() as f32));
    }
    set
}

/// Times the renderer on each device, then the whole stage 1 on flex.
pub fn run(args: BenchArgs) -> crate::Result<()> {
    let (n, s) = (args.gaussians.max(1), args.size.max(8));
    let set = random_set(n, s, 1);
    let settings = RenderSettings::default();
    let offset = (-2.0, 0.0);
    outln!("render: {s}x{s} px, {n} Gaussians, K = {}, view offset {offset:?}", settings.max_per_pixel);
    for &choice in &args.devices {
        let device = crate::device::device(choice)?;
        let start = Instant::now();
        let bins = bins_for_view(&set, offset, s, 0..s, &settings);
        let binning = start.elapsed().as_secs_f64();
        let g = set.to_module(&device);
        let mut times = Vec::new();
        for _ in 0..args.repeat.max(1) + 1 {
            let start = Instant::now();
            let out = render(&g, offset, &bins, &device);
            let loss = out.colour.mean() + out.disparity.mean();
            let grads = loss.backward();
            let grad = g.centre.val().grad(&grads).map(|t| t.sum().into_scalar::<f32>());
            times.push(start.elapsed().as_secs_f64());
            if grad.is_none_or(|v| !v.is_finite()) {
                return Err(crate::Error::Usage(format!("{choice:?}: the gradient did not come back finite")));
            }
        }
        times.remove(0); // the first run warms caches and compiles kernels
        let best = times.iter().copied().fold(f64::INFINITY, f64::min);
        let mean = times.iter().sum::<f64>() / times.len() as f64;
        outln!(
            "  {choice:?}: forward+backward {:.0} ms (best {:.0} ms of {}), binning {:.0} ms, {:.1}% pixels with K full",
            mean * 1e3,
            best * 1e3,
            times.len(),
            binning * 1e3,
            100.0 * bins.saturated_fraction()
        );
    }
    if !args.render_only {
        let start = Instant::now();
        let mut desc = base_scene("objects")?;
        desc.camera.num_cams = 9;
        let scene = generate(&desc, &GenerateOptions { size: Some([s, s]), seed: 0 }, |_, _| {}).map_err(crate::Error::Usage)?;
        let generated = start.elapsed().as_secs_f64();
        let dir = std::env::temp_dir().join(format!("rslf-bench-{}", std::process::id()));
        scene.write(&dir, true)?;
        let loaded = Scene::load(&dir);
        let _ = std::fs::remove_dir_all(&dir);
        let loaded = loaded?;
        let mut config = Config::default();
        config.stage1.gaussians = n;
        // Stage 1 alone: the generated scene has a rolling shutter, where stage 2 would run too.
        config.stage2.iterations = 0;
        let device = crate::device::device(DeviceChoice::Flex)?;
        let start = Instant::now();
        let (_, log) = crate::pipeline::run(&config, &loaded, &device)?;
        outln!("stage 1 on the generated `objects` scene ({s}x{s}, 81 views generated in {generated:.1} s), flex:");
        for line in log.lines {
            outln!("  {line}");
        }
        outln!("  whole stage 1: {:.1} s", start.elapsed().as_secs_f64());
    }
    if args.cues > 0 {
        bench_cue_placement(args.cues, args.repeat.max(1))?;
    }
    if let Some(mib) = peak_rss_mib() {
        outln!("peak memory of this process: {mib:.0} MiB");
    }
    Ok(())
}

/// Times one forward+backward placement of `n` points as the measured-cue term places its cues
/// (lifted, moved back to t = 0 from their rows' times, re-imaged into a corner each with three
/// fixed-point iterations of their own read-out time; the gradient with respect to the motion),
/// under each built-in model, its poses computed per point and read from the fit's table
/// ([`crate::pipeline::pose_table`]); with the largest difference the table makes, pixels.
fn bench_cue_placement(n: usize, repeat: usize) -> crate::Result<()> {
    use crate::geometry::{Camera, TensorCamera, ViewGrid, ViewOffset, readout_interval};
    use crate::model::motion::{MotionModel, MotionRegistry, MotionSetup};
    use crate::render::StaticShape;
    use burn::tensor::{Tensor, TensorData};

    let camera = Camera {
        grid: ViewGrid { rows: 9, cols: 9 },
        width: 256,
        height: 256,
        f_px: 366.0,
        baseline_m: 0.02,
        focus_m: 4.0,
        line_time_s: 1.5e-4,
    };
    let device = crate::device::device(DeviceChoice::Flex)?.autodiff();
    let mut rng = Rng::new(3);
    let mut set = GaussianSet { u: vec![], v: vec![], disparity: vec![], size: vec![1.0; n], colour: vec![0.0; n], channels: 1 };
    let (mut du, mut dv) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for _ in 0..n {
        set.u.push(rng.range(0.0, 256.0) as f32);
        set.v.push(rng.range(0.0, 256.0) as f32);
        set.disparity.push(rng.range(-2.0, 2.0) as f32);
        du.push(if rng.unit() < 0.5 { -4.0f32 } else { 4.0 });
        dv.push(if rng.unit() < 0.5 { -4.0f32 } else { 4.0 });
    }
    let points = set.to_module(&device).no_grad();
    let views =
        ViewOffset::PerPoint(Tensor::from_data(TensorData::new(du, [n]), &device), Tensor::from_data(TensorData::new(dv, [n]), &device));
    let tc = TensorCamera::new(&camera);
    let setup = MotionSetup { readout: readout_interval(camera.height, camera.line_time_s) };
    let registry = MotionRegistry::default();
    outln!("cue placement: {n} points, 256 x 256 px, each into a corner, forward+backward, flex:");
    for (name, segments, rates) in [
        ("constant_velocity", 1, vec![0.3, -0.5, 1.2, 0.8, -0.4, 2.0]),
        ("constant_acceleration", 1, vec![0.3, -0.5, 1.2, 0.8, -0.4, 2.0, 20.0, 5.0, -30.0, -40.0, 10.0, 25.0]),
        (
            "piecewise_constant",
            4,
            [0.3, -0.5, 1.2, 0.8, -0.4, 2.0].iter().cycle().take(24).enumerate().map(|(i, x)| x * (1.0 + 0.2 * (i / 6) as f64)).collect(),
        ),
    ] {
        let config = crate::config::MotionConfig { model: name.into(), segments };
        let model = registry.build(&config, &setup).map_err(|e| crate::Error::Usage(e.to_string()))?;
        let table = crate::pipeline::pose_table(model.as_ref(), &camera);
        let place = |m: &dyn MotionModel| -> crate::Result<(f64, Vec<f32>)> {
            let mut times = Vec::new();
            let mut placed = Vec::new();
            for _ in 0..repeat + 1 {
                let start = Instant::now();
                let params =
                    Tensor::<1>::from_data(TensorData::new(rates.iter().map(|&x| x as f32).collect::<Vec<_>>(), [rates.len()]), &device)
                        .require_grad();
                let shape = StaticShape::new(&points, tc, m, params.clone());
                let splats = shape.splats_rolling(m, params.clone(), views.clone(), 3);
                let grads = (splats.u.clone().sum() + splats.v.clone().sum()).backward();
                let grad = params.grad(&grads).map(|g| g.sum().into_scalar::<f32>());
                times.push(start.elapsed().as_secs_f64());
                if grad.is_none_or(|v| !v.is_finite()) {
                    return Err(crate::Error::Usage(format!("{name}: the gradient did not come back finite")));
                }
                placed = [crate::device::host_values(splats.u), crate::device::host_values(splats.v)].concat();
            }
            times.remove(0);
            Ok((times.iter().sum::<f64>() / times.len() as f64, placed))
        };
        let ((direct, a), (tabulated, b)) = (place(model.as_ref())?, place(&table)?);
        let off = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0f32, f32::max);
        outln!(
            "  {name:22} per point {:6.0} ms, tabulated ({} poses) {:6.0} ms: {:.1}x, placements within {off:.1e} px",
            direct * 1e3,
            table.samples,
            tabulated * 1e3,
            direct / tabulated
        );
    }
    Ok(())
}
