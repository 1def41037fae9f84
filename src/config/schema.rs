//! The TOML run configuration: which scene, where results go, which device, and how each stage,
//! the motion model and the loss terms are set. Every table refuses keys it does not know.

use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Which burn device runs the tensor programs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum DeviceChoice {
    /// burn's pure-Rust CPU backend.
    #[default]
    Flex,
    /// The GPU through wgpu (Vulkan, Metal, DX12 or OpenGL).
    Wgpu,
}

/// A whole run: `rslf train CONFIG`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// The scene folder (FORMAT layout). `--scene` overrides it.
    #[serde(default)]
    pub scene: Option<PathBuf>,
    /// The result folder. `--out` overrides it; default `results/<config name>`.
    #[serde(default)]
    pub out: Option<PathBuf>,
    /// `flex` (CPU, default) or `wgpu` (GPU).
    #[serde(default)]
    pub device: DeviceChoice,
    /// Seed of every random choice of the run (Gaussian sampling, ...).
    #[serde(default)]
    pub seed: u64,
    /// Stage 1: geometry from the central row of views, free of motion (and, if asked, from a few
    /// views of the central column).
    #[serde(default)]
    pub stage1: Stage1Config,
    /// Stage 2: motion from the off-row views.
    #[serde(default)]
    pub stage2: Stage2Config,
    /// The motion model of stage 2.
    #[serde(default)]
    pub motion: MotionConfig,
    /// The Gaussian renderer.
    #[serde(default)]
    pub render: RenderConfig,
    /// Loss terms and their weights (`[[loss]]` tables); default: photometric L1 and edge-aware
    /// disparity smoothness of weight 0.05.
    #[serde(default = "default_losses")]
    pub loss: Vec<LossConfig>,
}

/// Stage 1 settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Stage1Config {
    /// Number of Gaussians sampled on the central view.
    pub gaussians: usize,
    /// Adam iterations of the stage-1 fit (0 = initialisation only).
    pub iterations: usize,
    /// How many views of the central row to fit, centred on the central view.
    pub views: usize,
    /// How many views of the central column to fit too, in the plane sweep and the fit, nearest
    /// the central view first (0 = the paper's central row only). They hold the vertical
    /// parallax the row lacks (the disparity of horizontal edges), but read a point of disparity
    /// `d` in view row `r` at `(r-rc) d` rows from where the central view does, so motion in
    /// those `(r-rc) d` line times bends them slightly: measured in docs/results.md, four of them
    /// halve the static drift but double the error of a pan. Unset, it is 0 on a
    /// rolling-shutter capture and `views - 1` on a global-shutter one, where nothing bends
    /// them (see [`Stage1Config::column_views_for`]).
    #[serde(default)]
    pub column_views: Option<usize>,
    /// Rows per band: each Adam step renders one band in every view.
    pub band_height: usize,
    /// Disparity search range `[min, max]` of the initial plane sweep, pixels; default: the
    /// scene's `[meta] disp_min, disp_max`, else `[-4, 4]`.
    pub disparity_range: Option<[f64; 2]>,
    /// Step between plane-sweep candidates, pixels.
    pub disparity_step: f64,
    /// Adam learning rate of the centres, pixels per step.
    pub lr_position: f64,
    /// Adam learning rate of the disparities, pixels per step.
    pub lr_disparity: f64,
    /// Adam learning rate of `ln σ` per step.
    pub lr_size: f64,
    /// Adam learning rate of the colours per step.
    pub lr_colour: f64,
    /// The disparities' rate decays along a half cosine over the fit to this share of itself
    /// (1: constant). At a constant rate Adam keeps moving each disparity by about the rate a
    /// step up to the last one; the decay lets them settle. The other rates stay constant.
    pub lr_disparity_final_share: f64,
    /// Adam's epsilon (measured on HCI antinous: 1e-15 lets disparities random-walk, BadPix(0.07)
    /// 50.7%; 1e-5 gives 24.7%).
    pub adam_epsilon: f64,
    /// A disparity map (PFM, the central view's size) to start from instead of the plane sweep,
    /// e.g. another method's estimate, or the ground truth for an ablation.
    pub initial_disparity: Option<PathBuf>,
}

impl Config {
    /// The loss terms that count in `stage` (1 or 2), in config order.
    pub fn losses_in(&self, stage: u8) -> Vec<LossConfig> {
        self.loss.iter().filter(|l| l.applies_in(stage)).cloned().collect()
    }
}

impl Stage1Config {
    /// The central-column views to fit on a capture with or without a rolling shutter: the
    /// configured count, else none with a rolling shutter (the paper's central row) and as many
    /// as the row's off-centre views without one.
    pub fn column_views_for(&self, rolling_shutter: bool) -> usize {
        self.column_views.unwrap_or(if rolling_shutter { 0 } else { self.views.saturating_sub(1) })
    }
}

impl Default for Stage1Config {
    fn default() -> Self {
        Self {
            gaussians: 20_000,
            iterations: 100,
            views: 5,
            column_views: None,
            band_height: 64,
            disparity_range: None,
            disparity_step: 0.05,
            lr_position: 0.05,
            lr_disparity: 0.01,
            lr_size: 0.01,
            lr_colour: 0.01,
            lr_disparity_final_share: 0.1,
            adam_epsilon: 1e-5,
            initial_disparity: None,
        }
    }
}

/// Which off-row views stage 2 compares against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ViewSelection {
    /// The four corner views (the paper's choice).
    #[default]
    Corners,
    /// Every present view off the central row.
    AllOffRow,
    /// The present views on the grid's two diagonals, off the central row: 16 of a 9 x 9 grid,
    /// and all that the HCI benchmark's 33-view captures hold off the central row and column.
    Diagonals,
}

/// How stage 2 assigns read-out times when it renders a rolling-shutter view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimingChoice {
    /// Every Gaussian at the time of each band's centre row, band by band (the paper's scheme).
    Bands,
    /// Each Gaussian at the time of the row it lands on, found by fixed-point iteration; one
    /// pass per view.
    #[default]
    PerGaussian,
}

/// Stage 2 settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Stage2Config {
    /// Adam iterations of the motion fit (0 = no motion estimation).
    pub iterations: usize,
    /// The views compared against.
    pub views: ViewSelection,
    /// Read-out timing: `per_gaussian` or `bands`.
    pub timing: TimingChoice,
    /// Rows per band: per read-out time with `bands` timing, and per compared band in both.
    pub band_height: usize,
    /// Fixed-point iterations of `per_gaussian` timing.
    pub timing_iterations: usize,
    /// Bands compared per view and Adam step, spread over the image.
    pub bands_per_step: usize,
    /// Starting learning rate of the motion, in scaled units (one unit moves the image by about
    /// one pixel over half the read-out) per step; decays along a half cosine to `lr_final`.
    pub lr: f64,
    /// Final learning rate.
    pub lr_final: f64,
    /// Adam's epsilon.
    pub adam_epsilon: f64,
    /// Joint refinement: also fit the Gaussians in stage 2, against the central-row views and
    /// the off-row views together, at the stage-1 rates times this factor (0 = motion only, the
    /// paper's stage 2).
    pub refine_gaussians: f64,
    /// Leave out of the photometric terms the pixels of each compared view that no central-view
    /// pixel reaches (surfaces the central view does not see, which the Gaussians cannot
    /// render), so that the motion is not bent to shrink their residuals.
    pub mask_disocclusions: bool,
    /// With `mask_disocclusions`, leave the disocclusions out of the motion's residual too; false
    /// masks only the Gaussians' residual (joint refinement, which it then needs), and the motion
    /// compares every pixel.
    pub mask_motion_residual: bool,
    /// Pixels by which that mask is widened around each pixel no central-view pixel reaches.
    pub disocclusion_margin: usize,
    /// Weigh each pixel of an off-row view, in the motion's residual, by the share of its local
    /// gradient energy that is horizontal, so that horizontal edges (whose disparity the central
    /// row cannot fix, and whose vertical displacement a disparity error imitates exactly) do not
    /// bend the motion. Under joint refinement the Gaussians still compare every pixel.
    pub aperture_weighting: bool,
    /// Weight of the measured-cue term (0 = off): textured patches of the central-row view of
    /// the column of each view in `cue_views` are tracked into the view of the central row
    /// farthest from it (their disparity) and into that view, which measures, with no scene
    /// model, how far the motion moved each from where its disparity alone puts it (across the
    /// edges only, for an edge or a stripe); the term is the Huber penalty (px) of the motion's
    /// predicted cues against those along each measured direction, averaged per cue. With the cue
    /// check on, the term is left out of the fit the check judges, and a motion the check
    /// confirms is fitted again from the start with it.
    pub cue_weight: f64,
    /// The least support (0..1) the cues measured between the views must give the estimated
    /// motion for it to be kept: the noise-weighted least-squares scale of the estimate's
    /// predicted cues that fits the measured ones (1: borne out, 0: no such motion seen). Unless
    /// it is over it by two standard errors, the estimate is taken for a drift of the photometric
    /// fit and no motion is kept, unless the fit with the cues (`min_cue_signal`) is. 0 = no
    /// check.
    pub min_cue_support: f64,
    /// A motion whose photometric fit the check does not confirm is fitted again from the start
    /// with the measured cues (`cue_weight`), and kept when the cues confirm that fit at
    /// `min_cue_support` and its predicted cues stand at least this many times the measured
    /// cues' scatter clear of none, per cue ([`crate::pipeline::CueSupport::signal`]): the
    /// photometric fit can overshoot a true motion past the check, while a still scene's fit
    /// with the cues keeps only what their biases bear out. 0 = no such fit (the motion is set
    /// to none).
    pub min_cue_signal: f64,
    /// The views the cues are measured in: `corners`, `diagonals` or `all_off_row` (every
    /// present view off the central row and the central column), each tracked from the
    /// central-row view of its column.
    pub cue_views: ViewSelection,
    /// Edges and stripes (patches textured one way) give cues to the fit too: the component of
    /// the cue across them. They reach rows that patches textured both ways leave without cues
    /// (a striped wall), which a model with rates per part of the read-out needs, but carry
    /// biases of a few percent of the cue that the two-way patches do not (docs/results.md), so
    /// the check never uses them.
    pub cue_edges: bool,
    /// Cues of patches textured both ways whose row or corner match leaves more than this many
    /// times the scene's median share of the patch's contrast unexplained are left out, of the
    /// check and the fit (0 = none left out; by default
    /// [`crate::pipeline::MAX_RESIDUAL_OVER_MEDIAN`], 2). Those matches are the ones off the truth.
    pub cue_outlier_bound: f64,
    /// Cues of patches textured both ways whose two matches pin their displacements more than
    /// this many grid steps apart along x are left out, of the check and the fit (0 = none left
    /// out; by default [`crate::pipeline::MAX_LEVER_STEPS`], 1). The disparity gradient that
    /// carries both to the patch centre is off where the patch does not pin it, and such a cue
    /// by `b` times that error times the distance.
    pub cue_lever_bound: f64,
    /// The fit weighs down each cue whose matches leave more of its patch unexplained than the
    /// scene's median, by the inverse square of that share over the median.
    pub cue_residual_weights: bool,
    /// A motion file (FORMAT's `motion.toml` schema) to start from, e.g. from an IMU; default:
    /// no motion. With `iterations = 0` the scene is compensated with this motion as it is.
    pub initial_motion: Option<PathBuf>,
    /// Damped Newton steps on the motion after the Adam steps of the fit whose motion is kept
    /// (0 = none): the objective's Hessian in the motion parameters from finite differences of
    /// its gradient over every band of the compared views, each step taken only where it lowers
    /// that objective. They reach along the nearly flat directions (roll, forward translation)
    /// that Adam's decaying steps leave short, and hold the flattest (rotation against
    /// translation), which the views hardly observe. With the measured cues in the objective
    /// they leave the motion prior out: it would only shrink the directions they move.
    pub newton_iterations: usize,
    /// After the Newton steps, the directions they hold are set to rest (their components of
    /// the scaled motion put to 0) if that raises the objective by at most this share of it
    /// (0 = left where the Adam steps put them): what the views cannot tell apart is taken to be
    /// still. One more Hessian (a gradient per motion parameter).
    pub newton_rest_tolerance: f64,
    /// With the measured-cue term in the fit, after the Newton steps (and the move to rest) the
    /// directions they hold are set where the cue term alone is least, the rest of the motion
    /// kept: along them the photometric objective's minimum is off the truth (freed, they carry
    /// the fit away from it), while the cues', measured straight between the views, can lie
    /// near it. One more Hessian, then Newton steps on the cue term alone. The move is kept only
    /// where the views and the cues both ask for it: the photometric terms must not rise with
    /// it, and the cues must bear it out at `min_axial_support`, judged over blocks of the image
    /// (0: the views alone judge it).
    pub held_by_cues: bool,
    /// The least support (0..1) the measured cues must give the part of the kept motion along
    /// and about the optical axis (forward translation, roll: the least observed rates), the
    /// rest of the motion held, with a standard error from a jackknife over blocks of the image
    /// (the cues' errors are shared within a region). Unless it is over it by two standard
    /// errors, that part is set to 0. 0 = no such check.
    pub min_axial_support: f64,
}

impl Default for Stage2Config {
    fn default() -> Self {
        Self {
            iterations: 100,
            views: ViewSelection::Corners,
            timing: TimingChoice::PerGaussian,
            band_height: 16,
            timing_iterations: 3,
            bands_per_step: 8,
            lr: 0.3,
            lr_final: 0.01,
            adam_epsilon: 1e-8,
            refine_gaussians: 1.0,
            mask_disocclusions: true,
            mask_motion_residual: true,
            disocclusion_margin: 6,
            aperture_weighting: false,
            cue_weight: 1.0,
            min_cue_support: 0.5,
            min_cue_signal: 0.6,
            cue_views: ViewSelection::Corners,
            cue_edges: false,
            cue_outlier_bound: 2.0,
            cue_lever_bound: crate::pipeline::MAX_LEVER_STEPS,
            cue_residual_weights: true,
            initial_motion: None,
            newton_iterations: 5,
            newton_rest_tolerance: 1e-3,
            held_by_cues: false,
            min_axial_support: 0.5,
        }
    }
}

/// The motion model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MotionConfig {
    /// Registry name: `constant_velocity`, `constant_acceleration`, `piecewise_constant`, ...
    pub model: String,
    /// Segments of `piecewise_constant`.
    pub segments: usize,
}

impl Default for MotionConfig {
    fn default() -> Self {
        Self { model: "constant_velocity".into(), segments: 4 }
    }
}

/// Renderer settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderConfig {
    /// Gaussians blended per pixel (K), front-most first.
    pub max_per_pixel: usize,
    /// Footprint radius of a Gaussian, in standard deviations.
    pub cutoff_sigma: f64,
}

impl Default for RenderConfig {
    fn default() -> Self {
        Self { max_per_pixel: 16, cutoff_sigma: 3.0 }
    }
}

/// One loss term: a registry name and its weight.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LossConfig {
    /// Registry name: `l1`, `l2`, `dssim`, `smoothness`, `motion_prior`, `motion_smoothness`, ...
    pub kind: String,
    /// Weight of the term in the total loss.
    #[serde(default = "one")]
    pub weight: f64,
    /// The stages the term counts in (`[1]`, `[2]` or `[1, 2]`); unset, every stage.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stages: Option<Vec<u8>>,
}

impl LossConfig {
    /// The term `kind` at `weight`, in every stage.
    pub fn new(kind: &str, weight: f64) -> Self {
        Self { kind: kind.into(), weight, stages: None }
    }

    /// Whether the term counts in `stage` (1 or 2).
    pub fn applies_in(&self, stage: u8) -> bool {
        self.stages.as_ref().is_none_or(|s| s.contains(&stage))
    }
}

fn one() -> f64 {
    1.0
}

/// Photometric L1 plus a light edge-aware disparity smoothness (on HCI antinous, weight 0.05
/// takes the stage-1 fit from BadPix(0.07) 23.6 % at initialisation to 22.1 %; L1 alone ends
/// at 24.6 %, weight 0.5 at 26.6 %), and in stage 2 a motion prior of weight 3e-5 (it holds
/// a static scene still: at 256 px, 1.88 px of drift without it, 0.47 px with it).
fn default_losses() -> Vec<LossConfig> {
    vec![LossConfig::new("l1", 1.0), LossConfig::new("smoothness", 0.05), LossConfig::new("motion_prior", 3e-5)]
}

impl Default for Config {
    fn default() -> Self {
        Self {
            scene: None,
            out: None,
            device: DeviceChoice::default(),
            seed: 0,
            stage1: Stage1Config::default(),
            stage2: Stage2Config::default(),
            motion: MotionConfig::default(),
            render: RenderConfig::default(),
            loss: default_losses(),
        }
    }
}
