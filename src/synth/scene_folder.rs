//! Generating one scene and writing it as a FORMAT scene folder, whole or not at all.

use super::description::SceneDescription;
use super::render::Capture;
use super::truth::{Truth, ground_truth};
use super::world::World;
use crate::geometry::Camera;
use crate::io::{IoResult, MotionRecord, Raster, SceneParameters, view_file_name, write_folder, write_mask_png, write_pfm, write_png};
use std::path::Path;

/// Overrides of a description for one generation.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GenerateOptions {
    /// Image size `[W, H]` instead of the description's.
    pub size: Option<[usize; 2]>,
    /// Seed mixed into every random choice (noise lattices, branch shapes).
    pub seed: u64,
}

/// A generated light field with its ground truth, in memory.
#[derive(Debug, Clone)]
pub struct GeneratedScene {
    /// Its `parameters.cfg`.
    pub params: SceneParameters,
    /// Every view, index order.
    pub views: Vec<Raster>,
    /// Ground truth.
    pub truth: Truth,
    /// The true motion.
    pub motion: MotionRecord,
}

/// The camera and motion a description gives under `options` (disparity range left unset).
pub fn capture_setup(desc: &SceneDescription, options: &GenerateOptions) -> Result<(SceneParameters, MotionRecord), String> {
    let mut cam = desc.camera.clone();
    if let Some(size) = options.size {
        cam.size = size;
    }
    Ok((cam.parameters(None), desc.motion()?))
}

/// Renders every view of `desc` and its ground truth; `progress(done, total)` after each view.
pub fn generate(
    desc: &SceneDescription,
    options: &GenerateOptions,
    mut progress: impl FnMut(usize, usize),
) -> Result<GeneratedScene, String> {
    let (mut params, motion) = capture_setup(desc, options)?;
    let camera = Camera::from_parameters(&params);
    let world = World::new(desc, options.seed);
    let n = desc.render.supersampling;
    let truth = ground_truth(&world, &camera, &motion, n);
    let finite = truth.disparity.data.iter().filter(|d| d.is_finite());
    let (lo, hi) = finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &d| (a.min(d), b.max(d)));
    if lo.is_finite() && hi.is_finite() {
        let margin = 0.1 * (hi - lo).max(1.0) as f64;
        let round = |v: f64, up: bool| if up { (v * 10.0).ceil() / 10.0 } else { (v * 10.0).floor() / 10.0 };
        params.disparity_range = Some((round(lo as f64 - margin, false), round(hi as f64 + margin, true)));
    }
    let capture = Capture::new(&world, &camera, &motion);
    let total = camera.grid.len();
    let views = (0..total)
        .map(|i| {
            let view = capture.render_view(camera.grid.view(i), n);
            progress(i + 1, total);
            view
        })
        .collect();
    Ok(GeneratedScene { params, views, truth, motion })
}

/// [`generate`] with a progress bar on stderr (shown only on a terminal).
pub fn generate_with_progress(desc: &SceneDescription, options: &GenerateOptions) -> Result<GeneratedScene, String> {
    let bar = crate::progress::bar(1, &desc.name);
    let scene = generate(desc, options, |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    scene
}

impl GeneratedScene {
    /// Writes the scene folder `out`: views, `parameters.cfg`, ground truth. The folder appears
    /// only once complete; an existing `out` is replaced only when `replace` is set.
    pub fn write(&self, out: &Path, replace: bool) -> IoResult<()> {
        write_folder(out, replace, |dir| self.write_files(dir))
    }

    fn write_files(&self, dir: &Path) -> IoResult<()> {
        for (i, view) in self.views.iter().enumerate() {
            write_png(&dir.join(view_file_name(i)), view)?;
        }
        self.params.write(&dir.join("parameters.cfg"))?;
        write_pfm(&dir.join("gt_disp_lowres.pfm"), &self.truth.disparity)?;
        write_pfm(&dir.join("gt_depth_lowres.pfm"), &self.truth.depth)?;
        write_png(&dir.join("gt_central.png"), &self.truth.central)?;
        let (w, h) = (self.truth.depth.width, self.truth.depth.height);
        write_mask_png(&dir.join("gt_mask.png"), &self.truth.mask, w, h)?;
        self.motion.write(&dir.join("gt_motion.toml"))
    }
}
