//! Scene description files (TOML): camera, render quality, motion and objects of one synthetic
//! rolling-shutter light field.

use super::shapes::Shape;
use super::texture::{Rgb, Texture};
use crate::io::{IoError, IoResult, MotionRecord, SceneParameters};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The capture: an HCI-like 9x9 plenoptic camera with a rolling shutter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CameraSettings {
    /// Focal length, mm.
    pub focal_length_mm: f64,
    /// Larger sensor side, mm.
    pub sensor_size_mm: f64,
    /// Distance between neighbouring views, mm.
    pub baseline_mm: f64,
    /// Depth of the zero-disparity plane, m.
    pub focus_distance_m: f64,
    /// Views per side of the square grid (odd).
    pub num_cams: usize,
    /// Image size `[W, H]`, pixels.
    pub size: [usize; 2],
    /// Time from the first row's read-out to the last's, seconds (`line_time_s = this / (H - 1)`).
    pub readout_time_s: f64,
}

impl Default for CameraSettings {
    fn default() -> Self {
        Self {
            focal_length_mm: 100.0,
            sensor_size_mm: 35.0,
            baseline_mm: 25.0,
            focus_distance_m: 4.5,
            num_cams: 9,
            size: [512, 512],
            readout_time_s: 0.03,
        }
    }
}

impl CameraSettings {
    /// The `parameters.cfg` of this capture, with its disparity search range.
    pub fn parameters(&self, disparity_range: Option<(f64, f64)>) -> SceneParameters {
        SceneParameters {
            focal_length_mm: self.focal_length_mm,
            image_resolution_x_px: self.size[0],
            image_resolution_y_px: self.size[1],
            sensor_size_mm: self.sensor_size_mm,
            num_cams_x: self.num_cams,
            num_cams_y: self.num_cams,
            baseline_mm: self.baseline_mm,
            focus_distance_m: self.focus_distance_m,
            disparity_range,
            line_time_s: Some(self.readout_time_s / (self.size[1].max(2) - 1) as f64),
        }
    }
}

/// The most rays per pixel side a description may ask for: 32 x 32 renders 28 times the rays of
/// the default 6 x 6. At 12 x 12 the still checkerboard's cues hold half the alias bias they
/// hold at 6 x 6 (docs/results.md).
pub const MAX_SUPERSAMPLING: usize = 32;

/// Rendering quality.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    /// Samples per pixel side: `n x n` rays per pixel, averaged as a sensor integrates over its
    /// pixel. 6 by default: with 2 x 2 a sharp edge moves in half-pixel steps and aliases
    /// differently in every view, a bias the motion's cues take up (docs/results.md).
    pub supersampling: usize,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self { supersampling: 6 }
    }
}

/// One object: a shape, where it is (t = 0, central camera frame), and its texture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDescription {
    /// The shape, in its own frame.
    pub shape: Shape,
    /// Position of the shape's origin, metres (X right, Y down, Z forward).
    pub position: [f64; 3],
    /// Rotation of the shape, degrees about X, then Y, then Z.
    #[serde(default)]
    pub rotation_deg: [f64; 3],
    /// Its texture (in the shape's frame).
    pub texture: Texture,
}

/// A whole synthetic scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDescription {
    /// Name of the scene.
    pub name: String,
    /// The capture.
    #[serde(default)]
    pub camera: CameraSettings,
    /// Render quality.
    #[serde(default)]
    pub render: RenderSettings,
    /// The motion during read-out, in `gt_motion.toml`'s schema; none = static.
    #[serde(default)]
    pub motion: Option<toml::Table>,
    /// Colour where a ray meets nothing.
    #[serde(default = "grey")]
    pub background: Rgb,
    /// The objects (`[[object]]` tables).
    #[serde(rename = "object")]
    pub objects: Vec<ObjectDescription>,
}

fn grey() -> Rgb {
    [0.5; 3]
}

/// How many `base` descriptions one file may stand on, one on another (more is taken for a cycle).
const MAX_BASES: usize = 8;

/// The TOML table of a description's text; a syntax error names the line.
fn parse_table(text: &str, path: &Path) -> IoResult<toml::Table> {
    text.parse::<toml::Table>().map_err(|e| {
        let line = e.span().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        let at = line.map_or(String::new(), |l| format!("line {l}: "));
        IoError::new(path, format!("{at}{}", e.message().trim().replace('\n', " ")))
    })
}

/// `table` (read from `path`) over its `base` description, and that over its own, `depth` bases
/// deep so far (see [`SceneDescription::read`]).
fn with_bases(mut table: toml::Table, path: &Path, depth: usize) -> IoResult<toml::Table> {
    let Some(base) = table.remove("base") else { return Ok(table) };
    let toml::Value::String(base) = base else {
        return Err(IoError::new(path, "`base` must be the path of another scene description, relative to this file"));
    };
    if depth >= MAX_BASES {
        return Err(IoError::new(path, format!("more than {MAX_BASES} `base` descriptions, one on another: a cycle?")));
    }
    let base_path = path.parent().unwrap_or(Path::new(".")).join(base);
    let text = std::fs::read_to_string(&base_path).map_err(|e| IoError::os(&base_path, e))?;
    let mut merged = with_bases(parse_table(&text, &base_path)?, &base_path, depth + 1)?;
    for (key, value) in table {
        match (merged.get_mut(&key), value) {
            (Some(toml::Value::Table(into)), toml::Value::Table(over)) if key == "camera" || key == "render" => into.extend(over),
            (_, value) => {
                merged.insert(key, value);
            }
        }
    }
    Ok(merged)
}

impl SceneDescription {
    /// Parses and checks a description; `path` names the file in errors.
    pub fn parse(text: &str, path: &Path) -> IoResult<Self> {
        let desc: Self = toml::from_str(text).map_err(|e| {
            let line = e.span().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            let at = line.map_or(String::new(), |l| format!("line {l}: "));
            IoError::new(path, format!("{at}{}", e.message().trim().replace('\n', " ")))
        })?;
        desc.validate().map_err(|p| IoError::new(path, p))?;
        Ok(desc)
    }

    /// Reads a description file. A file with `base = "other.toml"` (a path relative to the
    /// file's folder) starts from that description: its `[camera]` and `[render]` keys override
    /// the base's one by one, and every other key (`name`, `[motion]`, `background`, the
    /// `[[object]]` list) replaces the base's whole.
    pub fn read(path: &Path) -> IoResult<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| IoError::os(path, e))?;
        let table = parse_table(&text, path)?;
        if !table.contains_key("base") {
            return Self::parse(&text, path);
        }
        let merged = with_bases(table, path, 0)?;
        let desc = Self::deserialize(merged).map_err(|e| IoError::new(path, e.message().trim().replace('\n', " ")))?;
        desc.validate().map_err(|p| IoError::new(path, p))?;
        Ok(desc)
    }

    /// The motion; zero when none is given.
    pub fn motion(&self) -> Result<MotionRecord, String> {
        match &self.motion {
            None => Ok(MotionRecord::zero()),
            Some(table) => {
                let text = toml::to_string(table).map_err(|e| e.to_string())?;
                MotionRecord::parse(&text).map_err(|e| format!("[motion]: {e}"))
            }
        }
    }

    fn validate(&self) -> Result<(), String> {
        let c = &self.camera;
        if c.num_cams.is_multiple_of(2) || c.num_cams == 0 {
            return Err(format!("[camera] num_cams = {} must be odd", c.num_cams));
        }
        if c.size[0] < 8 || c.size[1] < 8 || c.size[0] > 8192 || c.size[1] > 8192 {
            return Err(format!("[camera] size = {:?} must be 8 to 8192 pixels a side", c.size));
        }
        for (name, v) in [
            ("focal_length_mm", c.focal_length_mm),
            ("sensor_size_mm", c.sensor_size_mm),
            ("baseline_mm", c.baseline_mm),
            ("focus_distance_m", c.focus_distance_m),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(format!("[camera] {name} must be positive"));
            }
        }
        if !(c.readout_time_s >= 0.0 && c.readout_time_s.is_finite()) {
            return Err("[camera] readout_time_s must not be negative".into());
        }
        if !(1..=MAX_SUPERSAMPLING).contains(&self.render.supersampling) {
            return Err(format!("[render] supersampling must be 1 to {MAX_SUPERSAMPLING}"));
        }
        if self.objects.is_empty() {
            return Err("no [[object]]: a scene needs at least one".into());
        }
        for (i, o) in self.objects.iter().enumerate() {
            o.shape.validate().and_then(|_| o.texture.validate()).map_err(|e| format!("object {}: {e}", i + 1))?;
        }
        self.motion().map(|_| ())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn supersampling_is_taken_from_one_to_its_bound_and_refused_outside() {
        let with = |n: usize| {
            let text = format!(
                "name = \"s\"\n[render]\nsupersampling = {n}\n[[object]]\nshape = {{ kind = \"rectangle\", size = [1.0, 1.0] }}\n\
                 position = [0.0, 0.0, 3.0]\ntexture = {{ kind = \"checker\", size = 0.1, colors = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]] }}\n"
            );
            SceneDescription::parse(&text, Path::new("s.toml"))
        };
        for n in [1, 6, 12, MAX_SUPERSAMPLING] {
            assert_eq!(with(n).unwrap().render.supersampling, n);
        }
        for n in [0, MAX_SUPERSAMPLING + 1] {
            let err = with(n).unwrap_err().to_string();
            assert!(err.contains("s.toml") && err.contains(&format!("supersampling must be 1 to {MAX_SUPERSAMPLING}")), "{err}");
        }
    }
}
