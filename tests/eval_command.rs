//! `rslf eval` end to end on a generated scene: the motion's image-space error.

mod common;

use common::{rslf, tempdir};
use rslf::io::MotionRecord;
use rslf::synth::{GenerateOptions, SceneDescription, generate};
use std::path::Path;

/// The image-space RMS error (px) `rslf eval` prints, and its notes.
fn image_error(scene: &Path, result: &Path) -> (Option<f64>, String) {
    let (ok, stdout, stderr) = rslf(&["eval", "--scene", scene.to_str().unwrap(), "--result", result.to_str().unwrap(), "--no-write"]);
    assert!(ok, "{stderr}");
    let error = stdout.lines().find_map(|l| l.split("image-space RMS error ").nth(1)?.split(' ').next()?.parse().ok());
    (error, stdout)
}

#[test]
fn the_image_space_motion_error_takes_the_true_disparity_where_the_true_depth_is_missing() {
    let dir = tempdir();
    let scene = dir.path().join("scene");
    let truth = MotionRecord::ConstantVelocity { omega_rad_s: [0.0, 0.3, 0.0], velocity_m_s: [1.0, 0.0, 0.0] };
    let mut desc: SceneDescription = toml::from_str(&common::small_objects_description()).unwrap();
    desc.camera.num_cams = 5;
    // Rendered as the suite's views are, 6 x 6 rays a pixel: with one ray the views alias and the
    // cues measured between them miss the truth's by 0.22 px RMS, bearing out 0.7 to 2.3 of it
    // from one grid or size to the next.
    desc.render.supersampling = 6;
    desc.motion = Some(toml::from_str(&truth.to_toml_string()).unwrap());
    generate(&desc, &GenerateOptions { size: None, seed: 0 }, |_, _| {}).unwrap().write(&scene, false).unwrap();
    // A result whose motion is half the truth.
    let result = dir.path().join("result");
    std::fs::create_dir_all(&result).unwrap();
    let half = MotionRecord::ConstantVelocity { omega_rad_s: [0.0, 0.15, 0.0], velocity_m_s: [0.5, 0.0, 0.0] };
    std::fs::write(result.join("motion.toml"), half.to_toml_string()).unwrap();

    let (from_depth, stdout) = image_error(&scene, &result);
    let from_depth = from_depth.unwrap_or_else(|| panic!("no image-space error: {stdout}"));
    assert!(from_depth > 0.1, "half the motion is off by half its shift: {stdout}");
    // The split by texture in metrics.json covers every point: its groups' squared errors,
    // weighed by their shares, add up to the whole error's.
    let (ok, _, stderr) = rslf(&["eval", "--scene", scene.to_str().unwrap(), "--result", result.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    let metrics: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(result.join("metrics.json")).unwrap()).unwrap();
    let split = &metrics["motion"]["texture"];
    let squares = |group: &str| split[group]["share"].as_f64().unwrap() * split[group]["rms_error_px"].as_f64().map_or(0.0, |e| e * e);
    let added = (squares("one_way") + squares("both_ways") + squares("flat")).sqrt();
    assert!((added - from_depth).abs() < 2e-3, "{split} against {from_depth} px");
    // The cues measured between the views are compared with the true motion's, whatever the
    // result's motion: another estimate leaves them as they were. Tracked from the true
    // disparity in unaliased views, they bear out the truth's within a tenth and three standard
    // errors, and miss it by a few hundredths of a pixel.
    let cues = metrics["motion"]["cues"].clone();
    for group in ["both_ways", "one_way", "all"] {
        let g = &cues[group];
        let (share, se) = (g["truth_share"].as_f64().unwrap(), g["truth_share_se"].as_f64().unwrap());
        assert!(g["cues"].as_u64().unwrap() > 100 && g["implied_error_px"].is_f64(), "{cues}");
        assert!((share - 1.0).abs() < 0.1 && (share - 1.0).abs() < 3.0 * se.max(0.01), "{group}: {cues}");
        assert!(g["rms_miss_px"].as_f64().unwrap() < 0.06, "{group}: {cues}");
    }
    std::fs::write(result.join("motion.toml"), truth.to_toml_string()).unwrap();
    let (ok, _, stderr) = rslf(&["eval", "--scene", scene.to_str().unwrap(), "--result", result.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    let again: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(result.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(again["motion"]["cues"], cues);
    assert_eq!(again["motion"]["image"]["rms_error_px"].as_f64(), Some(0.0));
    std::fs::write(result.join("motion.toml"), half.to_toml_string()).unwrap();
    std::fs::remove_file(scene.join("gt_depth_lowres.pfm")).unwrap();
    let (from_disparity, stdout) = image_error(&scene, &result);
    let from_disparity = from_disparity.unwrap_or_else(|| panic!("no image-space error without gt_depth_lowres.pfm: {stdout}"));
    // The generator writes the disparity from the depth by the camera model: the same points.
    assert!((from_disparity - from_depth).abs() < 1e-3, "{from_disparity} px from the disparity, {from_depth} px from the depth");
    assert!(stdout.contains("the t = 0 points from gt_disp_lowres.pfm + parameters.cfg"), "{stdout}");
    std::fs::remove_file(scene.join("gt_disp_lowres.pfm")).unwrap();
    let (none, stdout) = image_error(&scene, &result);
    assert!(none.is_none() && stdout.contains("no ground-truth depth or disparity"), "{stdout}");
}
