//! Fitted models on disk (`models/<run>/model.json`): the Gaussians with what is needed to render
//! them again.

use super::gaussians::GaussianSet;
use crate::geometry::Camera;
use crate::io::{IoError, IoResult, MotionRecord, SceneParameters, create_dir_all, write_atomic};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Format tag written into every saved model.
pub const FORMAT: &str = "rslf-gaussians-1";

/// A fitted model with its context.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedModel {
    /// Always [`FORMAT`].
    pub format: String,
    /// The scene folder it was fitted to.
    pub scene: PathBuf,
    /// Image size `[W, H]`.
    pub size: [usize; 2],
    /// View grid `[rows, cols]`.
    pub grid: [usize; 2],
    /// The Gaussians (central view, t = 0).
    pub gaussians: GaussianSet,
    /// The estimated motion, if any, as `motion.toml` text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<String>,
    /// The scene's `parameters.cfg` text, if it had one (the camera the model renders with).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parameters: Option<String>,
}

impl SavedModel {
    /// A model of `gaussians` fitted to `scene`.
    pub fn new(
        scene: &Path,
        size: [usize; 2],
        grid: [usize; 2],
        gaussians: GaussianSet,
        motion: Option<&MotionRecord>,
        parameters: Option<&SceneParameters>,
    ) -> Self {
        Self {
            format: FORMAT.into(),
            scene: scene.to_path_buf(),
            size,
            grid,
            gaussians,
            motion: motion.map(|m| m.to_toml_string()),
            parameters: parameters.map(|p| p.to_cfg_string()),
        }
    }

    /// The scene parameters the model was saved with.
    pub fn scene_parameters(&self) -> Option<SceneParameters> {
        // Checked by `load`, so parsing cannot fail here.
        self.parameters.as_deref().and_then(|text| SceneParameters::parse(text).ok())
    }

    /// The camera the model renders with, when its scene had `parameters.cfg`.
    pub fn camera(&self) -> Option<Camera> {
        self.scene_parameters().map(|p| Camera::from_parameters(&p))
    }

    /// The estimated motion, if any.
    pub fn motion_record(&self) -> Option<MotionRecord> {
        // Checked by `load`, so parsing cannot fail here.
        self.motion.as_deref().and_then(|text| MotionRecord::parse(text).ok())
    }

    /// Writes `dir/model.json`, whole or not at all; returns its path.
    pub fn save(&self, dir: &Path) -> IoResult<PathBuf> {
        create_dir_all(dir)?;
        let path = dir.join("model.json");
        let json = serde_json::to_string(self).map_err(|e| IoError::new(&path, e.to_string()))?;
        write_atomic(&path, json.as_bytes())?;
        Ok(path)
    }

    /// Reads a saved model (a `model.json` or the folder holding it).
    pub fn load(path: &Path) -> IoResult<Self> {
        let file = if path.is_dir() { path.join("model.json") } else { path.to_path_buf() };
        let text = std::fs::read_to_string(&file).map_err(|e| IoError::os(&file, e))?;
        let model: Self = serde_json::from_str(&text).map_err(|e| IoError::new(&file, format!("not an rslf model: {e}")))?;
        if model.format != FORMAT {
            return Err(IoError::new(&file, format!("model format `{}` is not `{FORMAT}`", model.format)));
        }
        let g = &model.gaussians;
        let n = g.u.len();
        if g.v.len() != n || g.disparity.len() != n || g.size.len() != n || g.colour.len() != n * g.channels {
            return Err(IoError::new(&file, "Gaussian arrays have different lengths"));
        }
        if let Some(text) = &model.parameters {
            SceneParameters::parse(text).map_err(|e| IoError::new(&file, format!("`parameters`: {e}")))?;
        }
        if let Some(text) = &model.motion {
            MotionRecord::parse(text).map_err(|e| IoError::new(&file, format!("`motion`: {e}")))?;
        }
        if model.size[0] == 0 || model.size[1] == 0 || model.grid[0] == 0 || model.grid[1] == 0 {
            return Err(IoError::new(&file, "`size` and `grid` must be positive"));
        }
        Ok(model)
    }
}
