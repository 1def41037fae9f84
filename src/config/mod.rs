//! Run configuration (TOML): the schema and its loader.

mod load;
mod schema;

pub use load::ConfigError;
pub use schema::{Config, DeviceChoice, LossConfig, MotionConfig, RenderConfig, Stage1Config, Stage2Config, TimingChoice, ViewSelection};
