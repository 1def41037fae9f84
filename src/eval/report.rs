//! The evaluation report: what `rslf eval` prints and writes as `metrics.json`.

use super::cue_bias::{CueBias, CueGroup};
use super::metrics::{DepthMetrics, DisparityMetrics, ParameterError};
use super::motion_error::ImageMotionError;
use super::observability::Observability;
use super::texture_error::{TextureGroup, TextureSplit};
use crate::io::{IoError, IoResult, write_atomic};
use serde::Serialize;
use std::fmt;
use std::path::Path;

/// Depth metrics and where the two depth maps came from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DepthReport {
    /// The metrics.
    #[serde(flatten)]
    pub metrics: DepthMetrics,
    /// File of the estimate (`depth.pfm`, or `disparity.pfm` converted with the camera).
    pub estimate_source: String,
    /// File of the truth (`gt_depth_lowres.pfm`, or `gt_disp_lowres.pfm` converted).
    pub truth_source: String,
}

/// Motion errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MotionReport {
    /// The estimated model.
    pub estimated_model: String,
    /// The true model.
    pub true_model: String,
    /// Errors per parameter group, when both use the same model.
    pub parameters: Option<Vec<ParameterError>>,
    /// The image-space error, when the scene has a camera and ground-truth depth.
    pub image: Option<ImageMotionError>,
    /// How strongly the scene's cue observes each direction of constant-velocity motion, when
    /// the scene has a camera and ground-truth depth.
    pub observability: Option<Observability>,
    /// The image-space error split by the central view's texture around each point (where it
    /// runs one way, the component along it is what the views cannot show).
    pub texture: Option<TextureSplit>,
    /// The cues stage 2's check uses, measured from the scene's views and the true disparity,
    /// against those the true motion predicts, when the scene has a camera and ground-truth
    /// depth.
    pub cues: Option<CueBias>,
}

/// Everything `rslf eval` measured. Non-finite numbers are written as `null`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EvalReport {
    /// The scene folder.
    pub scene: String,
    /// The result folder.
    pub result: String,
    /// Disparity metrics (HCI, 15-pixel border left out), when both maps exist.
    pub disparity: Option<DisparityMetrics>,
    /// Depth metrics (the paper's), when both depths exist or can be derived.
    pub depth: Option<DepthReport>,
    /// PSNR (dB) of `central.png` against `gt_central.png`.
    pub central_psnr_db: Option<f64>,
    /// Motion errors, when both motion files exist.
    pub motion: Option<MotionReport>,
    /// What could not be evaluated, and why.
    pub notes: Vec<String>,
}

fn num(v: f64, digits: usize) -> String {
    if v.is_finite() { format!("{v:.digits$}") } else { format!("{v}") }
}

impl fmt::Display for EvalReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "scene   {}", self.scene)?;
        writeln!(f, "result  {}", self.result)?;
        if let Some(d) = &self.disparity {
            let bad: Vec<String> = d.badpix_percent.iter().map(|(t, p)| format!("BadPix({t}) {}%", num(*p, 2))).collect();
            writeln!(f, "disparity  MSE x100 {}  {}  [{} px]", num(d.mse_x100, 4), bad.join("  "), d.pixels)?;
            if d.non_finite > 0 {
                writeln!(f, "           {} estimates are not finite (counted as bad)", d.non_finite)?;
            }
        }
        if let Some(d) = &self.depth {
            let m = &d.metrics;
            writeln!(
                f,
                "depth      abs diff {} m  RMSE {} m  delta<1.25 {}  [{} px; {} vs {}]",
                num(m.abs_diff_m, 4),
                num(m.rmse_m, 4),
                num(m.delta_1_25, 4),
                m.pixels,
                d.estimate_source,
                d.truth_source
            )?;
        }
        if let Some(p) = self.central_psnr_db {
            writeln!(f, "central    PSNR {} dB", num(p, 2))?;
        }
        if let Some(m) = &self.motion {
            if let Some(i) = &m.image {
                let views: Vec<String> = i.per_view_px.iter().map(|(v, e)| format!("{v}: {}", num(*e, 3))).collect();
                writeln!(
                    f,
                    "motion     image-space RMS error {} px (true RS shift {} px, {} of it) over {} points; per view {}",
                    num(i.rms_error_px, 3),
                    num(i.rms_true_shift_px, 3),
                    if i.rms_true_shift_px > 0.0 {
                        format!("{:.1}%", 100.0 * i.rms_error_px / i.rms_true_shift_px)
                    } else {
                        "n/a".to_string()
                    },
                    i.points,
                    views.join(", ")
                )?;
            }
            match &m.parameters {
                Some(groups) => {
                    for g in groups {
                        let rel = g.relative.map_or("n/a (true value is zero)".to_string(), |r| format!("{}%", num(100.0 * r, 2)));
                        writeln!(f, "motion     {:<13} |error| {:.4e}  relative {rel}", g.name, g.absolute)?;
                    }
                }
                None => writeln!(f, "motion     estimated `{}` vs true `{}`: parameters not comparable", m.estimated_model, m.true_model)?,
            }
            if let Some(o) = &m.observability {
                let per: Vec<String> = o.per_parameter.iter().map(|(n, r)| format!("{n} {}", num(*r, 4))).collect();
                writeln!(f, "motion     observability, px of cue per px of image-space effect: {}", per.join("  "))?;
                let dirs: Vec<String> =
                    o.directions.iter().take(3).map(|(r, d)| format!("{} ({})", num(*r, 4), Observability::describe(d))).collect();
                writeln!(f, "motion     weakest directions: {}", dirs.join(", "))?;
            }
            if let Some(t) = &m.texture {
                let group = |g: &TextureGroup| format!("{:.1} %", 100.0 * g.share);
                let error = |g: &TextureGroup| if g.share > 0.0 { format!("{} px", num(g.rms_error_px, 3)) } else { "none".to_string() };
                let one_way = if t.one_way.share > 0.0 {
                    format!("{} ({} px along it, {} px across)", error(&t.one_way), num(t.along_px, 3), num(t.across_px, 3))
                } else {
                    error(&t.one_way)
                };
                writeln!(
                    f,
                    "motion     image-space error by the central view's texture: runs one way {}: {one_way}; both ways {}: {}; flat {}: {}",
                    group(&t.one_way),
                    group(&t.both_ways),
                    error(&t.both_ways),
                    group(&t.flat),
                    error(&t.flat)
                )?;
            }
            if let Some(c) = &m.cues {
                let group = |name: &str, g: &CueGroup| {
                    let share = match (g.truth_share, g.truth_share_se) {
                        (Some(s), Some(e)) => format!(", bear out {} (± {}) of the true motion's", num(s, 3), num(e, 3)),
                        _ => String::new(),
                    };
                    let alone = g.implied_error_px.map_or(String::new(), |e| format!(", alone {} px off", num(e, 3)));
                    format!("{name} {}{share}, RMS miss {} px{alone}", g.cues, num(g.rms_miss_px, 4))
                };
                let groups: Vec<String> =
                    [("textured both ways (the check's)", &c.both_ways), ("edges and stripes", &c.one_way), ("all (the fit's)", &c.all)]
                        .iter()
                        .filter_map(|(name, g)| Some(group(name, g.as_ref()?)))
                        .collect();
                writeln!(
                    f,
                    "motion     measured cues in the corners, tracked from the true disparity, against the true motion's (alone: a least-squares fit of them about a constant-velocity truth, image-space): {}",
                    groups.join("; ")
                )?;
            }
        }
        for note in &self.notes {
            writeln!(f, "note: {note}")?;
        }
        Ok(())
    }
}

impl EvalReport {
    /// Writes the report as pretty JSON (non-finite numbers as `null`), whole or not at all.
    pub fn write_json(&self, path: &Path) -> IoResult<()> {
        let json = serde_json::to_string_pretty(self).map_err(|e| IoError::new(path, e.to_string()))?;
        write_atomic(path, json.as_bytes())
    }
}
