//! # rslf
//!
//! A differentiable render-and-compare framework whose flagship model recovers dense depth and
//! camera motion from a single light field captured with a rolling-shutter sensor (McGriff et
//! al., "Dense Scene Reconstruction from Light-Field Images Affected by Rolling Shutter",
//! WACV 2025).
//!
//! Layers, bottom to top: [`io`] (files), [`geometry`] (the camera model), [`config`] (run
//! settings), [`pipeline`] (the RSLF composition), [`eval`] (metrics), [`cli`] (the `rslf`
//! command).

pub mod cli;
pub mod config;
pub mod device;
pub mod error;
pub mod eval;
pub mod geometry;
pub mod io;
pub mod loss;
pub mod model;
pub mod pipeline;
pub mod progress;
pub mod random;
pub mod render;
pub mod synth;

pub use error::{Error, Result};
