//! Loss terms by name, and the weighted sum a config asks for.

use super::{DSsim, EdgeAwareSmoothness, L1, L2, LossInput, LossTerm, MotionPrior, MotionSmoothness};
use crate::config::LossConfig;
use burn::tensor::Tensor;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Builds a loss term.
pub type LossConstructor = Arc<dyn Fn() -> Box<dyn LossTerm> + Send + Sync>;

/// A config names a term the registry does not know.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown loss term `{name}` (known: {known})")]
pub struct UnknownLoss {
    /// The name asked for.
    pub name: String,
    /// The names the registry knows, comma-separated.
    pub known: String,
}

/// Loss terms by registry name.
#[derive(Clone)]
pub struct LossRegistry {
    terms: BTreeMap<String, LossConstructor>,
}

impl Default for LossRegistry {
    /// The built-in terms: `l1`, `l2`, `dssim`, `smoothness`, `motion_prior`,
    /// `motion_smoothness`.
    fn default() -> Self {
        Self { terms: BTreeMap::new() }
            .register("l1", || Box::new(L1))
            .register("l2", || Box::new(L2))
            .register("dssim", || Box::new(DSsim))
            .register("smoothness", || Box::new(EdgeAwareSmoothness))
            .register("motion_prior", || Box::new(MotionPrior))
            .register("motion_smoothness", || Box::new(MotionSmoothness))
    }
}

impl LossRegistry {
    /// Adds (or replaces) the term `name`.
    pub fn register(mut self, name: &str, make: impl Fn() -> Box<dyn LossTerm> + Send + Sync + 'static) -> Self {
        self.terms.insert(name.to_string(), Arc::new(make));
        self
    }

    /// The registered names, sorted.
    pub fn names(&self) -> Vec<&str> {
        self.terms.keys().map(String::as_str).collect()
    }

    /// The weighted terms a config lists.
    pub fn build(&self, losses: &[LossConfig]) -> Result<WeightedLosses, UnknownLoss> {
        let terms = losses
            .iter()
            .map(|l| match self.terms.get(&l.kind) {
                Some(make) => Ok(WeightedLoss { weight: l.weight as f32, term: make() }),
                None => Err(UnknownLoss { name: l.kind.clone(), known: self.names().join(", ") }),
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(WeightedLosses { terms })
    }
}

/// A term and its weight.
pub struct WeightedLoss {
    /// Weight in the sum.
    pub weight: f32,
    /// The term.
    pub term: Box<dyn LossTerm>,
}

/// The objective of a stage: `Σ weight · term` over the terms that apply.
pub struct WeightedLosses {
    /// The terms, in config order.
    pub terms: Vec<WeightedLoss>,
}

impl WeightedLosses {
    /// The weighted sum for one band; `None` when no term applies.
    pub fn evaluate(&self, input: &LossInput) -> Option<Tensor<1>> {
        self.terms.iter().filter(|t| t.weight != 0.0).filter_map(|t| t.term.evaluate(input).map(|v| v * t.weight)).reduce(|a, b| a + b)
    }

    /// These terms less those that score the motion alone ([`LossTerm::scores_motion_only`]):
    /// the objective of a stage that fits no motion.
    pub fn without_motion_terms(mut self) -> Self {
        self.terms.retain(|t| !t.term.scores_motion_only());
        self
    }

    /// `name×weight` of each term, for logs.
    pub fn names(&self) -> Vec<String> {
        self.terms.iter().map(|t| format!("{}×{}", t.term.name(), t.weight)).collect()
    }
}
