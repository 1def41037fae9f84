//! `rslf eval --scene DIR --result DIR`.

use crate::eval::evaluate;
use std::path::{Path, PathBuf};

/// Arguments of `rslf eval`.
#[derive(Debug, clap::Args)]
pub struct EvalArgs {
    /// Scene folder with ground truth (gt_disp_lowres.pfm, gt_depth_lowres.pfm, gt_mask.png, ...).
    #[arg(long)]
    pub scene: PathBuf,
    /// Result folder of `rslf train` (disparity.pfm, depth.pfm, central.png, motion.toml).
    #[arg(long)]
    pub result: PathBuf,
    /// Print only; do not write RESULT/metrics.json.
    #[arg(long)]
    pub no_write: bool,
}

/// Evaluates `result` against `scene`, prints the table, and (when `write`) writes
/// `metrics.json` into the result folder.
pub fn report(scene: &Path, result: &Path, write: bool) -> crate::Result<()> {
    let report = evaluate(scene, result)?;
    out!("{report}");
    if write {
        let path = result.join("metrics.json");
        report.write_json(&path)?;
        outln!("wrote {}", path.display());
    }
    Ok(())
}

/// Runs `rslf eval`.
pub fn run(args: EvalArgs) -> crate::Result<()> {
    report(&args.scene, &args.result, !args.no_write)
}
