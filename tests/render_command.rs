//! `rslf render` end to end: a model fitted to a small generated static scene reproduces its
//! input views; the t = 0 light field of a model with motion is written as a global-shutter
//! scene; and the device choice fails cleanly when wgpu has no adapter.

mod common;

use common::{rslf, rslf_with_env};
use rslf::io::Scene;
use std::path::Path;

/// A 64x64 version of `configs/scenes/objects.toml` (rolling shutter, zero motion).
fn generate(dir: &Path) -> String {
    let text = common::small_objects_description();
    let description = dir.join("static.toml");
    std::fs::write(&description, text).unwrap();
    let scene = dir.join("scene");
    let (ok, _, stderr) = rslf(&["generate", description.to_str().unwrap(), "--out", scene.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    scene.to_str().unwrap().to_string()
}

/// Trains `name` on `scene` (stage 2 with `motion_steps` steps) and returns the model folder.
fn train(dir: &Path, scene: &str, name: &str, motion_steps: usize) -> String {
    let config = dir.join(format!("{name}.toml"));
    std::fs::write(
        &config,
        format!("scene = {scene:?}\n[stage1]\ngaussians = 4000\niterations = 200\nband_height = 32\n[stage2]\niterations = {motion_steps}\nbands_per_step = 2\n"),
    )
    .unwrap();
    let out = dir.join("results").join(name);
    let models = dir.join("models");
    let (ok, _, stderr) = rslf(&[
        "train",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--models",
        models.to_str().unwrap(),
        "--device",
        "flex",
    ]);
    assert!(ok, "{stderr}");
    models.join(name).to_str().unwrap().to_string()
}

/// The PSNR `rslf render` printed for view `index` of its 9x9 grid (row `index / 9`, column
/// `index % 9`).
fn view_psnr(stdout: &str, index: usize) -> f64 {
    let row = format!("r{}", index / 9);
    let line =
        stdout.lines().find(|l| l.split_whitespace().next() == Some(row.as_str())).unwrap_or_else(|| panic!("no grid row {row}: {stdout}"));
    let cells: Vec<&str> = line.split_whitespace().skip(1).collect();
    assert_eq!(cells.len(), 9, "{line}");
    cells[index % 9].parse().unwrap_or_else(|_| panic!("view {index}: {line}"))
}

#[test]
fn a_fitted_static_model_reproduces_its_input_views() {
    let root = common::tempdir();
    let scene = generate(root.path());
    let model = train(root.path(), &scene, "static", 0);
    let out = root.path().join("rendered");
    let (ok, stdout, stderr) = rslf(&["render", &model, "--out", out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("PSNR against the 81 input views"), "{stdout}");

    // The central view's PSNR agrees with what `rslf train` measured for central.png against
    // gt_central.png (the same image here: no motion), up to central.png's 8-bit rounding.
    let metrics: serde_json::Value =
        serde_json::from_slice(&std::fs::read(root.path().join("results/static/metrics.json")).unwrap()).unwrap();
    let central = metrics["central_psnr_db"].as_f64().unwrap();
    assert!((view_psnr(&stdout, 40) - central).abs() < 0.3, "render {} dB vs train {central} dB", view_psnr(&stdout, 40));
    // The fitted views (the five central-row views around the centre) are reproduced closely.
    for view in 38..=42 {
        assert!(view_psnr(&stdout, view) > 25.0, "view {view}: {stdout}");
    }

    // The written folder is a scene: 81 views of 64x64, a camera, and at t = 0 no rolling shutter.
    let written = Scene::load(&out).unwrap();
    assert_eq!((written.width(), written.height(), written.present_views().len()), (64, 64, 81));
    assert!(written.camera().is_some() && !written.is_rolling_shutter());

    // An existing folder is not replaced without --force.
    let (ok, _, stderr) = rslf(&["render", &model, "--out", out.to_str().unwrap()]);
    assert!(!ok && stderr.contains("already exists"), "{stderr}");
}

#[test]
fn with_motion_t0_is_global_shutter_and_capture_keeps_the_shutter() {
    let root = common::tempdir();
    let scene = generate(root.path());
    let model = train(root.path(), &scene, "moving", 3);
    let t0 = root.path().join("t0");
    let (ok, stdout, stderr) = rslf(&["render", &model, "--out", t0.to_str().unwrap(), "--at", "t0"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("PSNR: not computed"), "{stdout}");
    assert!(!Scene::load(&t0).unwrap().is_rolling_shutter());

    let capture = root.path().join("capture");
    let (ok, stdout, stderr) = rslf(&["render", &model, "--out", capture.to_str().unwrap(), "--at", "capture"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("PSNR against the 81 input views"), "{stdout}");
    assert!(Scene::load(&capture).unwrap().is_rolling_shutter());
}

#[test]
fn a_missing_model_is_a_one_line_error() {
    let root = common::tempdir();
    let (ok, _, stderr) =
        rslf(&["render", root.path().join("nothing").to_str().unwrap(), "--out", root.path().join("x").to_str().unwrap()]);
    assert!(!ok);
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(!root.path().join("x").exists());
}

#[test]
fn wgpu_without_an_adapter_fails_with_a_clear_error() {
    let root = common::tempdir();
    let scene = generate(root.path());
    let config = root.path().join("run.toml");
    std::fs::write(&config, format!("scene = {scene:?}\n[stage1]\ngaussians = 100\niterations = 1\n")).unwrap();
    // Ask cubecl for a discrete GPU that no machine running this test has.
    let (ok, stdout, stderr) = rslf_with_env(
        &["train", config.to_str().unwrap(), "--device", "wgpu", "--out", root.path().join("out").to_str().unwrap()],
        &[("CUBECL_WGPU_DEFAULT_DEVICE", Path::new("DiscreteGpu(97)"))],
    );
    assert!(!ok, "{stdout}");
    assert!(stderr.contains("no usable GPU adapter") && stderr.contains("--device flex"), "{stderr}");
    assert!(!root.path().join("out").exists());
}
