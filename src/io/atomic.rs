//! Writing files whole or not at all: a reader never sees a half-written result.

use super::error::{IoError, IoResult};
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename, so that
/// `path` either keeps its old content or has the new content complete.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> IoResult<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = path.file_name().ok_or_else(|| IoError::new(path, "not a file path"))?.to_string_lossy();
    let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
    let result = (|| {
        let mut file = std::fs::File::create(&tmp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        IoError::os(path, e)
    })
}

/// Creates `dir` and its parents.
pub fn create_dir_all(dir: &Path) -> IoResult<()> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::os(dir, e))
}

/// Writes the folder `out` whole or not at all: `fill` writes into a temporary sibling folder,
/// which is renamed to `out` once complete. An existing `out` is replaced only when `replace`
/// is set.
pub fn write_folder(out: &Path, replace: bool, fill: impl FnOnce(&Path) -> IoResult<()>) -> IoResult<()> {
    if out.exists() && !replace {
        return Err(IoError::new(out, "already exists (pass --force to replace it)"));
    }
    let name = out.file_name().ok_or_else(|| IoError::new(out, "not a folder path"))?.to_string_lossy();
    let parent = out.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    create_dir_all(parent)?;
    let tmp = parent.join(format!(".{name}.partial-{}", std::process::id()));
    if tmp.exists() {
        std::fs::remove_dir_all(&tmp).map_err(|e| IoError::os(&tmp, e))?;
    }
    let filled = create_dir_all(&tmp).and_then(|_| fill(&tmp));
    if let Err(e) = filled {
        let _ = std::fs::remove_dir_all(&tmp);
        return Err(e);
    }
    if out.exists() {
        std::fs::remove_dir_all(out).map_err(|e| IoError::os(out, e))?;
    }
    std::fs::rename(&tmp, out).map_err(|e| IoError::os(out, e))
}
