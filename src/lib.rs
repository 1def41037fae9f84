//! # rslf
//!
//! A differentiable render-and-compare framework whose flagship model recovers dense depth and
//! camera motion from a single light field captured with a rolling-shutter sensor (McGriff et
//! al., "Dense Scene Reconstruction from Light-Field Images Affected by Rolling Shutter",
//! WACV 2025).
//!
//! Layers, bottom to top: [`io`] (files), [`geometry`] (the camera model, host and tensor
//! versions), [`model`] (the Gaussians and the motion models, as burn modules and tensor
//! programs), [`render`] (the differentiable light-field renderer), [`loss`] (loss terms and
//! their registry), [`optim`] (generic optimisation stages), [`pipeline`] (the RSLF
//! composition of those pieces), [`eval`] (metrics), [`cli`] (the `rslf` command). Beside them:
//! [`config`] (run settings), [`synth`] (the scene generator), [`device`] (the backend).
//!
//! `docs/extending.md` shows how to add a loss term, a motion model or a stage from outside the
//! crate; `examples/` holds one program for each.

#![warn(missing_docs)]

/// `print!` for what rslf says on standard output; a reader that has gone ends the program
/// quietly where `print!` would panic (`output::write_out`). Defined before the modules so
/// that every one of them can use it.
macro_rules! out {
    ($($arg:tt)*) => { $crate::output::write_out(format_args!($($arg)*)) };
}

/// `out!` with a newline, as `println!`.
macro_rules! outln {
    () => { out!("\n") };
    ($($arg:tt)*) => { out!("{}\n", format_args!($($arg)*)) };
}

pub mod cli;
pub mod config;
pub mod device;
pub mod error;
pub mod eval;
pub mod geometry;
pub mod io;
pub mod loss;
pub mod model;
pub mod optim;
mod output;
pub mod pipeline;
pub mod progress;
pub mod random;
pub mod render;
pub mod synth;

pub use error::{Error, Result};
