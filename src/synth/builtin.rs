//! Built-in scenes by name (`scene = "builtin:checkerboards_slow1"` in a config): suite entries
//! generated into a cache folder the first time they are asked for.

use super::scene_folder::{GenerateOptions, generate_with_progress};
use super::suite::{SuiteEntry, suite};
use crate::io::{IoError, IoResult};
use std::path::PathBuf;

/// The prefix that marks a built-in scene in a config's `scene`.
pub const BUILTIN_PREFIX: &str = "builtin:";

/// Folder of generated built-in scenes: `$RSLF_CACHE_DIR`, else `$XDG_CACHE_HOME/rslf`, else
/// `~/.cache/rslf`.
pub fn cache_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("RSLF_CACHE_DIR") {
        return PathBuf::from(dir);
    }
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(|| PathBuf::from(".cache"));
    base.join("rslf")
}

/// The folder of built-in scene `name` (a suite entry such as `checkerboards_slow1`), generated
/// at its default size when not yet in the cache.
pub fn builtin_scene(name: &str) -> IoResult<PathBuf> {
    builtin_scene_sized(name, None)
}

/// The folder of built-in scene `name` at `size` (`[W, H]`; `None`: the default size, 512x512),
/// generated when not yet in the cache. The suite's motions are set for 512 px and their pixel
/// shifts scale with the width (a 64 px scene moves 1/8 as many pixels).
pub fn builtin_scene_sized(name: &str, size: Option<[usize; 2]>) -> IoResult<PathBuf> {
    // A cached scene is returned without building the suite.
    let dir = cache_folder(name, size);
    if dir.join("parameters.cfg").exists() {
        return Ok(dir);
    }
    let options = GenerateOptions { size, ..GenerateOptions::default() };
    let entries = suite(&options)?;
    let entry = entries.iter().find(|e| e.name == name).ok_or_else(|| {
        let names: Vec<&str> = entries.iter().map(|e| e.name.as_str()).collect();
        IoError::new(format!("{BUILTIN_PREFIX}{name}"), format!("no such built-in scene (expected one of {})", names.join(", ")))
    })?;
    cached_suite_scene(entry, &options)
}

/// The cache folder of suite entry `entry` generated under `options` (the entry must come from
/// `suite(options)`), generated when not yet there.
pub fn cached_suite_scene(entry: &SuiteEntry, options: &GenerateOptions) -> IoResult<PathBuf> {
    let dir = cache_folder(&entry.name, options.size);
    if dir.join("parameters.cfg").exists() {
        return Ok(dir);
    }
    println!("generating built-in scene {} into {} (once)", entry.name, dir.display());
    let scene = generate_with_progress(&entry.description, options).map_err(|e| IoError::new(&dir, e))?;
    scene.write(&dir, true)?;
    Ok(dir)
}

/// Where suite scene `name` at `size` is cached.
fn cache_folder(name: &str, size: Option<[usize; 2]>) -> PathBuf {
    let folder = match size {
        Some([w, h]) => format!("{name}_{w}x{h}"),
        None => name.to_string(),
    };
    cache_dir().join("scenes").join(folder)
}
