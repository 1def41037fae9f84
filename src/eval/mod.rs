//! Evaluation of a result folder against a scene's ground truth (`rslf eval`).

mod cue_bias;
mod metrics;
mod motion_error;
mod observability;
mod report;
mod texture_error;

pub use cue_bias::{CueBias, CueGroup, cue_bias};
pub use metrics::{
    BADPIX_THRESHOLDS, DepthMetrics, DisparityMetrics, HCI_BORDER_PX, ParameterError, depth_metrics, disparity_metrics, evaluation_region,
    motion_parameter_errors, psnr_db,
};
pub use motion_error::{ImageMotionError, image_motion_error};
pub use observability::{Observability, PARAMETER_NAMES, observability};
pub use report::{DepthReport, EvalReport, MotionReport};
pub use texture_error::{TextureGroup, TextureSplit, texture_error};

/// `rslf eval` compares motions on every 4th ground-truth pixel each way.
pub const MOTION_POINT_STRIDE: usize = 4;

/// The observability analysis linearises on every 8th ground-truth pixel each way.
pub const OBSERVABILITY_POINT_STRIDE: usize = 8;

use crate::geometry::Camera;
use crate::io::{GroundTruth, IoError, IoResult, MotionRecord, Raster, Scene, read_if_present, read_image, read_pfm};
use std::path::Path;

fn sized(path: &Path, r: Option<Raster>, w: usize, h: usize) -> IoResult<Option<Raster>> {
    match r {
        Some(r) if (r.width, r.height) != (w, h) => {
            Err(IoError::new(path, format!("is {}x{} but the scene's views are {w}x{h}", r.width, r.height)))
        }
        other => Ok(other),
    }
}

fn depth_from_disparity(cam: &Camera, disp: &Raster) -> Raster {
    let data = disp.data.iter().map(|&d| cam.disparity_to_depth(d as f64) as f32).collect();
    Raster { data, ..disp.clone() }
}

fn disparity_from_depth(cam: &Camera, depth: &Raster) -> Raster {
    let data = depth.data.iter().map(|&z| cam.depth_to_disparity(z as f64) as f32).collect();
    Raster { data, ..depth.clone() }
}

/// Evaluates the result folder `result` against the ground truth of the scene folder `scene`.
pub fn evaluate(scene_dir: &Path, result: &Path) -> IoResult<EvalReport> {
    let scene = Scene::load(scene_dir)?;
    let (w, h) = (scene.width(), scene.height());
    let gt = GroundTruth::load(scene_dir, w, h)?;
    if !result.is_dir() {
        return Err(IoError::new(result, if result.exists() { "not a folder" } else { "result folder not found" }));
    }
    let disp_path = result.join("disparity.pfm");
    let depth_path = result.join("depth.pfm");
    let central_path = result.join("central.png");
    let motion_path = result.join("motion.toml");
    let est_disp = sized(&disp_path, read_if_present(&disp_path, read_pfm)?, w, h)?;
    let est_depth = sized(&depth_path, read_if_present(&depth_path, read_pfm)?, w, h)?;
    let est_central = sized(&central_path, read_if_present(&central_path, read_image)?, w, h)?;
    let est_motion = read_if_present(&motion_path, MotionRecord::read)?;
    if est_disp.is_none() && est_depth.is_none() && est_central.is_none() && est_motion.is_none() {
        return Err(IoError::new(result, "has none of disparity.pfm, depth.pfm, central.png, motion.toml"));
    }
    if gt.is_empty() {
        return Err(IoError::new(
            scene_dir,
            "has no ground truth (gt_disp_lowres.pfm, gt_depth_lowres.pfm, gt_central.png, gt_motion.toml)",
        ));
    }

    let mut notes = Vec::new();
    let mask = gt.mask.as_deref();
    let disparity = match (&est_disp, &gt.disparity) {
        (Some(e), Some(t)) => Some(disparity_metrics(e, t, &evaluation_region(w, h, mask, HCI_BORDER_PX))),
        (None, Some(_)) => {
            notes.push("no disparity.pfm in the result: disparity not evaluated".into());
            None
        }
        _ => None,
    };

    let camera = scene.camera();
    let est_z = match (est_depth, &est_disp, &camera) {
        (Some(z), _, _) => Some((z, "depth.pfm")),
        (None, Some(d), Some(cam)) => Some((depth_from_disparity(cam, d), "disparity.pfm + parameters.cfg")),
        _ => None,
    };
    let gt_z = match (&gt.depth, &gt.disparity, &camera) {
        (Some(z), _, _) => Some((z.clone(), "gt_depth_lowres.pfm")),
        (None, Some(d), Some(cam)) => Some((depth_from_disparity(cam, d), "gt_disp_lowres.pfm + parameters.cfg")),
        _ => None,
    };
    let depth = match (est_z, &gt_z) {
        (Some((e, es)), Some((t, ts))) => Some(DepthReport {
            metrics: depth_metrics(&e, t, &evaluation_region(w, h, mask, 0)),
            estimate_source: es.into(),
            truth_source: (*ts).into(),
        }),
        (_, None) if camera.is_none() => {
            notes.push("no parameters.cfg in the scene: depth not evaluated (disparity only)".into());
            None
        }
        _ => None,
    };

    let central_psnr_db = match (&est_central, &gt.central) {
        (Some(e), Some(t)) => Some(psnr_db(e, t, &evaluation_region(w, h, mask, 0))),
        (None, Some(_)) => {
            notes.push("no central.png in the result: appearance not evaluated".into());
            None
        }
        _ => None,
    };

    // The motion's image-space error needs the scene's t = 0 points: the true depth, or the
    // true disparity through the camera.
    let motion = match (&est_motion, &gt.motion) {
        (Some(e), Some(t)) => {
            let points = camera.as_ref().zip(gt_z.as_ref());
            match points {
                Some((_, (_, source))) if gt.depth.is_none() => notes.push(format!("motion: the t = 0 points from {source}")),
                None => notes.push("motion: no ground-truth depth or disparity with parameters.cfg, so no image-space error".into()),
                _ => {}
            }
            Some(MotionReport {
                estimated_model: e.model_name().into(),
                true_model: t.model_name().into(),
                parameters: motion_parameter_errors(e, t),
                image: points.and_then(|(cam, (z, _))| image_motion_error(cam, e, t, z, MOTION_POINT_STRIDE)),
                observability: points.and_then(|(cam, (z, _))| observability(cam, t, z, OBSERVABILITY_POINT_STRIDE)),
                texture: points.and_then(|(cam, (z, _))| texture_error(cam, e, t, z, scene.central(), MOTION_POINT_STRIDE)),
                cues: points.and_then(|(cam, (z, _))| {
                    let disparity = gt.disparity.clone().unwrap_or_else(|| disparity_from_depth(cam, z));
                    cue_bias(&scene, cam, t, &disparity, z, MOTION_POINT_STRIDE)
                }),
            })
        }
        (None, Some(_)) => {
            notes.push("no motion.toml in the result: motion not evaluated".into());
            None
        }
        _ => None,
    };

    Ok(EvalReport {
        scene: scene_dir.display().to_string(),
        result: result.display().to_string(),
        disparity,
        depth,
        central_psnr_db,
        motion,
        notes,
    })
}
