//! Helpers shared by the end-to-end tests: where the HCI scenes are, and tiny scenes made here.
#![allow(dead_code)]

use rslf::geometry::ViewId;
use rslf::io::{Raster, Scene, SceneParameters, view_file_name, write_png};
use std::path::{Path, PathBuf};

/// The project folder. Cargo names it at run time; the path baked in at compile time is only the
/// fallback, because a target folder shared between two clones of the project (as `.ci/run`'s
/// is) can hand one clone test binaries that another compiled, with that clone's path inside.
pub fn project_dir() -> PathBuf {
    std::env::var_os("CARGO_MANIFEST_DIR").map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")), PathBuf::from)
}

/// A file or folder of the project, by its path relative to the project folder.
pub fn project_path(relative: &str) -> PathBuf {
    project_dir().join(relative)
}

/// A folder of the HCI benchmark scenes (`../shared/data/hci` beside the project, or
/// `$RSLF_HCI_DIR`). Panics with a clear message when it is not there: these tests are the
/// project's proof of its conventions on real data and must not be skipped silently.
pub fn hci(scene: &str) -> PathBuf {
    let root = std::env::var_os("RSLF_HCI_DIR").map(PathBuf::from).unwrap_or_else(|| project_path("../shared/data/hci"));
    let dir = root.join(scene);
    assert!(dir.is_dir(), "HCI scene not found at {} (set RSLF_HCI_DIR to the folder holding antinous/, cotton/, dino/)", dir.display());
    dir
}

/// A deterministic texture in [0, 1]: a sum of sinusoids at several scales plus hashed noise.
pub fn texture(x: f64, y: f64, channel: usize) -> f32 {
    let c = channel as f64;
    let v = 0.5
        + 0.18 * (0.37 * x + 0.11 * y + c).sin()
        + 0.12 * (0.05 * x - 0.29 * y + 2.0 * c).sin()
        + 0.10 * (0.71 * x + 0.53 * y).sin() * (0.13 * y - 0.07 * x + c).cos();
    v.clamp(0.0, 1.0) as f32
}

/// Parameters of a small `n x n` grid scene of `w x h` pixels.
pub fn params(w: usize, h: usize, n: usize) -> SceneParameters {
    SceneParameters {
        focal_length_mm: 50.0,
        image_resolution_x_px: w,
        image_resolution_y_px: h,
        sensor_size_mm: 36.0,
        num_cams_x: n,
        num_cams_y: n,
        baseline_mm: 10.0,
        focus_distance_m: 2.0,
        disparity_range: Some((-2.0, 2.0)),
        line_time_s: None,
    }
}

/// Writes a fronto-parallel textured plane of constant disparity `d` as an `n x n` light field:
/// view (r, c) at pixel (x, y) shows the central texture at `(x + (c-cc) d, y + (r-rc) d)`.
/// Only the views whose index passes `keep` are written.
pub fn write_plane_scene(dir: &Path, w: usize, h: usize, n: usize, d: f64, keep: impl Fn(usize) -> bool) {
    write_plane_scene_with(dir, w, h, n, d, keep, texture)
}

/// [`write_plane_scene`] with another texture.
#[allow(dead_code)]
pub fn write_plane_scene_with(
    dir: &Path,
    w: usize,
    h: usize,
    n: usize,
    d: f64,
    keep: impl Fn(usize) -> bool,
    texture: impl Fn(f64, f64, usize) -> f32,
) {
    std::fs::create_dir_all(dir).unwrap();
    let cc = (n as f64 - 1.0) / 2.0;
    for r in 0..n {
        for c in 0..n {
            let index = r * n + c;
            if !keep(index) {
                continue;
            }
            let mut img = Raster::zeros(w, h, 3);
            for y in 0..h {
                for x in 0..w {
                    let (sx, sy) = (x as f64 + (c as f64 - cc) * d, y as f64 + (r as f64 - cc) * d);
                    for ch in 0..3 {
                        img.set(x, y, ch, texture(sx, sy, ch));
                    }
                }
            }
            write_png(&dir.join(view_file_name(index)), &img).unwrap();
        }
    }
}

/// A fresh empty folder under the system's temporary folder, removed when dropped.
pub struct TempDir(PathBuf);

impl TempDir {
    /// The folder.
    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Makes a [`TempDir`] unique to this process and call.
pub fn tempdir() -> TempDir {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static COUNT: AtomicUsize = AtomicUsize::new(0);
    let n = COUNT.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("rslf-test-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    TempDir(dir)
}

/// Runs the `rslf` binary; returns (exit success, stdout, stderr).
pub fn rslf(args: &[&str]) -> (bool, String, String) {
    rslf_with_env(args, &[])
}

/// Runs the `rslf` binary from the project folder with extra environment variables.
pub fn rslf_with_env(args: &[&str], env: &[(&str, &Path)]) -> (bool, String, String) {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_rslf"));
    cmd.args(args).current_dir(project_dir());
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd.output().unwrap();
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Mean absolute difference between the central view and `view` warped onto it with
/// `sign * disparity` by FORMAT's rule, over pixels `border` away from the edges whose sample
/// stays inside the view.
pub fn warp_error(scene: &Scene, disparity: &Raster, view: ViewId, sign: f64, border: usize) -> f64 {
    let central = scene.central();
    let img = scene.view(view).unwrap();
    let (mut sum, mut n) = (0.0f64, 0usize);
    for y in border..central.height - border {
        for x in border..central.width - border {
            let d = sign * disparity.get(x, y, 0) as f64;
            let (xs, ys) = scene.grid.position_in_view(view, x as f64, y as f64, d);
            for ch in 0..central.channels {
                if let Some(s) = img.sample_bilinear(xs as f32, ys as f32, ch) {
                    sum += (s - central.get(x, y, ch)).abs() as f64;
                    n += 1;
                }
            }
        }
    }
    sum / n as f64
}

/// `configs/scenes/objects.toml` at 64 x 64 px and one ray per pixel: small and quick to render.
pub fn small_objects_description() -> String {
    let text = std::fs::read_to_string(project_path("configs/scenes/objects.toml")).unwrap();
    let small = |line: &str| match line {
        l if l.starts_with("size = ") => "size = [64, 64]".to_string(),
        l if l.starts_with("supersampling = ") => "supersampling = 1".to_string(),
        l => l.to_string(),
    };
    let text: Vec<String> = text.lines().map(small).collect();
    assert!(text.iter().any(|l| l == "size = [64, 64]") && text.iter().any(|l| l == "supersampling = 1"));
    text.join("\n") + "\n"
}
