//! Which parameters an optimiser moves and how: Adam with a learning-rate schedule and an
//! epsilon per group of parameters.

use super::schedule::{Schedule, Scheduled};
use burn::module::{Module, ParamGroup, ParamId};
use burn::optim::lr_scheduler::module_lr_scheduler::ModuleLrScheduler;
use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};

/// How one group of parameters is stepped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroupPlan {
    /// Learning rate per step, in the parameter's units.
    pub schedule: Schedule,
    /// Adam's epsilon. Near 0 Adam steps by the sign of the gradient, so parameters whose
    /// gradients are at noise level random-walk at the full rate; larger values damp them.
    pub adam_epsilon: f32,
}

/// Adam plans for a module's parameters: a default for all, and plans for groups of parameters
/// picked by [`ParamId`] (later groups take precedence). Parameters without gradients (made
/// with `Module::no_grad`) are not moved, whatever the plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    default: GroupPlan,
    groups: Vec<(Vec<ParamId>, GroupPlan)>,
}

impl Plan {
    /// Every parameter under `default`.
    pub fn new(default: GroupPlan) -> Self {
        Self { default, groups: Vec::new() }
    }

    /// The parameters `ids` under `plan`.
    pub fn with_group(mut self, ids: impl IntoIterator<Item = ParamId>, plan: GroupPlan) -> Self {
        self.groups.push((ids.into_iter().collect(), plan));
        self
    }
}

/// A [`Plan`] made runnable: burn's module optimiser and learning-rate policy, with their state.
#[derive(Clone)]
pub struct Optimiser {
    adam: ModuleOptimizer,
    lr: ModuleLrScheduler,
}

impl Optimiser {
    /// A fresh optimiser (zero moments, step 0) for `plan`.
    pub fn new(plan: &Plan) -> Self {
        let mut adam = AdamConfig::new().with_epsilon(plan.default.adam_epsilon).init();
        let mut lr = ModuleLrScheduler::new(Scheduled::from(plan.default.schedule));
        for (ids, group) in &plan.groups {
            let params = ParamGroup::from_ids(ids.clone());
            adam = adam.with_group(params.clone(), AdamConfig::new().with_epsilon(group.adam_epsilon).build(), None);
            lr = lr.with_group(params, Scheduled::from(group.schedule));
        }
        Self { adam, lr }
    }

    /// One Adam step of `module` along the gradients `grads` of its parameters.
    pub fn step<M: Module>(&mut self, module: M, grads: GradientsParams) -> M {
        self.adam.step(self.lr.step(), module, grads)
    }
}
