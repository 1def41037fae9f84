//! The light-field Gaussian renderer: any view, any band of rows, colour, disparity and opacity;
//! with a rolling-shutter motion, the views as the moving sensor read them.

mod binning;
mod rolling_shutter;
mod splat;

pub use binning::{PixelBins, bin};
pub use rolling_shutter::{RsTiming, StaticShape, ViewWindow, bands, concat_outputs, render_rolling_shutter, row_bands};
pub use splat::{
    ALPHA_MAX, RenderOutput, RenderSettings, SURFACE_HIDING, Splats, bins_for_view, render, render_rows, splat, splat_with_surface,
};
