//! The result folder of a run, written per FORMAT: only once everything is computed, each file
//! whole or not at all.

use crate::geometry::Camera;
use crate::io::{IoResult, MotionRecord, Raster, create_dir_all, write_atomic, write_pfm, write_png};
use crate::model::GaussianSet;
use crate::render::StaticShape;
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
    /// The Gaussians' centres at t = 0 in metres, when the scene has a camera.
    pub points: Option<PointCloud>,
    /// Loss per step, per stage.
    pub curves: LossCurves,
}

/// Loss per step, per stage: `(stage name, values)`.
pub type LossCurves = Vec<(String, Vec<f32>)>;

/// A coloured point cloud: the scene at t = 0 in the central camera frame (OpenCV axes, metres).
#[derive(Debug, Clone, PartialEq)]
pub struct PointCloud {
    /// `[x, y, z]` per point.
    pub positions: Vec<[f32; 3]>,
    /// Colour per point in [0, 1] (grey repeated for one-channel scenes).
    pub colours: Vec<[f32; 3]>,
}

impl PointCloud {
    /// The centres and colours of a static shape; points behind the camera are left out.
    pub fn of_shape(shape: &StaticShape) -> Self {
        let p = crate::device::host_values(shape.points.clone());
        let c = crate::device::host_values(shape.colour.clone());
        let channels = shape.colour.dims()[1];
        let mut cloud = Self { positions: Vec::new(), colours: Vec::new() };
        for (xyz, col) in p.chunks_exact(3).zip(c.chunks_exact(channels)) {
            if xyz.iter().all(|v| v.is_finite()) && xyz[2] > 0.0 {
                cloud.positions.push([xyz[0], xyz[1], xyz[2]]);
                cloud.colours.push(if channels == 3 { [col[0], col[1], col[2]] } else { [col[0]; 3] });
            }
        }
        cloud
    }

    /// The cloud as an ASCII PLY file (x y z as float, red green blue as uchar).
    pub fn to_ply(&self) -> String {
        use std::fmt::Write;
        let mut out = format!(
            "ply\nformat ascii 1.0\ncomment rslf: scene at t = 0, central camera frame (x right, y down, z forward), metres\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n",
            self.positions.len()
        );
        let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        for (p, c) in self.positions.iter().zip(&self.colours) {
            let _ = writeln!(out, "{} {} {} {} {} {}", p[0], p[1], p[2], byte(c[0]), byte(c[1]), byte(c[2]));
        }
        out
    }
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
    /// Writes `disparity.pfm`, `depth.pfm` (with a camera), `central.png`, `motion.toml`
    /// (when estimated), `points.ply` (with a camera) and the loss curves into `out`; returns the files written.
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
        if let Some(cloud) = &self.points {
            put("points.ply", &|p| write_atomic(p, cloud.to_ply().as_bytes()))?;
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
