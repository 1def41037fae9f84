//! Reading a config file, with errors that name the file, the line, the key and what was expected.

use super::schema::Config;
use std::fmt;
use std::path::{Path, PathBuf};

/// A problem with a config file.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigError {
    /// The config file.
    pub path: PathBuf,
    /// 1-based line of the problem, when known.
    pub line: Option<usize>,
    /// Dotted key at fault (`stage1.iterations`), when known.
    pub key: Option<String>,
    /// What is wrong and what was expected.
    pub message: String,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(key) = &self.key {
            write!(f, ": key `{key}`")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for ConfigError {}

/// The table header (`[stage1]`, `[[loss]]`) in force at byte `offset` of `text`.
fn table_at(text: &str, offset: usize) -> Option<String> {
    text[..offset.min(text.len())].lines().rev().find_map(|l| {
        let l = l.trim();
        let name =
            l.strip_prefix("[[").and_then(|r| r.split("]]").next()).or_else(|| l.strip_prefix('[').and_then(|r| r.split(']').next()))?;
        Some(name.trim().to_string())
    })
}

/// The key assigned on the line holding byte `offset`, if that line is `key = value`.
fn key_at(text: &str, offset: usize) -> Option<String> {
    let start = text[..offset.min(text.len())].rfind('\n').map_or(0, |i| i + 1);
    let line = text[start..].lines().next()?;
    let (key, _) = line.split_once('=')?;
    let key = key.trim().trim_matches('"');
    (!key.is_empty() && !key.starts_with('[')).then(|| key.to_string())
}

impl Config {
    /// Parses config text; `path` is only used to name the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let config: Config = toml::from_str(text).map_err(|e| {
            let span = e.span();
            let line = span.as_ref().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            let key = span.as_ref().and_then(|s| {
                let key = key_at(text, s.start)?;
                Some(match table_at(text, s.start) {
                    Some(table) => format!("{table}.{key}"),
                    None => key,
                })
            });
            // The message of an unknown key already names it; keep ours for type errors.
            let message = e.message().trim().replace('\n', " ");
            let key = if message.starts_with("unknown field") { None } else { key };
            ConfigError { path: path.to_path_buf(), line, key, message }
        })?;
        config.validate().map_err(|(key, message)| ConfigError { path: path.to_path_buf(), line: None, key: Some(key), message })?;
        Ok(config)
    }

    /// Reads and checks a config file.
    pub fn read(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError {
            path: path.to_path_buf(),
            line: None,
            key: None,
            message: crate::io::IoError::os(path, e).problem,
        })?;
        Self::parse(&text, path)
    }

    /// Range checks serde cannot express: `(key, problem)` of the first one that fails.
    fn validate(&self) -> Result<(), (String, String)> {
        let fail = |key: &str, msg: &str| Err((key.to_string(), msg.to_string()));
        if self.stage1.gaussians == 0 {
            return fail("stage1.gaussians", "must be at least 1");
        }
        if self.stage1.views == 0 {
            return fail("stage1.views", "must be at least 1 (the central view)");
        }
        if !(self.stage1.disparity_step > 0.0 && self.stage1.disparity_step.is_finite()) {
            return fail("stage1.disparity_step", "must be a positive number of pixels");
        }
        if let Some([lo, hi]) = self.stage1.disparity_range {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return fail("stage1.disparity_range", "must be [min, max] with min < max");
            }
            if (hi - lo) / self.stage1.disparity_step > 100_000.0 {
                return fail("stage1.disparity_range", "has more than 100000 candidates at this disparity_step");
            }
        }
        for (key, lr) in [
            ("stage1.lr_position", self.stage1.lr_position),
            ("stage1.lr_disparity", self.stage1.lr_disparity),
            ("stage1.lr_size", self.stage1.lr_size),
            ("stage1.lr_colour", self.stage1.lr_colour),
        ] {
            if !(lr >= 0.0 && lr.is_finite()) {
                return fail(key, "must be a finite number >= 0");
            }
        }
        if !(self.stage1.lr_disparity_final_share > 0.0 && self.stage1.lr_disparity_final_share <= 1.0) {
            return fail("stage1.lr_disparity_final_share", "must be in (0, 1] (1: a constant rate)");
        }
        if !(self.stage1.adam_epsilon > 0.0 && self.stage1.adam_epsilon.is_finite()) {
            return fail("stage1.adam_epsilon", "must be a positive number");
        }
        if !(1..=256).contains(&self.render.max_per_pixel) {
            return fail("render.max_per_pixel", "must be 1 to 256");
        }
        if !(self.render.cutoff_sigma > 0.0 && self.render.cutoff_sigma <= 10.0) {
            return fail("render.cutoff_sigma", "must be in (0, 10]");
        }
        if self.stage1.band_height == 0 {
            return fail("stage1.band_height", "must be at least 1 row");
        }
        if !(self.stage2.cue_outlier_bound == 0.0 || self.stage2.cue_outlier_bound >= 1.0 && self.stage2.cue_outlier_bound.is_finite()) {
            return fail("stage2.cue_outlier_bound", "must be 0 (no cue left out) or at least 1 (times the median)");
        }
        if !(self.stage2.cue_lever_bound >= 0.0 && self.stage2.cue_lever_bound.is_finite()) {
            return fail("stage2.cue_lever_bound", "must be 0 (no cue left out) or a positive number of grid steps");
        }
        if self.stage2.band_height == 0 {
            return fail("stage2.band_height", "must be at least 1 row");
        }
        if self.stage2.mask_disocclusions && !self.stage2.mask_motion_residual && self.stage2.refine_gaussians <= 0.0 {
            return fail(
                "stage2.mask_motion_residual",
                "false masks only the Gaussians' residual, and with refine_gaussians = 0 there is none: set mask_disocclusions = false to compare every pixel",
            );
        }
        if self.stage2.disocclusion_margin > 32 {
            return fail("stage2.disocclusion_margin", "must be at most 32 pixels");
        }
        if !(self.stage2.cue_weight >= 0.0 && self.stage2.cue_weight.is_finite()) {
            return fail("stage2.cue_weight", "must be a finite number >= 0");
        }
        if !(0.0..=1.0).contains(&self.stage2.min_cue_support) {
            return fail("stage2.min_cue_support", "must be between 0 and 1");
        }
        if !(0.0..=1.0).contains(&self.stage2.min_axial_support) {
            return fail("stage2.min_axial_support", "must be between 0 and 1");
        }
        if !(self.stage2.min_cue_signal >= 0.0 && self.stage2.min_cue_signal.is_finite()) {
            return fail("stage2.min_cue_signal", "must be a finite number >= 0");
        }
        if !(self.stage2.newton_rest_tolerance >= 0.0 && self.stage2.newton_rest_tolerance.is_finite()) {
            return fail(
                "stage2.newton_rest_tolerance",
                "must be 0 (held directions left as they are) or a positive share of the objective",
            );
        }
        if self.motion.model.is_empty() {
            return fail("motion.model", "must name a motion model");
        }
        if self.motion.segments == 0 {
            return fail("motion.segments", "must be at least 1");
        }
        for (i, term) in self.loss.iter().enumerate() {
            if term.kind.is_empty() {
                return Err((format!("loss[{i}].kind"), "must name a loss term".into()));
            }
            if !term.weight.is_finite() || term.weight < 0.0 {
                return Err((format!("loss[{i}].weight"), "must be a finite number >= 0".into()));
            }
            if let Some(stages) = &term.stages {
                // One or two stages out of {1, 2}, none twice.
                let valid = matches!(stages.len(), 1 | 2) && stages.iter().all(|s| matches!(s, 1 | 2)) && stages.first() != stages.get(1);
                if !valid {
                    return Err((format!("loss[{i}].stages"), "must list stage 1, stage 2 or both, e.g. [2]".into()));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Config, ConfigError> {
        Config::parse(text, Path::new("run.toml"))
    }

    #[test]
    fn defaults_fill_what_a_config_leaves_out() {
        let c = parse("scene = \"scenes/a\"\n").unwrap();
        assert_eq!(c.scene.as_deref(), Some(Path::new("scenes/a")));
        assert_eq!(c.stage1.gaussians, 20_000);
        assert_eq!(c.motion.model, "constant_velocity");
        let kinds: Vec<&str> = c.loss.iter().map(|l| l.kind.as_str()).collect();
        assert_eq!(kinds, vec!["l1", "smoothness", "motion_prior"]);
    }

    #[test]
    fn a_loss_term_counts_in_the_stages_it_lists_and_in_every_stage_without_a_list() {
        let c = parse("[[loss]]\nkind = \"l1\"\n\n[[loss]]\nkind = \"dssim\"\nweight = 0.2\nstages = [2]\n\n[[loss]]\nkind = \"smoothness\"\nstages = [1, 2]\n").unwrap();
        let kinds = |stage| c.losses_in(stage).into_iter().map(|l| l.kind).collect::<Vec<_>>();
        assert_eq!(kinds(1), ["l1", "smoothness"]);
        assert_eq!(kinds(2), ["l1", "dssim", "smoothness"]);
    }

    #[test]
    fn unknown_keys_are_named_with_file_and_line() {
        let err = parse("scene = \"a\"\n\n[stage1]\niterations = 10\nlearning_rat = 0.1\n").unwrap_err();
        let text = err.to_string();
        assert!(text.starts_with("run.toml:5: "), "{text}");
        assert!(text.contains("unknown field `learning_rat`"), "{text}");
        assert!(text.contains("expected one of"), "{text}");
    }

    #[test]
    fn wrong_types_name_the_dotted_key_and_the_expected_type() {
        let err = parse("[stage2]\niterations = \"many\"\n").unwrap_err();
        assert_eq!(err.line, Some(2));
        assert_eq!(err.key.as_deref(), Some("stage2.iterations"));
        assert!(err.message.contains("expected"), "{}", err.message);
        let err = parse("device = \"tpu\"\n").unwrap_err();
        assert!(err.to_string().contains("device"), "{err}");
    }

    #[test]
    fn ranges_are_checked() {
        let err = parse("[[loss]]\nkind = \"l1\"\nweight = -1.0\n").unwrap_err();
        assert_eq!(err.key.as_deref(), Some("loss[0].weight"));
        for bad in ["[]", "[3]", "[2, 2]", "[1, 2, 1]"] {
            let err = parse(&format!("[[loss]]\nkind = \"l1\"\nstages = {bad}\n")).unwrap_err();
            assert_eq!(err.key.as_deref(), Some("loss[0].stages"), "{bad}");
        }
        let err = parse("[stage2]\nmask_motion_residual = false\nrefine_gaussians = 0.0\n").unwrap_err();
        assert_eq!(err.key.as_deref(), Some("stage2.mask_motion_residual"));
        assert!(parse("[stage2]\nmask_motion_residual = false\n").is_ok(), "the Gaussians' residual is masked");
        assert!(parse("[stage2]\nmask_motion_residual = false\nrefine_gaussians = 0.0\nmask_disocclusions = false\n").is_ok());
        for bad in ["0.0", "1.5", "nan"] {
            let err = parse(&format!("[stage1]\nlr_disparity_final_share = {bad}\n")).unwrap_err();
            assert_eq!(err.key.as_deref(), Some("stage1.lr_disparity_final_share"), "{bad}");
        }
        assert!(parse("[stage1]\nlr_disparity_final_share = 1.0\n").is_ok(), "a constant rate");
        let err = parse("[stage2]\ndisocclusion_margin = 1000\n").unwrap_err();
        assert_eq!(err.key.as_deref(), Some("stage2.disocclusion_margin"));
        let err = parse("[stage2]\ncue_weight = -0.5\n").unwrap_err();
        assert_eq!(err.key.as_deref(), Some("stage2.cue_weight"));
        let err = parse("[stage2]\nmin_cue_support = 1.5\n").unwrap_err();
        assert_eq!(err.key.as_deref(), Some("stage2.min_cue_support"));
        for bad in ["1.5", "-0.1", "nan"] {
            let err = parse(&format!("[stage2]\nmin_axial_support = {bad}\n")).unwrap_err();
            assert_eq!(err.key.as_deref(), Some("stage2.min_axial_support"), "{bad}");
        }
        let err = parse("[stage2]\nmin_cue_signal = -1.0\n").unwrap_err();
        assert_eq!(err.key.as_deref(), Some("stage2.min_cue_signal"));
        for bad in ["0.5", "-1.0", "inf"] {
            let err = parse(&format!("[stage2]\ncue_outlier_bound = {bad}\n")).unwrap_err();
            assert_eq!(err.key.as_deref(), Some("stage2.cue_outlier_bound"), "{bad}");
        }
        assert_eq!(parse("[stage2]\ncue_outlier_bound = 0.0\n").unwrap().stage2.cue_outlier_bound, 0.0);
        for bad in ["-1.0", "nan", "inf"] {
            let err = parse(&format!("[stage2]\ncue_lever_bound = {bad}\n")).unwrap_err();
            assert_eq!(err.key.as_deref(), Some("stage2.cue_lever_bound"), "{bad}");
        }
        assert_eq!(parse("[stage2]\ncue_lever_bound = 0.0\n").unwrap().stage2.cue_lever_bound, 0.0);
        for bad in ["-1e-3", "nan", "inf"] {
            let err = parse(&format!("[stage2]\nnewton_rest_tolerance = {bad}\n")).unwrap_err();
            assert_eq!(err.key.as_deref(), Some("stage2.newton_rest_tolerance"), "{bad}");
        }
        assert_eq!(parse("[stage2]\nnewton_rest_tolerance = 0.0\n").expect("0 turns the move off").stage2.newton_rest_tolerance, 0.0);
    }
}
