//! Every kind of bad input ends with a one-line error naming the file, a non-zero exit, no
//! panic and no partial output; output that nobody reads any more ends the program quietly.

mod common;

use common::{params, rslf, write_plane_scene};
use std::path::{Path, PathBuf};

/// A valid 3x3 scene of 24x20 pixels with its camera, and a config pointing at it.
fn valid_scene(root: &Path) -> (PathBuf, PathBuf) {
    let scene = root.join("scene");
    write_plane_scene(&scene, 24, 20, 3, 0.5, |_| true);
    params(24, 20, 3).write(&scene.join("parameters.cfg")).unwrap();
    let config = root.join("run.toml");
    std::fs::write(&config, "[stage1]\ndisparity_step = 0.25\n").unwrap();
    (scene, config)
}

/// Runs `rslf train` and checks the failure: message names `culprit`, no panic, no output folder.
fn assert_train_fails(scene: &Path, config: &Path, culprit: &str, problem: &str) {
    let out = scene.parent().unwrap().join("out");
    let (ok, _stdout, stderr) =
        rslf(&["train", config.to_str().unwrap(), "--scene", scene.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(!ok, "expected failure for {culprit}");
    assert_eq!(stderr.matches("panicked").count(), 0, "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "one line expected: {stderr}");
    assert!(stderr.contains(culprit), "message must name {culprit}: {stderr}");
    assert!(stderr.contains(problem), "message must say `{problem}`: {stderr}");
    assert!(!out.exists(), "nothing may be written on failure");
}

#[test]
fn missing_scene_folder() {
    let root = common::tempdir();
    let (_, config) = valid_scene(root.path());
    let missing = root.path().join("nowhere");
    assert_train_fails(&missing, &config, "nowhere", "scene folder not found");
}

#[test]
fn no_central_view() {
    let root = common::tempdir();
    let (scene, config) = valid_scene(root.path());
    std::fs::remove_file(scene.join("input_Cam004.png")).unwrap();
    assert_train_fails(&scene, &config, "scene", "no central view (input_Cam004.png)");
}

#[test]
fn views_of_different_sizes() {
    let root = common::tempdir();
    let (scene, config) = valid_scene(root.path());
    let small = rslf::io::Raster::zeros(12, 10, 3);
    rslf::io::write_png(&scene.join("input_Cam002.png"), &small).unwrap();
    assert_train_fails(&scene, &config, "input_Cam002.png", "view is 12x10 but the central view is 24x20");
}

#[test]
fn corrupt_png() {
    let root = common::tempdir();
    let (scene, config) = valid_scene(root.path());
    std::fs::write(scene.join("input_Cam003.png"), b"this is not a png").unwrap();
    assert_train_fails(&scene, &config, "input_Cam003.png", "unreadable PNG");
}

#[test]
fn truncated_png() {
    let root = common::tempdir();
    let (scene, config) = valid_scene(root.path());
    let path = scene.join("input_Cam005.png");
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    assert_train_fails(&scene, &config, "input_Cam005.png", "unreadable PNG");
}

#[test]
fn corrupt_exr() {
    let root = common::tempdir();
    let (scene, config) = valid_scene(root.path());
    std::fs::remove_file(scene.join("input_Cam001.png")).unwrap();
    std::fs::write(scene.join("input_Cam001.exr"), b"v/1\x01 definitely not an exr").unwrap();
    assert_train_fails(&scene, &config, "input_Cam001.exr", "unreadable EXR");
}

#[test]
fn parameters_cfg_with_a_missing_key() {
    let root = common::tempdir();
    let (scene, config) = valid_scene(root.path());
    let cfg = scene.join("parameters.cfg");
    let text = std::fs::read_to_string(&cfg).unwrap();
    std::fs::write(&cfg, text.lines().filter(|l| !l.starts_with("focus_distance_m")).collect::<Vec<_>>().join("\n")).unwrap();
    assert_train_fails(&scene, &config, "parameters.cfg", "[extrinsics] focus_distance_m is missing");
}

#[test]
fn parameters_cfg_with_a_non_numeric_key() {
    let root = common::tempdir();
    let (scene, config) = valid_scene(root.path());
    let cfg = scene.join("parameters.cfg");
    let text = std::fs::read_to_string(&cfg).unwrap().replace("baseline_mm = 10", "baseline_mm = ten");
    std::fs::write(&cfg, text).unwrap();
    assert_train_fails(&scene, &config, "parameters.cfg", "[extrinsics] baseline_mm = `ten` is not a number");
}

#[test]
fn parameters_cfg_that_disagrees_with_the_views() {
    let root = common::tempdir();
    let (scene, config) = valid_scene(root.path());
    let mut p = params(24, 20, 3);
    p.image_resolution_x_px = 32;
    p.write(&scene.join("parameters.cfg")).unwrap();
    assert_train_fails(&scene, &config, "parameters.cfg", "says 32x20 pixels but the views are 24x20");
}

#[test]
fn config_with_an_unknown_key() {
    let root = common::tempdir();
    let (scene, config) = valid_scene(root.path());
    std::fs::write(&config, "[stage1]\niterations = 5\nlearning_rate = 0.1\n").unwrap();
    assert_train_fails(&scene, &config, "run.toml:3", "unknown field `learning_rate`");
}

#[test]
fn config_with_a_wrong_type() {
    let root = common::tempdir();
    let (scene, config) = valid_scene(root.path());
    std::fs::write(&config, "[motion]\nsegments = \"four\"\n").unwrap();
    assert_train_fails(&scene, &config, "run.toml:2: key `motion.segments`", "expected");
}

#[test]
fn config_naming_an_unknown_loss_or_motion_model() {
    let root = common::tempdir();
    let (scene, config) = valid_scene(root.path());
    std::fs::write(&config, "[[loss]]\nkind = \"perceptual\"\n").unwrap();
    assert_train_fails(&scene, &config, "run.toml", "unknown loss term `perceptual`");
    std::fs::write(&config, "[motion]\nmodel = \"helical\"\n").unwrap();
    assert_train_fails(&scene, &config, "run.toml", "motion model `helical`: unknown");
    std::fs::write(&config, "[motion]\nmodel = \"piecewise_constant\"\nsegments = 0\n").unwrap();
    assert_train_fails(&scene, &config, "run.toml", "motion.segments`: must be at least 1");
}

#[test]
fn missing_config() {
    let root = common::tempdir();
    let (scene, _) = valid_scene(root.path());
    assert_train_fails(&scene, &root.path().join("absent.toml"), "absent.toml", "no such file");
}

#[test]
fn eval_with_a_truncated_pfm_names_it_and_writes_nothing() {
    let root = common::tempdir();
    let (scene, _) = valid_scene(root.path());
    let map = rslf::io::Raster::zeros(24, 20, 1);
    rslf::io::write_pfm(&scene.join("gt_disp_lowres.pfm"), &map).unwrap();
    let result = root.path().join("result");
    std::fs::create_dir(&result).unwrap();
    let bytes = rslf::io::encode_pfm(&map);
    std::fs::write(result.join("disparity.pfm"), &bytes[..bytes.len() - 7]).unwrap();
    let (ok, _, stderr) = rslf(&["eval", "--scene", scene.to_str().unwrap(), "--result", result.to_str().unwrap()]);
    assert!(!ok);
    assert_eq!(stderr.matches("panicked").count(), 0, "{stderr}");
    assert!(stderr.contains("disparity.pfm") && stderr.contains("truncated PFM"), "{stderr}");
    assert!(!result.join("metrics.json").exists());
}

#[test]
fn eval_of_a_scene_without_ground_truth_says_so() {
    let root = common::tempdir();
    let (scene, _) = valid_scene(root.path());
    let result = root.path().join("result");
    std::fs::create_dir(&result).unwrap();
    rslf::io::write_pfm(&result.join("disparity.pfm"), &rslf::io::Raster::zeros(24, 20, 1)).unwrap();
    let (ok, _, stderr) = rslf(&["eval", "--scene", scene.to_str().unwrap(), "--result", result.to_str().unwrap()]);
    assert!(!ok);
    assert!(stderr.contains("has no ground truth"), "{stderr}");
}

#[test]
fn output_whose_reader_has_gone_ends_quietly_with_the_status_of_sigpipe() {
    // `rslf generate --suite --list | head`, with the reader gone before the first line: the
    // program ends at once, saying nothing, with the status a shell reports for a tool that
    // SIGPIPE ended (128 + 13), where `println!` panicked (status 101, a backtrace on stderr).
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rslf"))
        .args(["generate", "--suite", "--list"])
        .current_dir(common::project_dir())
        .stdout(writer)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(141), "{stderr}");
    assert!(stderr.is_empty(), "{stderr}");
}
