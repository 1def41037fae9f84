//! A scene folder's evaluation files: `gt_disp_lowres.pfm`, `gt_depth_lowres.pfm`, `gt_mask.png`,
//! `gt_central.png` and `gt_motion.toml`. Each is optional.

use super::error::{IoError, IoResult};
use super::image_file::read_image;
use super::motion_file::MotionRecord;
use super::pfm::read_pfm;
use super::raster::Raster;
use std::path::Path;

/// The ground truth a scene folder carries, checked against the views' size.
#[derive(Debug, Clone, Default)]
pub struct GroundTruth {
    /// Disparity of the central view at t = 0.
    pub disparity: Option<Raster>,
    /// Depth Z (m) of the central view at t = 0.
    pub depth: Option<Raster>,
    /// Pixels whose ground truth is visible in the rolling-shutter central view (`None` = all).
    pub mask: Option<Vec<bool>>,
    /// The central view at t = 0 without rolling shutter.
    pub central: Option<Raster>,
    /// The true motion.
    pub motion: Option<MotionRecord>,
}

/// Reads `path` with `read` when it exists; `None` when it does not.
pub fn read_if_present<T>(path: &Path, read: impl FnOnce(&Path) -> IoResult<T>) -> IoResult<Option<T>> {
    if path.exists() { read(path).map(Some) } else { Ok(None) }
}

fn check_size(path: &Path, r: &Raster, width: usize, height: usize) -> IoResult<()> {
    if (r.width, r.height) != (width, height) {
        return Err(IoError::new(path, format!("is {}x{} but the views are {width}x{height}", r.width, r.height)));
    }
    Ok(())
}

impl GroundTruth {
    /// Loads whatever ground truth `dir` has; every map must be `width x height`.
    pub fn load(dir: &Path, width: usize, height: usize) -> IoResult<Self> {
        let map = |name: &str| -> IoResult<Option<Raster>> {
            let path = dir.join(name);
            let r = read_if_present(&path, read_pfm)?;
            if let Some(r) = &r {
                check_size(&path, r, width, height)?;
            }
            Ok(r)
        };
        let image = |name: &str| -> IoResult<Option<Raster>> {
            let path = dir.join(name);
            let r = read_if_present(&path, read_image)?;
            if let Some(r) = &r {
                check_size(&path, r, width, height)?;
            }
            Ok(r)
        };
        let mask =
            image("gt_mask.png")?.map(|m| m.data.chunks_exact(m.channels).map(|px| px.iter().any(|&v| v > 0.0)).collect::<Vec<bool>>());
        Ok(Self {
            disparity: map("gt_disp_lowres.pfm")?,
            depth: map("gt_depth_lowres.pfm")?,
            mask,
            central: image("gt_central.png")?,
            motion: read_if_present(&dir.join("gt_motion.toml"), MotionRecord::read)?,
        })
    }

    /// `true` when there is nothing to evaluate against.
    pub fn is_empty(&self) -> bool {
        self.disparity.is_none() && self.depth.is_none() && self.central.is_none() && self.motion.is_none()
    }
}
