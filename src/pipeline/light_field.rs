//! Rendering a saved model's whole light field: every view of its grid, either as the scene was
//! at t = 0 (the rolling shutter compensated) or as the camera captured it.

use super::{colour_raster, params_tensor, static_shape};
use crate::config::MotionConfig;
use crate::geometry::{ViewGrid, ViewId, readout_interval};
use crate::io::{MotionRecord, Raster};
use crate::model::SavedModel;
use crate::model::motion::{MotionModel, MotionRegistry, MotionSetup};
use crate::render::{RenderSettings, RsTiming, ViewWindow, render_rolling_shutter, render_rows};
use burn::tensor::Device;

/// Fixed-point iterations of the per-Gaussian read-out time when rendering as captured.
const CAPTURE_TIMING_ITERATIONS: usize = 3;

/// When the rendered light field is seen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Moment {
    /// The scene at t = 0, every row at once: a global-shutter light field.
    T0,
    /// As the camera read it: each row at its read-out time under the estimated motion.
    Capture,
}

/// The motion model that expresses `record`, from `registry`, and its parameter vector.
pub fn motion_of_record(
    record: &MotionRecord,
    registry: &MotionRegistry,
    setup: &MotionSetup,
) -> crate::Result<(Box<dyn MotionModel>, Vec<f64>)> {
    let segments = match record {
        MotionRecord::PiecewiseConstant { omega_rad_s, .. } => omega_rad_s.len(),
        _ => 1,
    };
    let config = MotionConfig { model: record.model_name().to_string(), segments };
    let model = registry.build(&config, setup).map_err(|e| crate::Error::Usage(e.to_string()))?;
    let params = model
        .parameters_of(record)
        .ok_or_else(|| crate::Error::Usage(format!("motion model `{}` cannot express its own record", model.name())))?;
    Ok((model, params))
}

/// Renders every view of `saved`'s grid at `moment`, in grid order (`input_CamNNN` order).
/// Without a motion both moments are the same: the plain light-field render.
pub fn render_light_field(
    saved: &SavedModel,
    moment: Moment,
    settings: &RenderSettings,
    device: &Device,
    mut progress: impl FnMut(usize, usize),
) -> crate::Result<Vec<Raster>> {
    let [w, h] = saved.size;
    let grid = ViewGrid { rows: saved.grid[0], cols: saved.grid[1] };
    let g = saved.gaussians.to_module(device);
    let c = saved.gaussians.channels;
    let motion = match (saved.motion_record(), saved.camera()) {
        (Some(record), Some(camera)) => {
            let setup = MotionSetup { readout: readout_interval(camera.height, camera.line_time_s) };
            let (model, params) = motion_of_record(&record, &MotionRegistry::default(), &setup)?;
            let shape = static_shape(&g, &camera, model.as_ref(), &params, device);
            Some((model, params, shape))
        }
        (Some(_), None) => return Err(crate::Error::Usage("the model has a motion but no camera parameters".into())),
        (None, _) => None,
    };
    let views: Vec<ViewId> = (0..grid.len()).map(|i| grid.view(i)).collect();
    let mut out = Vec::with_capacity(views.len());
    for (i, &view) in views.iter().enumerate() {
        let (dx, dy) = grid.offset(view);
        let offset = (dx as f32, dy as f32);
        let rendered = match &motion {
            None => render_rows(&g, offset, w, 0..h, settings, device),
            Some((model, params, shape)) => {
                let p = params_tensor(params, device);
                match moment {
                    Moment::T0 => {
                        let splats = shape.splats_at_time(model.as_ref(), p, offset, 0.0);
                        crate::render::splat(&splats, &splats.bins(w, 0..h, settings), device)
                    }
                    Moment::Capture => {
                        let timing = RsTiming::PerGaussian(CAPTURE_TIMING_ITERATIONS);
                        let window = ViewWindow { offset, width: w, rows: 0..h };
                        render_rolling_shutter(shape, model.as_ref(), p, window, timing, settings, device)
                    }
                }
            }
        };
        let mut image = colour_raster(rendered.colour, w, h, c);
        image.data.iter_mut().for_each(|x| *x = x.clamp(0.0, 1.0));
        out.push(image);
        progress(i + 1, views.len());
    }
    Ok(out)
}
