//! `rslf generate`: a ray-traced synthetic rolling-shutter light-field generator with ground
//! truth (the paper's RSLF+ contribution). It uses only `geometry` and `io`, never the
//! renderer of the model, so that the two can check each other.

mod builtin;
mod description;
mod render;
mod scene_folder;
mod shapes;
mod suite;
mod texture;
mod truth;
mod world;

pub use builtin::{BUILTIN_PREFIX, builtin_scene, builtin_scene_sized, cache_dir, cached_suite_scene};
pub use description::{CameraSettings, ObjectDescription, RenderSettings, SceneDescription};
pub use render::Capture;
pub use scene_folder::{GenerateOptions, GeneratedScene, capture_setup, generate, generate_with_progress};
pub use shapes::Shape;
pub use suite::{BASE_SCENES, DIRECTIONS, FAST_PX, SLOW_PX, SuiteEntry, base_scene, max_shift_px, suite};
pub use texture::{Rgb, Texture};
pub use truth::{Truth, ground_truth};
pub use world::{Hit, World};
