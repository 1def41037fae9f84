//! The crate's error: one variant per layer, each printing as one line that names its file.

use crate::config::ConfigError;
use crate::io::IoError;

/// Any error rslf reports.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scene, result or data file is missing or wrong.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A config file is wrong.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The command line or the combination of settings is wrong.
    #[error("{0}")]
    Usage(String),
}

/// Result with the crate's error.
pub type Result<T> = std::result::Result<T, Error>;
