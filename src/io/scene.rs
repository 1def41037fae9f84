//! Scene folders: the views `input_CamNNN.{png,exr}` on a grid, and `parameters.cfg` when present.

use super::error::{IoError, IoResult};
use super::image_file::read_image;
use super::params::SceneParameters;
use super::raster::Raster;
use crate::geometry::{Camera, ViewGrid, ViewId};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A loaded light field: the views that exist, their grid, and the camera when it is known.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The scene folder.
    pub dir: PathBuf,
    /// The view grid (from `parameters.cfg`, else the smallest square holding every view).
    pub grid: ViewGrid,
    /// One slot per grid position, row-major; `None` where the view is missing.
    pub views: Vec<Option<Raster>>,
    /// The parsed `parameters.cfg`, when present.
    pub params: Option<SceneParameters>,
}

/// The file name of view `index`: `input_CamNNN.png`.
pub fn view_file_name(index: usize) -> String {
    format!("input_Cam{index:03}.png")
}

/// Parses `input_CamNNN.png` / `.exr` into its index.
fn parse_view_name(name: &str) -> Option<usize> {
    let rest = name.strip_prefix("input_Cam")?;
    let (digits, ext) = rest.split_once('.')?;
    let ok_ext = ext.eq_ignore_ascii_case("png") || ext.eq_ignore_ascii_case("exr");
    (ok_ext && digits.len() >= 3 && digits.bytes().all(|b| b.is_ascii_digit())).then(|| digits.parse().ok())?
}

impl Scene {
    /// Loads a scene folder, checking that the central view exists, that every view has the
    /// same size and channels, and that `parameters.cfg` (if any) agrees with the views.
    pub fn load(dir: &Path) -> IoResult<Self> {
        if !dir.is_dir() {
            let problem = if dir.exists() { "not a folder" } else { "scene folder not found" };
            return Err(IoError::new(dir, problem));
        }
        let mut files: BTreeMap<usize, PathBuf> = BTreeMap::new();
        let entries = std::fs::read_dir(dir).map_err(|e| IoError::os(dir, e))?;
        for entry in entries {
            let entry = entry.map_err(|e| IoError::os(dir, e))?;
            let name = entry.file_name().to_string_lossy().into_owned();
            if let Some(index) = parse_view_name(&name)
                && let Some(other) = files.insert(index, entry.path())
            {
                return Err(IoError::new(&other, format!("view {index} is given twice (also as {name})")));
            }
        }
        let Some(&max_index) = files.keys().next_back() else {
            return Err(IoError::new(dir, "no views (input_CamNNN.png or .exr) in the scene folder"));
        };

        let cfg_path = dir.join("parameters.cfg");
        let params = if cfg_path.exists() { Some(SceneParameters::read(&cfg_path)?) } else { None };
        let grid = match &params {
            Some(p) => ViewGrid { rows: p.num_cams_y, cols: p.num_cams_x },
            None => {
                let n = (1..).find(|n| n * n > max_index).unwrap_or(1);
                ViewGrid { rows: n, cols: n }
            }
        };
        if max_index >= grid.len() {
            return Err(IoError::new(
                &files[&max_index],
                format!("view index {max_index} is outside the {}x{} grid of parameters.cfg", grid.rows, grid.cols),
            ));
        }
        let central = grid
            .central()
            .ok_or_else(|| IoError::new(dir, format!("a {}x{} view grid has no central view (needs odd sizes)", grid.rows, grid.cols)))?;
        let central_index = grid.index(central);
        if !files.contains_key(&central_index) {
            return Err(IoError::new(dir, format!("no central view ({})", view_file_name(central_index))));
        }

        let loaded: Vec<(usize, Raster)> = files.par_iter().map(|(&i, path)| read_image(path).map(|r| (i, r))).collect::<IoResult<_>>()?;
        let reference = &loaded.iter().find(|(i, _)| *i == central_index).expect("central view loaded").1;
        let (w, h, ch) = (reference.width, reference.height, reference.channels);
        for (i, r) in &loaded {
            if (r.width, r.height) != (w, h) {
                return Err(IoError::new(&files[i], format!("view is {}x{} but the central view is {w}x{h}", r.width, r.height)));
            }
            if r.channels != ch {
                return Err(IoError::new(&files[i], format!("view has {} channels but the central view has {ch}", r.channels)));
            }
        }
        if let Some(p) = &params
            && (p.image_resolution_x_px, p.image_resolution_y_px) != (w, h)
        {
            return Err(IoError::new(
                &cfg_path,
                format!("says {}x{} pixels but the views are {w}x{h}", p.image_resolution_x_px, p.image_resolution_y_px),
            ));
        }
        let mut views = vec![None; grid.len()];
        for (i, r) in loaded {
            views[i] = Some(r);
        }
        Ok(Self { dir: dir.to_path_buf(), grid, views, params })
    }

    /// Image width in pixels.
    pub fn width(&self) -> usize {
        self.central().width
    }

    /// Image height in pixels.
    pub fn height(&self) -> usize {
        self.central().height
    }

    /// Channels per pixel (1 or 3).
    pub fn channels(&self) -> usize {
        self.central().channels
    }

    /// The central view's position.
    pub fn central_id(&self) -> ViewId {
        self.grid.central().expect("checked at load")
    }

    /// The central view.
    pub fn central(&self) -> &Raster {
        self.view(self.central_id()).expect("checked at load")
    }

    /// The view at `id`, if present.
    pub fn view(&self, id: ViewId) -> Option<&Raster> {
        if id.row >= self.grid.rows || id.col >= self.grid.cols {
            return None;
        }
        self.views[self.grid.index(id)].as_ref()
    }

    /// Every present view, in index order.
    pub fn present_views(&self) -> Vec<ViewId> {
        (0..self.grid.len()).filter(|&i| self.views[i].is_some()).map(|i| self.grid.view(i)).collect()
    }

    /// The present views of the central row (read with no motion between them), left to right.
    pub fn central_row_views(&self) -> Vec<ViewId> {
        let row = self.central_id().row;
        self.present_views().into_iter().filter(|v| v.row == row).collect()
    }

    /// The metric camera, when `parameters.cfg` is present.
    pub fn camera(&self) -> Option<Camera> {
        self.params.as_ref().map(Camera::from_parameters)
    }

    /// `true` when `parameters.cfg` gives a rolling-shutter line time above zero.
    pub fn is_rolling_shutter(&self) -> bool {
        self.params.as_ref().and_then(|p| p.line_time_s).is_some_and(|t| t > 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::parse_view_name;

    #[test]
    fn view_names_follow_the_zero_padded_pattern() {
        assert_eq!(parse_view_name("input_Cam040.png"), Some(40));
        assert_eq!(parse_view_name("input_Cam000.exr"), Some(0));
        assert_eq!(parse_view_name("input_Cam1200.png"), Some(1200));
        assert_eq!(parse_view_name("input_Cam40.png"), None);
        assert_eq!(parse_view_name("input_Cam040.jpg"), None);
        assert_eq!(parse_view_name("gt_disp_lowres.pfm"), None);
    }
}
