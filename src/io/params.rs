//! `parameters.cfg`: HCI's INI file of camera parameters, plus rslf's `[rolling_shutter]` section.

use super::atomic::write_atomic;
use super::error::{IoError, IoResult};
use std::collections::BTreeMap;
use std::path::Path;

/// The keys of `parameters.cfg` that rslf uses (HCI names), checked for presence, type and range.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneParameters {
    /// `[intrinsics] focal_length_mm`.
    pub focal_length_mm: f64,
    /// `[intrinsics] image_resolution_x_px`.
    pub image_resolution_x_px: usize,
    /// `[intrinsics] image_resolution_y_px`.
    pub image_resolution_y_px: usize,
    /// `[intrinsics] sensor_size_mm`, the larger sensor side.
    pub sensor_size_mm: f64,
    /// `[extrinsics] num_cams_x`: views per grid row.
    pub num_cams_x: usize,
    /// `[extrinsics] num_cams_y`: views per grid column.
    pub num_cams_y: usize,
    /// `[extrinsics] baseline_mm`: distance between neighbouring views.
    pub baseline_mm: f64,
    /// `[extrinsics] focus_distance_m`: depth of the zero-disparity plane.
    pub focus_distance_m: f64,
    /// `[meta] disp_min`, `disp_max`: the disparity search range, when given.
    pub disparity_range: Option<(f64, f64)>,
    /// `[rolling_shutter] line_time_s`: seconds between two row read-outs; `None` = global shutter.
    pub line_time_s: Option<f64>,
}

/// An INI file as sections of key/value strings, with the line each key came from.
type Ini = BTreeMap<String, BTreeMap<String, (String, usize)>>;

fn parse_ini(text: &str) -> Result<Ini, String> {
    let mut ini = Ini::new();
    let mut section = String::new();
    for (i, raw) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with(';') {
            continue;
        }
        if let Some(rest) = line.strip_prefix('[') {
            let name = rest.strip_suffix(']').ok_or_else(|| format!("line {line_no}: section header `{line}` has no closing `]`"))?;
            section = name.trim().to_string();
            ini.entry(section.clone()).or_default();
            continue;
        }
        let (key, value) = line.split_once('=').ok_or_else(|| format!("line {line_no}: expected `key = value`, found `{line}`"))?;
        let key = key.trim().to_string();
        let entries = ini.entry(section.clone()).or_default();
        if entries.contains_key(&key) {
            return Err(format!("line {line_no}: [{section}] {key} is given twice"));
        }
        entries.insert(key, (value.trim().to_string(), line_no));
    }
    Ok(ini)
}

struct Reader<'a> {
    ini: &'a Ini,
}

impl Reader<'_> {
    fn raw(&self, section: &str, key: &str) -> Option<&(String, usize)> {
        self.ini.get(section).and_then(|s| s.get(key))
    }

    fn float(&self, section: &str, key: &str) -> Result<Option<f64>, String> {
        match self.raw(section, key) {
            None => Ok(None),
            Some((value, line)) => match value.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(Some(v)),
                _ => Err(format!("line {line}: [{section}] {key} = `{value}` is not a number")),
            },
        }
    }

    fn positive(&self, section: &str, key: &str) -> Result<f64, String> {
        let v = self.float(section, key)?.ok_or_else(|| format!("[{section}] {key} is missing"))?;
        if v <= 0.0 {
            return Err(format!("[{section}] {key} = {v} must be positive"));
        }
        Ok(v)
    }

    fn count(&self, section: &str, key: &str) -> Result<usize, String> {
        let v = self.positive(section, key)?;
        if v.fract() != 0.0 || v > 1.0e6 {
            return Err(format!("[{section}] {key} = {v} must be a whole number"));
        }
        Ok(v as usize)
    }
}

impl SceneParameters {
    /// Reads and checks `parameters.cfg`.
    pub fn read(path: &Path) -> IoResult<Self> {
        let text = std::fs::read(path).map_err(|e| IoError::os(path, e))?;
        let text = String::from_utf8(text).map_err(|_| IoError::new(path, "not a text file"))?;
        Self::parse(&text).map_err(|problem| IoError::new(path, problem))
    }

    /// Parses the text of a `parameters.cfg`; the error names the section and key.
    pub fn parse(text: &str) -> Result<Self, String> {
        let ini = parse_ini(text)?;
        let r = Reader { ini: &ini };
        let disparity_range = match (r.float("meta", "disp_min")?, r.float("meta", "disp_max")?) {
            (Some(lo), Some(hi)) if lo < hi => Some((lo, hi)),
            (Some(lo), Some(hi)) => return Err(format!("[meta] disp_min = {lo} is not below disp_max = {hi}")),
            (None, None) => None,
            _ => return Err("[meta] needs both disp_min and disp_max, or neither".into()),
        };
        let line_time_s = match r.raw("rolling_shutter", "line_time_s") {
            None => None,
            Some(_) => {
                let v = r.float("rolling_shutter", "line_time_s")?.unwrap_or(0.0);
                if v < 0.0 {
                    return Err(format!("[rolling_shutter] line_time_s = {v} must not be negative"));
                }
                Some(v)
            }
        };
        Ok(Self {
            focal_length_mm: r.positive("intrinsics", "focal_length_mm")?,
            image_resolution_x_px: r.count("intrinsics", "image_resolution_x_px")?,
            image_resolution_y_px: r.count("intrinsics", "image_resolution_y_px")?,
            sensor_size_mm: r.positive("intrinsics", "sensor_size_mm")?,
            num_cams_x: r.count("extrinsics", "num_cams_x")?,
            num_cams_y: r.count("extrinsics", "num_cams_y")?,
            baseline_mm: r.positive("extrinsics", "baseline_mm")?,
            focus_distance_m: r.positive("extrinsics", "focus_distance_m")?,
            disparity_range,
            line_time_s,
        })
    }

    /// The file's text, in HCI's layout (rslf's `[rolling_shutter]` section when set).
    pub fn to_cfg_string(&self) -> String {
        let mut s = format!(
            "[intrinsics]\nfocal_length_mm = {}\nimage_resolution_x_px = {}\nimage_resolution_y_px = {}\nsensor_size_mm = {}\n\n\
             [extrinsics]\nnum_cams_x = {}\nnum_cams_y = {}\nbaseline_mm = {}\nfocus_distance_m = {}\n",
            self.focal_length_mm,
            self.image_resolution_x_px,
            self.image_resolution_y_px,
            self.sensor_size_mm,
            self.num_cams_x,
            self.num_cams_y,
            self.baseline_mm,
            self.focus_distance_m,
        );
        if let Some((lo, hi)) = self.disparity_range {
            s += &format!("\n[meta]\ndisp_min = {lo}\ndisp_max = {hi}\n");
        }
        if let Some(t) = self.line_time_s {
            s += &format!("\n[rolling_shutter]\nline_time_s = {t:e}\n");
        }
        s
    }

    /// Writes `parameters.cfg`, whole or not at all.
    pub fn write(&self, path: &Path) -> IoResult<()> {
        write_atomic(path, self.to_cfg_string().as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const COTTON_LIKE: &str = "[intrinsics]\nfocal_length_mm = 100.0\nimage_resolution_x_px = 512\n\
        image_resolution_y_px = 512\nsensor_size_mm = 35.0\n\n[extrinsics]\nnum_cams_x = 9\nnum_cams_y = 9\n\
        baseline_mm = 25.0\nfocus_distance_m = 4.25\n\n[meta]\nscene = cotton\ndisp_min = -1.6\ndisp_max = 1.5\n";

    #[test]
    fn reads_hci_keys_and_ignores_the_rest() {
        let p = SceneParameters::parse(COTTON_LIKE).unwrap();
        assert_eq!(p.focal_length_mm, 100.0);
        assert_eq!((p.num_cams_x, p.num_cams_y), (9, 9));
        assert_eq!(p.disparity_range, Some((-1.6, 1.5)));
        assert_eq!(p.line_time_s, None);
    }

    #[test]
    fn round_trips_through_its_own_text() {
        let mut p = SceneParameters::parse(COTTON_LIKE).unwrap();
        p.line_time_s = Some(3.25e-5);
        assert_eq!(SceneParameters::parse(&p.to_cfg_string()).unwrap(), p);
    }

    #[test]
    fn missing_and_non_numeric_keys_are_named() {
        let missing = COTTON_LIKE.replace("baseline_mm = 25.0\n", "");
        assert_eq!(SceneParameters::parse(&missing).unwrap_err(), "[extrinsics] baseline_mm is missing");
        let bad = COTTON_LIKE.replace("focal_length_mm = 100.0", "focal_length_mm = abc");
        let err = SceneParameters::parse(&bad).unwrap_err();
        assert!(err.contains("[intrinsics] focal_length_mm = `abc` is not a number"), "{err}");
        let negative = format!("{COTTON_LIKE}\n[rolling_shutter]\nline_time_s = -1\n");
        assert!(SceneParameters::parse(&negative).unwrap_err().contains("line_time_s"));
    }
}
