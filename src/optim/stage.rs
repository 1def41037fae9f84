//! The optimisation loop: a model, a plan, an objective, a number of steps.

use super::gradients::gradients_of;
use super::plan::{Optimiser, Plan};
use burn::module::Module;
use burn::optim::GradientsParams;
use burn::tensor::Tensor;

/// What an optimisation stage minimises: the loss of a step as a one-element tensor on the
/// autodiff graph of the model's parameters, or `None` to stop early (nothing to compare).
/// Any `FnMut(&M, usize) -> Option<Tensor<1>>` is an objective.
pub trait Objective<M> {
    /// The loss of `model` at `step` (counted from 0).
    fn loss(&mut self, model: &M, step: usize) -> Option<Tensor<1>>;
}

impl<M, F: FnMut(&M, usize) -> Option<Tensor<1>>> Objective<M> for F {
    fn loss(&mut self, model: &M, step: usize) -> Option<Tensor<1>> {
        self(model, step)
    }
}

/// How long and how a stage optimises.
#[derive(Debug, Clone, PartialEq)]
pub struct Stage {
    /// Adam steps.
    pub iterations: usize,
    /// Learning rates and epsilons per parameter group.
    pub plan: Plan,
}

/// Progress after one step, for a progress bar or a log.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// Steps done.
    pub step: usize,
    /// Steps in the stage.
    pub of: usize,
    /// The loss before this step's update.
    pub loss: f32,
}

/// Runs `stage` on `model` under `objective`; returns the fitted model and the loss of each step
/// (before its update). `progress` is called after each step.
pub fn optimise<M: Module>(model: M, stage: &Stage, mut objective: impl Objective<M>, progress: impl FnMut(StepReport)) -> (M, Vec<f32>) {
    let by_gradients = |m: &M, step: usize| {
        let loss = objective.loss(m, step)?;
        Some((loss.clone().into_scalar::<f32>(), gradients_of(loss, m)))
    };
    optimise_by_gradients(model, stage, by_gradients, progress)
}

/// [`optimise`] under an objective that returns the loss of a step with its gradients with
/// respect to the model's parameters, or `None` to stop early: one that takes them part by
/// part ([`super::weighted_sum`]), so that no one graph holds the whole loss.
pub fn optimise_by_gradients<M: Module>(
    mut model: M,
    stage: &Stage,
    mut objective: impl FnMut(&M, usize) -> Option<(f32, GradientsParams)>,
    mut progress: impl FnMut(StepReport),
) -> (M, Vec<f32>) {
    let mut optimiser = Optimiser::new(&stage.plan);
    let mut curve = Vec::with_capacity(stage.iterations);
    for step in 0..stage.iterations {
        let Some((value, grads)) = objective(&model, step) else { break };
        model = optimiser.step(model, grads);
        curve.push(value);
        progress(StepReport { step: step + 1, of: stage.iterations, loss: value });
    }
    (model, curve)
}
