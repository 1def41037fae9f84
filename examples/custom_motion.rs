//! Adds a motion model without touching `src/`: `pan_tilt`, a camera on a pan-tilt head that
//! turns about its X and Y axes at constant rates and neither rolls nor translates (2 parameters
//! instead of 6). Leaving out roll and translation along the optical axis, the directions the
//! rolling-shutter cue observes worst, makes the fit better posed when the model is right.
//!
//! The model is one `MotionModel` impl (its pose as a burn tensor program, so gradients come
//! from autodiff) and one `MotionRegistry::register` call; a config selects it with
//! `[motion] model = "pan_tilt"`.
//!
//! `cargo run --release --example custom_motion` generates a 96x96 light field of a camera
//! panning at 1 rad/s, fits it with `pan_tilt` and with `constant_velocity`, and prints the
//! image-space motion error of each against the truth.

use burn::tensor::Tensor;
use rslf::config::Config;
use rslf::eval::{EvalReport, evaluate};
use rslf::geometry::{PoseBatch, rotation_matrices};
use rslf::io::{MotionRecord, Scene};
use rslf::model::motion::{MotionModel, MotionRegistry, ParamKind, Quantity, scale_rows};
use rslf::pipeline::{Registries, run_with};
use rslf::synth::{GenerateOptions, SceneDescription, generate};
use std::path::{Path, PathBuf};

/// `P(t) = R(t (ωx, ωy, 0)) P0`: parameters `[ωx, ωy]` (rad/s).
struct PanTilt;

impl MotionModel for PanTilt {
    fn name(&self) -> &str {
        "pan_tilt"
    }

    fn parameters(&self) -> Vec<ParamKind> {
        ParamKind::xyz(Quantity::Rotation, 1)[..2].to_vec()
    }

    fn poses(&self, params: Tensor<1>, times: Tensor<1>) -> PoseBatch {
        let n = times.dims()[0];
        let device = times.device();
        let omega = Tensor::cat(vec![params, Tensor::zeros([1], &device)], 0).reshape([1, 3]);
        PoseBatch { rotation: rotation_matrices(scale_rows(&times, omega)), translation: Tensor::zeros([n, 3], &device) }
    }

    /// FORMAT has no pan-tilt model: it is a constant velocity with ωz = 0 and v = 0.
    fn record(&self, p: &[f64]) -> MotionRecord {
        MotionRecord::ConstantVelocity { omega_rad_s: [p[0], p[1], 0.0], velocity_m_s: [0.0; 3] }
    }

    fn parameters_of(&self, record: &MotionRecord) -> Option<Vec<f64>> {
        match record {
            MotionRecord::ConstantVelocity { omega_rad_s: [x, y, 0.0], velocity_m_s: [0.0, 0.0, 0.0] } => Some(vec![*x, *y]),
            _ => None,
        }
    }
}

/// The built-in registries plus `pan_tilt`.
fn registries() -> Registries {
    Registries { motions: MotionRegistry::default().register("pan_tilt", |_, _| Ok(Box::new(PanTilt))), ..Registries::default() }
}

/// Generates `configs/scenes/objects.toml` at `size` px, panning about Y at `omega_y` rad/s.
fn generate_scene(dir: &Path, size: usize, omega_y: f64) -> Scene {
    let text = include_str!("../configs/scenes/objects.toml");
    let text =
        format!("{text}\n[motion]\nmodel = \"constant_velocity\"\nomega_rad_s = [0.0, {omega_y}, 0.0]\nvelocity_m_s = [0.0, 0.0, 0.0]\n");
    let description = SceneDescription::parse(&text, Path::new("objects.toml")).expect("the description parses");
    let options = GenerateOptions { size: Some([size, size]), seed: 0 };
    let scene = generate(&description, &options, |_, _| {}).expect("the scene generates");
    scene.write(dir, true).expect("the scene folder is writable");
    Scene::load(dir).expect("the generated scene loads")
}

/// The image-space error of the fitted motion and the true rolling-shutter shift, pixels; and
/// the fitted ω.
#[derive(Debug)]
struct Fitted {
    error_px: f64,
    shift_px: f64,
    omega: [f64; 3],
}

/// A file of the project. Cargo names the project folder when it runs the example (or its
/// tests); the compile-time path is the fallback, as a target folder shared between two clones
/// can hold a binary built in the other one.
fn project_file(relative: &str) -> PathBuf {
    std::env::var_os("CARGO_MANIFEST_DIR").map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")), PathBuf::from).join(relative)
}

fn fit(scene: &Scene, model: &str, gaussians: usize, out: &Path) -> Fitted {
    let mut config = Config::read(&project_file("configs/constant_velocity.toml")).expect("config parses");
    config.motion.model = model.into();
    config.stage1.gaussians = gaussians;
    config.stage1.band_height = 32;
    let registries = registries();
    registries.check(&config).expect("the config names a known model");
    let device = rslf::device::device(config.device).expect("flex is always there");
    let (result, _) = run_with(&config, scene, &device, &registries).expect("the run succeeds");
    result.write(out, scene.camera().as_ref()).expect("the result folder is writable");
    let report: EvalReport = evaluate(&scene.dir, out).expect("the scene has ground truth");
    let image = report.motion.and_then(|m| m.image).expect("image-space motion error");
    let omega = match result.motion.expect("a motion") {
        MotionRecord::ConstantVelocity { omega_rad_s, .. } => omega_rad_s,
        other => panic!("unexpected record {other:?}"),
    };
    Fitted { error_px: image.rms_error_px, shift_px: image.rms_true_shift_px, omega }
}

/// Fits the panning scene at `size` px with each of `models`.
fn demo(size: usize, gaussians: usize, models: &[&str]) -> Vec<Fitted> {
    let dir = std::env::temp_dir().join(format!("rslf-custom-motion-{}", std::process::id()));
    let scene = generate_scene(&dir.join("scene"), size, 1.0);
    let fitted = models.iter().map(|m| fit(&scene, m, gaussians, &dir.join(m))).collect();
    let _ = std::fs::remove_dir_all(&dir);
    fitted
}

#[cfg_attr(test, allow(dead_code))]
fn main() {
    let models = ["pan_tilt", "constant_velocity"];
    let fitted = demo(96, 6000, &models);
    println!("panning at ω = (0, 1, 0) rad/s, 96x96 px; true RMS rolling-shutter shift {:.2} px", fitted[0].shift_px);
    for (name, f) in models.iter().zip(&fitted) {
        println!(
            "  {name:17}: image-space error {:.3} px ({:.0}% of the shift), ω = ({:.3}, {:.3}, {:.3}) rad/s",
            f.error_px,
            100.0 * f.error_px / f.shift_px,
            f.omega[0],
            f.omega[1],
            f.omega[2]
        );
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_custom_model_recovers_a_pan() {
        let fitted = super::demo(96, 6000, &["pan_tilt"]);
        let f = &fitted[0];
        println!("pan_tilt {f:?}");
        assert!(f.shift_px > 2.0, "the scene has a rolling-shutter shift: {f:?}");
        assert!(f.error_px < 0.25 * f.shift_px, "pan_tilt removes most of the shift: {f:?}");
        assert!((f.omega[1] - 1.0).abs() < 0.2, "ω_y is recovered: {f:?}");
    }
}
