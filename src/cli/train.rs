//! `rslf train CONFIG [--scene DIR] [--out DIR]`.

use crate::config::{Config, DeviceChoice};
use crate::io::{GroundTruth, Scene};
use crate::model::SavedModel;
use crate::pipeline;
use std::path::PathBuf;

/// Arguments of `rslf train`.
#[derive(Debug, clap::Args)]
pub struct TrainArgs {
    /// The run's TOML config (see configs/).
    pub config: PathBuf,
    /// Scene folder; overrides the config's `scene`.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Result folder; overrides the config's `out`.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Device; overrides the config's `device`.
    #[arg(long, value_enum)]
    pub device: Option<DeviceChoice>,
    /// Folder of saved models; the fitted model goes to `MODELS/<result folder name>/model.json`.
    #[arg(long, default_value = "models")]
    pub models: PathBuf,
}

/// Loads config and scene, runs the pipeline, writes the result folder (and `metrics.json`
/// when the scene has ground truth).
pub fn run(args: TrainArgs, registries: &pipeline::Registries) -> crate::Result<()> {
    let config = Config::read(&args.config)?;
    registries.check(&config).map_err(|e| crate::Error::Usage(format!("{}: {e}", args.config.display())))?;
    let scene_dir = args.scene.or(config.scene.clone()).ok_or_else(|| {
        crate::Error::Usage(format!("{}: no scene: set `scene` in the config or pass --scene DIR", args.config.display()))
    })?;
    let out = args.out.or(config.out.clone()).unwrap_or_else(|| {
        let stem = args.config.file_stem().map_or("run".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from("results").join(stem)
    });
    let scene_dir = match scene_dir.to_str().and_then(|s| s.strip_prefix(crate::synth::BUILTIN_PREFIX)) {
        Some(name) => crate::synth::builtin_scene(name)?,
        None => scene_dir,
    };
    let device = crate::device::device(args.device.unwrap_or(config.device))?;
    let scene = Scene::load(&scene_dir)?;
    let gt = GroundTruth::load(&scene_dir, scene.width(), scene.height())?;
    outln!(
        "scene {}: {} of {} views, {}x{} px, {} channel(s), {}",
        scene_dir.display(),
        scene.present_views().len(),
        scene.grid.len(),
        scene.width(),
        scene.height(),
        scene.channels(),
        match (&scene.params, scene.is_rolling_shutter()) {
            (None, _) => "no parameters.cfg: disparity only, no depth or motion".to_string(),
            (Some(_), true) => "rolling shutter".to_string(),
            (Some(_), false) => "global shutter".to_string(),
        }
    );
    // Each stage's line is printed as the stage ends.
    let (result, _) = pipeline::run_logged(&config, &scene, &device, registries, pipeline::RunLog::printing())?;
    let written = result.write(&out, scene.camera().as_ref())?;
    for path in &written {
        outln!("wrote {}", path.display());
    }
    if let Some(gaussians) = &result.gaussians {
        let name = out.file_name().map_or("run".into(), |n| n.to_string_lossy().into_owned());
        let size = [scene.width(), scene.height()];
        let grid = [scene.grid.rows, scene.grid.cols];
        let model = SavedModel::new(&scene_dir, size, grid, gaussians.clone(), result.motion.as_ref(), scene.params.as_ref());
        let path = model.save(&args.models.join(name))?;
        outln!("wrote {}", path.display());
    }
    if !gt.is_empty() {
        super::eval::report(&scene_dir, &out, true)?;
    }
    Ok(())
}
