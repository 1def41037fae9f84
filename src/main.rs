use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = rslf::cli::Cli::parse();
    match rslf::cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err}");
            ExitCode::FAILURE
        }
    }
}
