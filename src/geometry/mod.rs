//! Geometry of the light-field camera (FORMAT conventions), on the host.

mod camera;

pub use camera::{Camera, ViewGrid, ViewId};
