//! `rslf generate` obeys FORMAT: checked the way real data is checked, on scenes it makes.

mod common;

use common::{rslf, tempdir};
use rslf::geometry::{Camera, rs_project};
use rslf::io::{GroundTruth, MotionRecord, Scene};
use rslf::synth::{FAST_PX, GenerateOptions, SLOW_PX, SceneDescription, base_scene, generate, suite};
use std::path::Path;

/// A base scene at `size` px and a 5x5 grid, with `motion`, written to `dir`.
fn small_scene(dir: &Path, name: &str, size: usize, motion: Option<&MotionRecord>) -> Scene {
    let mut desc: SceneDescription = base_scene(name).unwrap();
    desc.camera.num_cams = 5;
    desc.motion = motion.map(|m| toml::from_str(&m.to_toml_string()).unwrap());
    let options = GenerateOptions { size: Some([size, size]), seed: 0 };
    generate(&desc, &options, |_, _| {}).unwrap().write(dir, false).unwrap();
    Scene::load(dir).unwrap()
}

#[test]
fn a_static_scene_warps_onto_its_central_view_with_its_ground_truth_disparity() {
    let dir = tempdir();
    let scene = small_scene(&dir.path().join("s"), "objects", 256, None);
    let gt = GroundTruth::load(&scene.dir, 256, 256).unwrap();
    let disparity = gt.disparity.unwrap();
    for view in scene.grid.corners() {
        let (right, wrong) = (common::warp_error(&scene, &disparity, view, 1.0, 8), common::warp_error(&scene, &disparity, view, -1.0, 8));
        eprintln!("view {view:?}: warp error {right:.4} (FORMAT sign), {wrong:.4} (opposite)");
        // What remains is resampling of fine textures and disoccluded pixels; it halves from 128 to 256 px.
        assert!(right < 0.025, "view {view:?}: warp error {right}");
        assert!(wrong > 3.0 * right, "view {view:?}: {right} with the FORMAT sign, {wrong} with the opposite");
    }
    assert!(gt.mask.unwrap().iter().all(|&m| m), "static scene: every ground-truth pixel is visible");
    assert_eq!(gt.motion, Some(MotionRecord::zero()));
}

#[test]
fn moving_ground_truth_points_land_on_every_rolling_shutter_view_under_the_true_motion() {
    let dir = tempdir();
    let motion = MotionRecord::ConstantVelocity { omega_rad_s: [0.1, 0.25, -0.2], velocity_m_s: [0.6, -0.3, 0.5] };
    const S: usize = 256;
    let scene = small_scene(&dir.path().join("m"), "checkerboards", S, Some(&motion));
    let cam: Camera = scene.camera().unwrap();
    assert!(scene.is_rolling_shutter());
    let gt = GroundTruth::load(&scene.dir, S, S).unwrap();
    assert_eq!(gt.motion.as_ref(), Some(&motion));
    let (depth, central0, mask) = (gt.depth.unwrap(), gt.central.unwrap(), gt.mask.unwrap());
    let scaled =
        |k: f64| MotionRecord::ConstantVelocity { omega_rad_s: [0.1 * k, 0.25 * k, -0.2 * k], velocity_m_s: [0.6 * k, -0.3 * k, 0.5 * k] };
    // Mean colour error between the t = 0 central view and `view` sampled where `motion` puts
    // each visible ground-truth point, over the samples; and the largest shift from the static
    // projection.
    let error = |view, motion: &MotionRecord| {
        let image = scene.view(view).unwrap();
        let (mut sum, mut n, mut shift) = (0.0f64, 0usize, 0.0f64);
        for v in 4..S - 4 {
            for u in 4..S - 4 {
                if !mask[v * S + u] {
                    continue;
                }
                let p0 = cam.back_project(u as f64, v as f64, depth.get(u, v, 0) as f64);
                let (x, y, _) = rs_project(&cam, motion, view, &p0).unwrap();
                let (xs, ys, _) = cam.project(view, &p0);
                shift = shift.max(((x - xs).powi(2) + (y - ys).powi(2)).sqrt());
                for ch in 0..3 {
                    if let Some(s) = image.sample_bilinear(x as f32, y as f32, ch) {
                        sum += (s - central0.get(u, v, ch)).abs() as f64;
                        n += 1;
                    }
                }
            }
        }
        (sum / n as f64, n, shift)
    };
    let views: Vec<_> = std::iter::once(scene.central_id()).chain(scene.grid.corners()).collect();
    for view in views {
        let (truth, n, shift) = error(view, &motion);
        let (still, smaller, larger) = (error(view, &scaled(0.0)).0, error(view, &scaled(0.9)).0, error(view, &scaled(1.1)).0);
        eprintln!(
            "view {view:?}: colour error {truth:.4} under the true motion (x0.9 {smaller:.4}, x1.1 {larger:.4}, none {still:.4}) over {n} samples, largest shift {shift:.2} px"
        );
        assert!(n > 3 * (S - 8) * (S - 8) * 8 / 10, "view {view:?}: most pixels are masked visible and land inside: {n}");
        assert!(shift > 4.0, "view {view:?}: the motion must move points visibly: {shift} px");
        // What remains is resampling and, in the corners, what they see behind foreground edges.
        assert!(truth < 0.03, "view {view:?}: colour error {truth} following the true motion");
        assert!(still > 2.0 * truth, "view {view:?}: ignoring the motion must be worse: {still} vs {truth}");
        // The data's own minimum is at the true motion: a 10 % error either way is worse.
        assert!(
            smaller > 1.05 * truth && larger > 1.05 * truth,
            "view {view:?}: {truth} at the truth, {smaller} at 0.9x, {larger} at 1.1x"
        );
    }
    assert!(mask.iter().any(|&m| !m), "some points leave the view or get hidden under motion");
}

#[test]
fn the_same_seed_gives_the_same_scene_and_another_seed_another() {
    let desc = base_scene("vegetation").unwrap();
    let run = |seed| generate(&desc, &GenerateOptions { size: Some([48, 40]), seed }, |_, _| {}).unwrap();
    let (a, b, c) = (run(1), run(1), run(2));
    assert_eq!(a.views, b.views);
    assert_eq!(a.truth.depth, b.truth.depth);
    assert_ne!(a.views[40], c.views[40]);
    assert_eq!((a.views[0].width, a.views[0].height), (48, 40));
}

#[test]
fn the_suite_spans_static_slow_and_fast_motions_of_the_intended_size() {
    let size = 128;
    let entries = suite(&GenerateOptions { size: Some([size, size]), seed: 0 }).unwrap();
    assert_eq!(entries.len(), 33);
    let scale = size as f64 / 512.0;
    let mut used = [false; 6];
    for e in &entries {
        let target = match e.category {
            "static" => 0.0,
            "slow" => SLOW_PX * scale,
            "fast" => FAST_PX * scale,
            other => panic!("category {other}"),
        };
        assert!((e.max_shift_px - target).abs() <= 0.05 * target.max(1.0), "{}: {} px for {target}", e.name, e.max_shift_px);
        let m = e.description.motion().unwrap();
        for (i, x) in m.groups().iter().flat_map(|g| g.1.clone()).enumerate() {
            used[i] |= x != 0.0;
        }
    }
    assert!(used.iter().all(|&u| u), "every velocity dimension is exercised: {used:?}");
}

/// The README's suite table is what `rslf generate --suite --list` prints (a table edited by
/// hand once lost its velocity column to a search-and-replace).
#[test]
fn the_readme_suite_table_is_what_the_generator_lists() {
    let (ok, stdout, stderr) = rslf(&["generate", "--suite", "--list"]);
    assert!(ok, "{stderr}");
    let readme = std::fs::read_to_string(common::project_path("README.md")).unwrap();
    let listed: Vec<String> = stdout
        .lines()
        .skip(1)
        .map(|line| {
            // `name  kind  max shift  S px  omega [..] rad/s  v [..] m/s`
            let (head, rest) = line.split_once(" max shift ").expect("a suite line");
            let mut words = head.split_whitespace();
            let (name, kind) = (words.next().unwrap(), words.next().unwrap());
            let (shift, rest) = rest.trim_start().split_once(" px  omega ").unwrap();
            let (omega, rest) = rest.split_once(" rad/s  v ").unwrap();
            let velocity = rest.trim_end_matches(" m/s");
            format!("| `{name}` | {kind} | {shift} | {omega} | {velocity} |")
        })
        .collect();
    assert_eq!(listed.len(), 33, "{stdout}");
    let table: Vec<&str> =
        readme.lines().filter(|l| l.starts_with("| `") && ["| static |", "| slow |", "| fast |"].iter().any(|k| l.contains(k))).collect();
    assert_eq!(table, listed.iter().map(String::as_str).collect::<Vec<_>>());
}

#[test]
fn generate_refuses_bad_descriptions_and_existing_folders_cleanly() {
    let dir = tempdir();
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "name = \"x\"\n[[object]]\nshape = { kind = \"cone\" }\nposition = [0, 0, 1]\n").unwrap();
    let out = dir.path().join("out");
    let (ok, _, stderr) = rslf(&["generate", bad.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(!ok && stderr.contains("bad.toml") && stderr.contains("line 3"), "{stderr}");
    assert_eq!(stderr.matches("panicked").count(), 0);
    assert!(!out.exists());

    let scene_path = common::project_path("configs/scenes/objects.toml");
    let scene = scene_path.to_str().expect("the project path is UTF-8");
    std::fs::create_dir(&out).unwrap();
    let (ok, _, stderr) = rslf(&["generate", scene, "--out", out.to_str().unwrap(), "--size", "16"]);
    assert!(!ok && stderr.contains("already exists"), "{stderr}");
    let (ok, stdout, stderr) = rslf(&["generate", scene, "--out", out.to_str().unwrap(), "--size", "24x16", "--force"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("81 views rendered"), "{stdout}");
    let written = Scene::load(&out).unwrap();
    assert_eq!((written.width(), written.height(), written.present_views().len()), (24, 16, 81));
}

#[test]
fn the_motion_model_scenes_are_objects_under_a_motion_of_their_own_model() {
    let objects = SceneDescription::read(&common::project_path("configs/scenes/objects.toml")).unwrap();
    for (file, model) in
        [("objects_accel", "constant_acceleration"), ("objects_piecewise", "piecewise_constant"), ("objects_jolt", "piecewise_constant")]
    {
        let scene = SceneDescription::read(&common::project_path(&format!("configs/scenes/{file}.toml"))).unwrap();
        assert_eq!(scene.name, file);
        assert_eq!((&scene.camera, &scene.render, &scene.objects), (&objects.camera, &objects.render, &objects.objects), "{file}");
        let motion = scene.motion().unwrap();
        assert_eq!(motion.model_name(), model, "{file}");
        assert_ne!(motion, MotionRecord::zero());
    }
}

#[test]
fn a_description_on_a_base_overrides_camera_keys_one_by_one_and_replaces_the_rest() {
    let dir = tempdir();
    let write = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    write(
        "base.toml",
        "name = \"base\"\n[camera]\nnum_cams = 5\nsize = [32, 24]\n[motion]\nmodel = \"constant_velocity\"\nomega_rad_s = [0, 1, 0]\nvelocity_m_s = [0, 0, 0]\n[[object]]\nshape = { kind = \"sphere\", radius = 0.5 }\nposition = [0, 0, 4]\ntexture = { kind = \"flat\", color = [0.5, 0.5, 0.5] }\n",
    );
    let derived = write("derived.toml", "base = \"base.toml\"\nname = \"derived\"\n[camera]\nsize = [16, 16]\n");
    let scene = SceneDescription::read(&derived).unwrap();
    assert_eq!((scene.name.as_str(), scene.camera.size, scene.camera.num_cams, scene.objects.len()), ("derived", [16, 16], 5, 1));
    assert_eq!(scene.motion().unwrap().model_name(), "constant_velocity");
    // A motion of another model replaces the base's whole: none of its keys are left over.
    let piecewise = write(
        "piecewise.toml",
        "base = \"derived.toml\"\n[motion]\nmodel = \"piecewise_constant\"\nsegments = 1\nomega_rad_s = [[0, 0, 1]]\nvelocity_m_s = [[0, 0, 0]]\n",
    );
    let scene = SceneDescription::read(&piecewise).unwrap();
    assert_eq!((scene.name.as_str(), scene.camera.size), ("derived", [16, 16]));
    assert_eq!(scene.motion().unwrap().model_name(), "piecewise_constant");
    // A cycle, a missing base and a base that is not a path are errors naming the file.
    let cycle = write("cycle.toml", "base = \"cycle.toml\"\nname = \"c\"\n");
    let missing = write("missing.toml", "base = \"nowhere.toml\"\n");
    let number = write("number.toml", "base = 3\n");
    for (path, problem) in [(&cycle, "a cycle?"), (&missing, "nowhere.toml"), (&number, "`base` must be the path")] {
        let error = SceneDescription::read(path).unwrap_err().to_string();
        assert!(error.contains(problem), "{error}");
    }
}
