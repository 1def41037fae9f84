//! The built-in suite, in the spirit of the RSLF datasets: each base scene captured static, under
//! five slow and under five fast constant-velocity motions spread over the six velocity
//! dimensions. Slow and fast are set by the largest image displacement a point of the central
//! view undergoes during the read-out: 3 px and 15 px at 512 px wide (scaled with the width).

use super::description::SceneDescription;
use super::render::Capture;
use super::scene_folder::{GenerateOptions, capture_setup};
use super::world::World;
use crate::geometry::{Camera, rs_project};
use crate::io::{IoError, IoResult, MotionRecord};
use nalgebra::Point3;
use std::path::Path;

/// The base scenes: (name, description text). Their files are in `configs/scenes/`.
pub const BASE_SCENES: [(&str, &str); 3] = [
    ("checkerboards", include_str!("../../configs/scenes/checkerboards.toml")),
    ("vegetation", include_str!("../../configs/scenes/vegetation.toml")),
    ("objects", include_str!("../../configs/scenes/objects.toml")),
];

/// Largest image displacement over the read-out of a slow motion, pixels at 512 px wide.
pub const SLOW_PX: f64 = 3.0;
/// Largest image displacement over the read-out of a fast motion, pixels at 512 px wide.
pub const FAST_PX: f64 = 15.0;

/// Motion directions `[ωx, ωy, ωz, vx, vy, vz]` (rad/s, m/s; scaled afterwards), one per
/// slow/fast pair: pan with sideways drift, tilt with vertical drift, roll with forward motion,
/// pure translation, and all six at once.
pub const DIRECTIONS: [[f64; 6]; 5] = [
    [0.0, 0.25, 0.0, 1.0, 0.0, 0.0],
    [0.25, 0.0, 0.0, 0.0, -1.0, 0.0],
    [0.0, 0.0, 0.3, 0.0, 0.0, 1.5],
    [0.0, 0.0, 0.0, 1.0, 1.0, -1.0],
    [0.15, -0.15, 0.1, -0.6, 0.6, 0.8],
];

/// One scene of the suite.
#[derive(Debug, Clone)]
pub struct SuiteEntry {
    /// Folder name: `<scene>_static`, `<scene>_slow<k>`, `<scene>_fast<k>`.
    pub name: String,
    /// `static`, `slow` or `fast`.
    pub category: &'static str,
    /// The description, its motion set.
    pub description: SceneDescription,
    /// Largest image displacement of the motion over the read-out, pixels.
    pub max_shift_px: f64,
}

fn scaled(direction: &[f64; 6], s: f64) -> MotionRecord {
    MotionRecord::ConstantVelocity {
        omega_rad_s: [direction[0] * s, direction[1] * s, direction[2] * s],
        velocity_m_s: [direction[3] * s, direction[4] * s, direction[5] * s],
    }
}

/// Largest distance between where `points` (t = 0) project in the central view without and with
/// rolling shutter under `motion`.
pub fn max_shift_px(camera: &Camera, motion: &MotionRecord, points: &[Point3<f64>]) -> f64 {
    let centre = camera.grid.central().expect("odd grid");
    points
        .iter()
        .filter_map(|p| {
            let (u, v, _) = camera.project(centre, p);
            let (x, y, _) = rs_project(camera, motion, centre, p)?;
            Some(((x - u).powi(2) + (y - v).powi(2)).sqrt())
        })
        .fold(0.0, f64::max)
}

/// Points of the central view at t = 0 on a grid of `step` pixels.
fn sample_points(world: &World, camera: &Camera, step: usize) -> Vec<Point3<f64>> {
    let still = Capture::new(world, camera, &MotionRecord::zero());
    let centre = camera.grid.central().expect("odd grid");
    let mut points = Vec::new();
    for y in (0..camera.height).step_by(step) {
        for x in (0..camera.width).step_by(step) {
            let (o, d) = still.ray(centre, x as f64, y as f64, y);
            if let Some(hit) = world.trace(&o, &d) {
                points.push(hit.point);
            }
        }
    }
    points
}

/// The motion along `direction` whose largest image displacement is `target` pixels.
fn motion_for_shift(camera: &Camera, points: &[Point3<f64>], direction: &[f64; 6], target: f64) -> (MotionRecord, f64) {
    let mut s = 1.0;
    for _ in 0..4 {
        let shift = max_shift_px(camera, &scaled(direction, s), points);
        if shift <= 0.0 {
            break;
        }
        s *= target / shift;
    }
    let motion = scaled(direction, s);
    let shift = max_shift_px(camera, &motion, points);
    (motion, shift)
}

/// Parses a base scene's text.
pub fn base_scene(name: &str) -> IoResult<SceneDescription> {
    let (_, text) = BASE_SCENES
        .iter()
        .find(|(n, _)| *n == name)
        .ok_or_else(|| IoError::new(name, format!("no built-in scene `{name}` (expected one of checkerboards, vegetation, objects)")))?;
    SceneDescription::parse(text, Path::new(&format!("configs/scenes/{name}.toml")))
}

/// Every entry of the suite at the size and seed of `options`.
pub fn suite(options: &GenerateOptions) -> IoResult<Vec<SuiteEntry>> {
    let mut entries = Vec::new();
    for (name, _) in BASE_SCENES {
        let base = base_scene(name)?;
        let (params, _) = capture_setup(&base, options).map_err(|e| IoError::new(name, e))?;
        let camera = Camera::from_parameters(&params);
        let world = World::new(&base, options.seed);
        let points = sample_points(&world, &camera, (camera.width / 64).max(1));
        let scale = camera.width as f64 / 512.0;
        let mut with = |suffix: String, category, motion: MotionRecord, shift| {
            let mut description = base.clone();
            description.motion = Some(toml::from_str(&motion.to_toml_string()).expect("motion files are TOML"));
            entries.push(SuiteEntry { name: format!("{name}_{suffix}"), category, description, max_shift_px: shift });
        };
        with("static".into(), "static", MotionRecord::zero(), 0.0);
        for (k, dir) in DIRECTIONS.iter().enumerate() {
            let (m, shift) = motion_for_shift(&camera, &points, dir, SLOW_PX * scale);
            with(format!("slow{}", k + 1), "slow", m, shift);
        }
        for (k, dir) in DIRECTIONS.iter().enumerate() {
            let (m, shift) = motion_for_shift(&camera, &points, dir, FAST_PX * scale);
            with(format!("fast{}", k + 1), "fast", m, shift);
        }
    }
    Ok(entries)
}
