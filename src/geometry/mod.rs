//! Geometry of the light-field camera (FORMAT conventions): host versions (nalgebra) for the
//! generator, the evaluation and the checks, tensor versions (burn) for what is differentiated.

mod camera;
mod lift;
mod rigid_motion;
mod rotation;
mod rs_projection;

pub use camera::{Camera, ViewGrid, ViewId};
pub use lift::{TensorCamera, ViewOffset};
pub use rigid_motion::{Pose, pose_at, readout_interval};
pub use rotation::{PoseBatch, compose, rotate, rotate_inverse, rotation_matrices};
pub use rs_projection::rs_project;
