//! The `rslf` command line: argument parsing and dispatch to the subcommands.

mod ablation;
mod bench;
mod eval;
mod generate;
mod render;
mod train;

use crate::pipeline::Registries;
use clap::{Parser, Subcommand};

/// Dense depth and camera motion from one rolling-shutter light field.
#[derive(Debug, Parser)]
#[command(name = "rslf", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Fit a scene as a config describes and write the result folder.
    Train(train::TrainArgs),
    /// Render a synthetic rolling-shutter light field with ground truth (one scene or the suite).
    Generate(generate::GenerateArgs),
    /// Time the renderer (flex, wgpu) and stage 1; print peak memory.
    Bench(bench::BenchArgs),
    /// Compare a result folder with a scene's ground truth; print and write metrics.json.
    Eval(eval::EvalArgs),
    /// Fit generated scenes with and without the stage-1 fit and stage 2; print the paper's
    /// ablation table (Table 3).
    Ablation(ablation::AblationArgs),
    /// Render a saved model's whole light field (at t = 0 or as captured) as a scene folder.
    Render(render::RenderArgs),
}

/// Runs the parsed command line with the built-in loss terms and motion models.
pub fn run(cli: Cli) -> crate::Result<()> {
    run_with(cli, &Registries::default())
}

/// Runs the parsed command line; `train` draws loss terms and motion models from `registries`.
/// A program that registers its own terms or models and calls this is the `rslf` command with
/// them added (see `examples/custom_loss.rs`).
pub fn run_with(cli: Cli, registries: &Registries) -> crate::Result<()> {
    match cli.command {
        Command::Train(args) => train::run(args, registries),
        Command::Eval(args) => eval::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Generate(args) => generate::run(args),
        Command::Render(args) => render::run(args),
        Command::Ablation(args) => ablation::run(args),
    }
}

/// The whole `rslf` program: parses the process's arguments, runs them with `registries`,
/// prints an error as one line and returns the exit code.
pub fn main_with(registries: &Registries) -> std::process::ExitCode {
    use clap::Parser;
    match run_with(Cli::parse(), registries) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err}");
            std::process::ExitCode::FAILURE
        }
    }
}
