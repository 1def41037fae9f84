//! Generic optimisation stages: which parameters move, at which learning rates, under which
//! objective, for how many steps.
//!
//! A stage is a burn [`Module`](burn::module::Module) (the model's parameters), a [`Plan`] (Adam
//! with a learning-rate [`Schedule`] and epsilon per parameter group), and an [`Objective`]
//! (a function from the model to a scalar loss on the autodiff graph). [`optimise`] runs it;
//! [`optimise_by_gradients`] runs an objective that takes its gradients itself, part by part
//! ([`mean_over_parts`], [`weighted_sum`]), as both RSLF stages do over their views.
//! Both RSLF stages are compositions of these pieces (`pipeline::fit_stage1`,
//! `pipeline::fit_stage2`); `examples/fit_image.rs` uses them to fit 2D Gaussians to one image.

mod gradients;
mod mean_loss;
mod newton;
mod plan;
mod schedule;
mod stage;

pub use gradients::{gradients_of, mean_over_parts, weighted_sum};
pub use mean_loss::MeanLoss;
pub use newton::{NewtonReport, NewtonSettings, RestReport, held_directions, newton_minimise, newton_within};
pub use plan::{GroupPlan, Optimiser, Plan};
pub use schedule::Schedule;
pub use stage::{Objective, Stage, StepReport, optimise, optimise_by_gradients};
