//! `rslf train` end to end on a small scene of known geometry.

mod common;

use common::{params, rslf, write_plane_scene};
use rslf::geometry::Camera;
use rslf::io::{Raster, read_image, read_pfm, write_pfm};

#[test]
fn train_recovers_the_disparity_of_a_plane_and_writes_a_format_result() {
    let root = common::tempdir();
    let scene = root.path().join("plane");
    let (w, h, d) = (64, 48, 0.75);
    write_plane_scene(&scene, w, h, 5, d, |_| true);
    let p = params(w, h, 5);
    p.write(&scene.join("parameters.cfg")).unwrap();
    write_pfm(&scene.join("gt_disp_lowres.pfm"), &Raster::from_vec(w, h, 1, vec![d as f32; w * h]).unwrap()).unwrap();
    let config = root.path().join("plane.toml");
    std::fs::write(&config, format!("scene = {:?}\n[stage1]\ndisparity_step = 0.1\n", scene.to_str().unwrap())).unwrap();
    let out = root.path().join("result");

    let models = root.path().join("models");
    let (ok, stdout, stderr) =
        rslf(&["train", config.to_str().unwrap(), "--out", out.to_str().unwrap(), "--models", models.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("stage 1 initialisation"), "{stdout}");
    // A global-shutter capture: the central column is fitted too, as many views as the row's.
    assert!(stdout.contains("of 5 central-row and 4 central-column views"), "{stdout}");

    let disp = read_pfm(&out.join("disparity.pfm")).unwrap();
    assert_eq!((disp.width, disp.height), (w, h));
    let (mut err, mut n) = (0.0f64, 0);
    for y in 4..h - 4 {
        for x in 8..w - 8 {
            err += (disp.get(x, y, 0) as f64 - d).abs();
            n += 1;
        }
    }
    assert!(err / n as f64 <= 0.03, "mean interior disparity error {}", err / n as f64);

    let cam = Camera::from_parameters(&p);
    let depth = read_pfm(&out.join("depth.pfm")).unwrap();
    let (x, y) = (w / 2, h / 2);
    let expected = cam.disparity_to_depth(disp.get(x, y, 0) as f64);
    assert!((depth.get(x, y, 0) as f64 - expected).abs() < 1e-4 * expected);

    let central = read_image(&out.join("central.png")).unwrap();
    assert_eq!((central.width, central.height, central.channels), (w, h, 3));
    assert!(!out.join("motion.toml").exists(), "global-shutter scene: no motion");
    let metrics: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("metrics.json")).unwrap()).unwrap();
    let badpix_007 = metrics["disparity"]["badpix_percent"][0][1].as_f64().unwrap();
    assert!(badpix_007 < 5.0, "BadPix(0.07) {badpix_007}%");
}

#[test]
fn a_rolling_shutter_scene_of_the_central_row_alone_is_not_compensated_and_says_why() {
    // The central row's views read each row at the same instant: they hold no trace of motion,
    // so no motion may be reported.
    let root = common::tempdir();
    let scene = root.path().join("row");
    let (w, h, n) = (48, 32, 5);
    write_plane_scene(&scene, w, h, n, 0.5, |i| i / n == n / 2);
    let p = rslf::io::SceneParameters { line_time_s: Some(1e-4), ..params(w, h, n) };
    p.write(&scene.join("parameters.cfg")).unwrap();
    let config = root.path().join("row.toml");
    std::fs::write(
        &config,
        format!("scene = {:?}\n[stage1]\ngaussians = 500\niterations = 5\ndisparity_step = 0.1\n", scene.to_str().unwrap()),
    )
    .unwrap();
    let (out, models) = (root.path().join("result"), root.path().join("models"));
    let (ok, stdout, stderr) =
        rslf(&["train", config.to_str().unwrap(), "--out", out.to_str().unwrap(), "--models", models.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("stage 2 (motion): skipped, the scene has no view off the central row"), "{stdout}");
    assert!(out.join("disparity.pfm").exists() && out.join("central.png").exists());
    assert!(!out.join("motion.toml").exists(), "no motion can be estimated from the central row");
}

#[test]
fn the_shipped_configs_parse_and_name_only_built_in_terms_and_models() {
    let registries = rslf::pipeline::Registries::default();
    for entry in std::fs::read_dir(common::project_path("configs")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let config = rslf::config::Config::read(&path).unwrap_or_else(|e| panic!("{e}"));
            registries.check(&config).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        }
    }
}

#[test]
fn every_subcommand_has_help() {
    for sub in ["train", "eval", "generate"] {
        let (ok, stdout, _) = rslf(&[sub, "--help"]);
        assert!(ok && stdout.contains("Usage: rslf"), "{sub}: {stdout}");
    }
}

#[test]
fn the_readme_main_command_runs_on_its_built_in_scene() {
    let dir = common::tempdir();
    let cache = dir.path().join("cache");
    let out = dir.path().join("result");
    let models = dir.path().join("models");
    let (ok, stdout, stderr) = common::rslf_with_env(
        &["train", "configs/constant_velocity.toml", "--out", out.to_str().unwrap(), "--models", models.to_str().unwrap()],
        &[("RSLF_CACHE_DIR", &cache)],
    );
    assert!(ok, "{stderr}");
    assert_eq!(stderr.matches("panicked").count(), 0);
    let scene = rslf::io::Scene::load(&cache.join("scenes/checkerboards_slow1")).unwrap();
    assert!(scene.is_rolling_shutter() && scene.present_views().len() == 81);
    for file in ["disparity.pfm", "depth.pfm", "central.png", "loss_stage1.csv", "metrics.json"] {
        assert!(out.join(file).exists(), "{file} missing; stdout: {stdout}");
    }
    assert!(models.join("result/model.json").exists());
    // The motion prior is in the config's list; stage 1 fits no motion and does not list it.
    let line = |prefix: &str| stdout.lines().find(|l| l.starts_with(prefix)).unwrap_or_else(|| panic!("no `{prefix}` line: {stdout}"));
    let (stage1, stage2) = (line("stage 1 fit:"), line("stage 2 fit:"));
    assert!(stage1.contains("l1×1 + smoothness×0.05") && !stage1.contains("motion_prior"), "{stage1}");
    assert!(stage1.contains("the disparities' rate decaying to 0.1 of itself"), "{stage1}");
    assert!(stage2.contains("motion_prior×"), "{stage2}");
    let saved = rslf::model::SavedModel::load(&models.join("result")).unwrap();
    assert_eq!(saved.gaussians.len(), 20_000);
    let metrics: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("metrics.json")).unwrap()).unwrap();
    let delta = metrics["depth"]["delta_1_25"].as_f64().unwrap();
    // Stage 1 alone on a rolling-shutter scene with uniform checker squares: measured 0.82.
    assert!(delta > 0.75, "depth delta<1.25 {delta}: {stdout}");
}
