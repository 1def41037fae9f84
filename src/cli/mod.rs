//! The `rslf` command line: argument parsing and dispatch to the subcommands.

mod bench;
mod eval;
mod generate;
mod train;

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
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> crate::Result<()> {
    match cli.command {
        Command::Train(args) => train::run(args),
        Command::Eval(args) => eval::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Generate(args) => generate::run(args),
    }
}
