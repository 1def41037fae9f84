//! The RSLF composition: stage-1 initialisation, stage-1 fit, stage-2 fit, results.
//!
//! This version runs the stage-1 initialisation (a central-row plane sweep); the Gaussian fit
//! of stage 1 and the motion estimation of stage 2 plug in after it.

mod plane_sweep;
mod results;

pub use plane_sweep::{DisparityEstimate, PlaneSweepSettings, plane_sweep};
pub use results::{RunResult, depth_map};

use crate::config::Config;
use crate::io::Scene;

/// Which stages a run carried out, for the user and the logs.
#[derive(Debug, Clone, Default)]
pub struct RunLog {
    /// One line per stage: what ran, with its figures, or why it did not.
    pub lines: Vec<String>,
}

/// The plane-sweep settings a config gives for a scene: the config's range, else the scene's
/// `[meta]` range, else [-4, 4] pixels.
pub fn sweep_settings(config: &Config, scene: &Scene) -> PlaneSweepSettings {
    let range = config
        .stage1
        .disparity_range
        .map(|[lo, hi]| (lo, hi))
        .or_else(|| scene.params.as_ref().and_then(|p| p.disparity_range))
        .unwrap_or((-4.0, 4.0));
    PlaneSweepSettings { range, step: config.stage1.disparity_step, window_radius: 2 }
}

/// Runs what this version of the pipeline has on `scene` and returns the result to write.
pub fn run(config: &Config, scene: &Scene) -> (RunResult, RunLog) {
    let mut log = RunLog::default();
    let settings = sweep_settings(config, scene);
    let views = scene.central_row_views();
    let labels = ((settings.range.1 - settings.range.0) / settings.step).round() as u64 + 1;
    let bar = crate::progress::bar(labels, "stage 1: init");
    let start = std::time::Instant::now();
    let estimate = plane_sweep(scene, &views, &settings, |done, _| bar.set_position(done as u64));
    bar.finish_and_clear();
    log.lines.push(format!(
        "stage 1 initialisation: plane sweep over {} central-row views, disparity {:.2}..{:.2} px in {} steps, {:.1} s",
        views.len(),
        settings.range.0,
        settings.range.1,
        labels,
        start.elapsed().as_secs_f64()
    ));
    if config.stage1.iterations > 0 {
        log.lines.push("stage 1 fit: not part of this version yet; the result is the initialisation".into());
    }
    if scene.is_rolling_shutter() && config.stage2.iterations > 0 {
        log.lines.push("stage 2 (motion): not part of this version yet; no motion.toml written".into());
    }
    let result = RunResult { disparity: estimate.disparity, central: scene.central().clone(), motion: None };
    (result, log)
}
