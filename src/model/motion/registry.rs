//! Motion models by name.

use super::{ConstantAcceleration, ConstantVelocity, MotionModel, PiecewiseConstant};
use crate::config::MotionConfig;
use std::collections::BTreeMap;
use std::sync::Arc;

/// What a constructor may need besides the config: the capture's read-out interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionSetup {
    /// `[t(0), t(H-1)]`, seconds.
    pub readout: (f64, f64),
}

/// Builds a motion model from its config table.
pub type MotionConstructor = Arc<dyn Fn(&MotionConfig, &MotionSetup) -> Result<Box<dyn MotionModel>, String> + Send + Sync>;

/// A config names a model the registry does not know, or the model refuses its settings.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("motion model `{name}`: {problem}")]
pub struct UnknownMotion {
    /// The name asked for.
    pub name: String,
    /// What is wrong.
    pub problem: String,
}

/// Motion models by registry name.
#[derive(Clone)]
pub struct MotionRegistry {
    models: BTreeMap<String, MotionConstructor>,
}

impl Default for MotionRegistry {
    /// The built-in models: `constant_velocity`, `constant_acceleration`, `piecewise_constant`.
    fn default() -> Self {
        Self { models: BTreeMap::new() }
            .register("constant_velocity", |_, _| Ok(Box::new(ConstantVelocity)))
            .register("constant_acceleration", |_, _| Ok(Box::new(ConstantAcceleration)))
            .register("piecewise_constant", |c, s| {
                if c.segments == 0 {
                    return Err("segments must be at least 1".into());
                }
                Ok(Box::new(PiecewiseConstant { segments: c.segments, readout: s.readout }))
            })
    }
}

impl MotionRegistry {
    /// Adds (or replaces) the model `name`.
    pub fn register(
        mut self,
        name: &str,
        make: impl Fn(&MotionConfig, &MotionSetup) -> Result<Box<dyn MotionModel>, String> + Send + Sync + 'static,
    ) -> Self {
        self.models.insert(name.to_string(), Arc::new(make));
        self
    }

    /// The registered names, sorted.
    pub fn names(&self) -> Vec<&str> {
        self.models.keys().map(String::as_str).collect()
    }

    /// The model a config asks for.
    pub fn build(&self, config: &MotionConfig, setup: &MotionSetup) -> Result<Box<dyn MotionModel>, UnknownMotion> {
        let err = |problem: String| UnknownMotion { name: config.model.clone(), problem };
        let make = self.models.get(&config.model).ok_or_else(|| err(format!("unknown (known: {})", self.names().join(", "))))?;
        make(config, setup).map_err(err)
    }
}
