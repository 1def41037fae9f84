//! Differentiable scene models (burn `Module`s) and their saved form.

mod gaussians;
mod saved;

pub use gaussians::{GaussianSet, Gaussians};
pub use saved::{FORMAT as MODEL_FORMAT, SavedModel};
