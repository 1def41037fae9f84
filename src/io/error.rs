//! The error of the I/O layer: always names the file and says what is wrong with it.

use std::fmt;
use std::path::{Path, PathBuf};

/// A problem with one file or folder: which one, and what is wrong, in one line.
#[derive(Debug, Clone, PartialEq)]
pub struct IoError {
    /// The file or folder at fault.
    pub path: PathBuf,
    /// What is wrong with it, in words a user can act on.
    pub problem: String,
}

impl IoError {
    /// An error about `path`.
    pub fn new(path: impl AsRef<Path>, problem: impl Into<String>) -> Self {
        Self { path: path.as_ref().to_path_buf(), problem: problem.into() }
    }

    /// Wraps an OS error (missing file, permission denied, ...) for `path`.
    pub fn os(path: impl AsRef<Path>, err: std::io::Error) -> Self {
        let problem = match err.kind() {
            std::io::ErrorKind::NotFound => "no such file or folder".to_string(),
            std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
            _ => err.to_string(),
        };
        Self::new(path, problem)
    }
}

impl fmt::Display for IoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.problem)
    }
}

impl std::error::Error for IoError {}

/// Result of the I/O layer.
pub type IoResult<T> = Result<T, IoError>;
