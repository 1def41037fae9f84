//! The result folder of a run, written per FORMAT: only once everything is computed, each file
//! whole or not at all.

use crate::geometry::Camera;
use crate::io::{IoResult, MotionRecord, Raster, create_dir_all, write_atomic, write_pfm, write_png};
use crate::model::GaussianSet;
use std::path::{Path, PathBuf};

/// What a run produced, ready to be written.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// Disparity of the central view at t = 0.
    pub disparity: Raster,
    /// The central view at t = 0.
    pub central: Raster,
    /// The estimated motion, when one was estimated.
    pub motion: Option<MotionRecord>,
    /// The fitted Gaussians, when a model was fitted.
    pub gaussians: Option<GaussianSet>,
    /// Loss per step, per stage: `(stage name, values)`.
    pub curves: Vec<(String, Vec<f32>)>,
}

/// Depth of every pixel of a disparity map; NaN where the disparity is at or beyond infinity.
pub fn depth_map(camera: &Camera, disparity: &Raster) -> Raster {
    let data = disparity
        .data
        .iter()
        .map(|&d| {
            let z = camera.disparity_to_depth(d as f64);
            if z.is_finite() && z > 0.0 { z as f32 } else { f32::NAN }
        })
        .collect();
    Raster { data, ..disparity.clone() }
}

impl RunResult {
    /// Writes `disparity.pfm`, `depth.pfm` (with a camera), `central.png` and `motion.toml`
    /// (when estimated) into `out`; returns the files written.
    pub fn write(&self, out: &Path, camera: Option<&Camera>) -> IoResult<Vec<PathBuf>> {
        create_dir_all(out)?;
        let mut written = Vec::new();
        let mut put = |name: &str, write: &dyn Fn(&Path) -> IoResult<()>| -> IoResult<()> {
            let path = out.join(name);
            write(&path)?;
            written.push(path);
            Ok(())
        };
        put("disparity.pfm", &|p| write_pfm(p, &self.disparity))?;
        if let Some(cam) = camera {
            put("depth.pfm", &|p| write_pfm(p, &depth_map(cam, &self.disparity)))?;
        }
        put("central.png", &|p| write_png(p, &self.central))?;
        if let Some(m) = &self.motion {
            put("motion.toml", &|p| m.write(p))?;
        }
        for (stage, curve) in &self.curves {
            let csv: String = std::iter::once("step,loss\n".to_string())
                .chain(curve.iter().enumerate().map(|(i, l)| format!("{},{l}\n", i + 1)))
                .collect();
            put(&format!("loss_{stage}.csv"), &|p| write_atomic(p, csv.as_bytes()))?;
        }
        Ok(written)
    }
}
