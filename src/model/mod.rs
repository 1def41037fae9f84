//! Differentiable scene models (burn `Module`s): the Gaussians, the motion models, and their
//! saved form.

mod gaussians;
pub mod motion;
mod saved;

pub use gaussians::{GaussianSet, Gaussians};
pub use saved::{FORMAT as MODEL_FORMAT, SavedModel};
