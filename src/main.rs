//! The `rslf` command: the built-in loss terms and motion models.

fn main() -> std::process::ExitCode {
    rslf::cli::main_with(&rslf::pipeline::Registries::default())
}
