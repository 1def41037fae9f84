//! Geometry of the light-field camera (FORMAT conventions), on the host.

mod camera;
mod rigid_motion;
mod rs_projection;

pub use camera::{Camera, ViewGrid, ViewId};
pub use rigid_motion::{Pose, pose_at, readout_interval};
pub use rs_projection::rs_project;
