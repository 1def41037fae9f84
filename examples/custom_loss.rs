//! Adds a loss term without touching `src/`: `gradient_l1`, the L1 distance between the image
//! gradients (horizontal and vertical finite differences) of the render and of the target, which
//! weighs edges, where disparity is observable, more than flat regions.
//!
//! The term is one `LossTerm` impl and one `LossRegistry::register` call. The config that uses
//! it, `examples/custom_loss.toml`, lists it like any built-in term.
//!
//! `cargo run --release --example custom_loss` fits a 128x128 generated static scene with and
//! without the term and prints the disparity error of each.
//! `cargo run --release --example custom_loss -- train examples/custom_loss.toml` is the `rslf`
//! command with the term added.

use burn::tensor::Tensor;
use rslf::config::Config;
use rslf::eval::{EvalReport, evaluate};
use rslf::io::Scene;
use rslf::loss::{LossInput, LossRegistry, LossTerm};
use rslf::pipeline::{Registries, run_with};
use std::path::{Path, PathBuf};

/// `mean |∂x render - ∂x target| + mean |∂y render - ∂y target|` over a band.
struct GradientL1;

impl GradientL1 {
    /// Horizontal and vertical differences of `[P, C]` band pixels, `rows x width`.
    fn gradients(pixels: Tensor<2>, rows: usize, width: usize) -> (Tensor<3>, Tensor<3>) {
        let c = pixels.dims()[1];
        let img = pixels.reshape([rows, width, c]);
        let dx = img.clone().slice([0..rows, 1..width]) - img.clone().slice([0..rows, 0..width - 1]);
        let dy = img.clone().slice([1..rows, 0..width]) - img.slice([0..rows - 1, 0..width]);
        (dx, dy)
    }
}

impl LossTerm for GradientL1 {
    fn name(&self) -> &str {
        "gradient_l1"
    }

    fn evaluate(&self, input: &LossInput) -> Option<Tensor<1>> {
        if input.rows < 2 || input.width < 2 {
            return None;
        }
        let (rx, ry) = Self::gradients(input.rendered.colour.clone(), input.rows, input.width);
        let (tx, ty) = Self::gradients(input.target.clone(), input.rows, input.width);
        Some((rx - tx).abs().mean() + (ry - ty).abs().mean())
    }
}

/// The built-in registries plus `gradient_l1`.
fn registries() -> Registries {
    Registries { losses: LossRegistry::default().register("gradient_l1", || Box::new(GradientL1)), ..Registries::default() }
}

/// Runs `config` on `scene` and evaluates the result against the scene's ground truth.
fn fit_and_evaluate(config: &Config, scene: &Scene, registries: &Registries, out: &Path) -> (EvalReport, Vec<String>) {
    let device = rslf::device::device(config.device).expect("flex is always there");
    let (result, log) = run_with(config, scene, &device, registries).expect("the run succeeds");
    result.write(out, scene.camera().as_ref()).expect("the result folder is writable");
    (evaluate(&scene.dir, out).expect("the scene has ground truth"), log.lines)
}

/// BadPix(0.07) in percent.
fn badpix(report: &EvalReport) -> f64 {
    let metrics = report.disparity.as_ref().expect("disparity metrics");
    metrics.badpix_percent.iter().find(|(t, _)| (*t - 0.07).abs() < 1e-9).expect("BadPix(0.07)").1
}

/// What the demo measured: BadPix(0.07) with and without the term, and the stage-1 log line.
#[derive(Debug)]
struct Outcome {
    with_term: f64,
    without_term: f64,
    log: String,
}

/// A file of the project. Cargo names the project folder when it runs the example (or its
/// tests); the compile-time path is the fallback, as a target folder shared between two clones
/// can hold a binary built in the other one.
fn project_file(relative: &str) -> PathBuf {
    std::env::var_os("CARGO_MANIFEST_DIR").map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")), PathBuf::from).join(relative)
}

/// Fits the `objects_static` scene at `size` px with `examples/custom_loss.toml` (at `gaussians`
/// and `iterations`), then again without `gradient_l1`.
fn demo(size: usize, gaussians: usize, iterations: usize) -> Outcome {
    let path = project_file("examples/custom_loss.toml");
    let mut config = Config::read(&path).expect("examples/custom_loss.toml parses");
    config.stage1.gaussians = gaussians;
    config.stage1.iterations = iterations;
    let scene_dir = rslf::synth::builtin_scene_sized("objects_static", Some([size, size])).expect("the scene generates");
    let scene = Scene::load(&scene_dir).expect("the generated scene loads");
    let out = std::env::temp_dir().join(format!("rslf-custom-loss-{}", std::process::id()));

    let registries = registries();
    registries.check(&config).expect("the config names known terms");
    let (with, log) = fit_and_evaluate(&config, &scene, &registries, &out.join("with"));
    let mut baseline = config.clone();
    baseline.loss.retain(|l| l.kind != "gradient_l1");
    let (without, _) = fit_and_evaluate(&baseline, &scene, &registries, &out.join("without"));
    let _ = std::fs::remove_dir_all(&out);
    let log = log.into_iter().find(|l| l.starts_with("stage 1 fit")).unwrap_or_default();
    Outcome { with_term: badpix(&with), without_term: badpix(&without), log }
}

#[cfg_attr(test, allow(dead_code))]
fn main() -> std::process::ExitCode {
    if std::env::args_os().len() > 1 {
        return rslf::cli::main_with(&registries());
    }
    let o = demo(128, 8000, 150);
    println!("{}", o.log);
    println!("objects_static 128x128, BadPix(0.07): {:.2}% with gradient_l1, {:.2}% without", o.with_term, o.without_term);
    std::process::ExitCode::SUCCESS
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_config_naming_the_custom_term_trains_with_it() {
        let o = demo(64, 1500, 40);
        println!("{o:?}");
        assert!(o.log.contains("gradient_l1×0.5"), "the stage-1 objective lists the term: {}", o.log);
        assert!(o.with_term.is_finite() && o.without_term.is_finite());
        assert_ne!(o.with_term, o.without_term, "the term changes the fit");
    }

    #[test]
    fn the_term_is_zero_for_a_perfect_render_and_sees_a_shift() {
        use burn::tensor::TensorData;
        let device = rslf::device::device(rslf::config::DeviceChoice::Flex).unwrap();
        let (rows, width) = (4, 6);
        let ramp: Vec<f32> = (0..rows * width).map(|i| ((i % width) as f32 * 0.3).sin()).collect();
        let shifted: Vec<f32> = (0..rows * width).map(|i| ((i % width) as f32 * 0.3 + 0.3).sin()).collect();
        let t = |v: Vec<f32>| Tensor::<2>::from_data(TensorData::new(v, [rows * width, 1]), &device);
        let zeros = Tensor::<1>::zeros([rows * width], &device);
        let rendered = |c: Tensor<2>| rslf::render::RenderOutput { colour: c, disparity: zeros.clone(), alpha: zeros.clone() };
        let value = |r: &rslf::render::RenderOutput, target: &Tensor<2>| {
            let input = LossInput { rendered: r, target, rows, width, motion: None };
            GradientL1.evaluate(&input).unwrap().into_scalar::<f32>()
        };
        assert!(value(&rendered(t(ramp.clone())), &t(ramp.clone())).abs() < 1e-7);
        assert!(value(&rendered(t(shifted)), &t(ramp)) > 1e-3);
    }
}
