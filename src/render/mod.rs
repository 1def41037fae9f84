//! The light-field Gaussian renderer: any view, any band of rows, colour, disparity and opacity.

mod binning;
mod splat;

pub use binning::{PixelBins, bin};
pub use splat::{ALPHA_MAX, RenderOutput, RenderSettings, bins_for_view, render, render_rows};
