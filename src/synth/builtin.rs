//! Built-in scenes by name (`scene = "builtin:checkerboards_slow1"` in a config): suite entries
//! generated into a cache folder the first time they are asked for.

use super::scene_folder::{GenerateOptions, generate_with_progress};
use super::suite::{SuiteEntry, suite};
use crate::io::{IoError, IoResult, write_atomic};
use std::path::{Path, PathBuf};

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
    let options = GenerateOptions { size, ..GenerateOptions::default() };
    let entries = suite(&options)?;
    let entry = entries.iter().find(|e| e.name == name).ok_or_else(|| {
        let names: Vec<&str> = entries.iter().map(|e| e.name.as_str()).collect();
        IoError::new(format!("{BUILTIN_PREFIX}{name}"), format!("no such built-in scene (expected one of {})", names.join(", ")))
    })?;
    cached_suite_scene(entry, &options)
}

/// The cache folder of suite entry `entry` generated under `options` (the entry must come from
/// `suite(options)`), generated when not yet there or when the folder there was generated from
/// anything else (an older rslf's descriptions, another seed).
pub fn cached_suite_scene(entry: &SuiteEntry, options: &GenerateOptions) -> IoResult<PathBuf> {
    cached_in(&cache_dir().join("scenes"), entry, options)
}

/// The file of a cached scene that holds what it was generated from.
const GENERATED_FROM: &str = "generated_from.toml";

fn cached_in(root: &Path, entry: &SuiteEntry, options: &GenerateOptions) -> IoResult<PathBuf> {
    let dir = root.join(match options.size {
        Some([w, h]) => format!("{}_{w}x{h}", entry.name),
        None => entry.name.clone(),
    });
    let stamp = generated_from(entry, options).map_err(|e| IoError::new(&dir, e))?;
    let cached = std::fs::read_to_string(dir.join(GENERATED_FROM)).ok();
    if dir.join("parameters.cfg").exists() && cached.as_deref() == Some(stamp.as_str()) {
        return Ok(dir);
    }
    let why = if dir.exists() { "again: the folder there was generated from something else, or not completely" } else { "once" };
    outln!("generating built-in scene {} into {} ({why})", entry.name, dir.display());
    let scene = generate_with_progress(&entry.description, options).map_err(|e| IoError::new(&dir, e))?;
    scene.write(&dir, true)?;
    // Written last: a folder without it (an interrupted run) is generated again.
    write_atomic(&dir.join(GENERATED_FROM), stamp.as_bytes())?;
    Ok(dir)
}

/// What a cached scene is generated from: its scene description (`rslf generate`'s input) and
/// the options, in a comment.
fn generated_from(entry: &SuiteEntry, options: &GenerateOptions) -> Result<String, String> {
    let description = toml::to_string(&entry.description).map_err(|e| format!("the description of {}: {e}", entry.name))?;
    let size = options.size.map_or("the description's".to_string(), |[w, h]| format!("{w}x{h}"));
    Ok(format!("# suite scene {}, generated at size {size}, seed {}\n{description}", entry.name, options.seed))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::SceneDescription;

    #[test]
    fn a_cached_scene_is_generated_again_only_when_what_it_was_generated_from_changed() -> Result<(), Box<dyn std::error::Error>> {
        let root = std::env::temp_dir().join(format!("rslf-cache-test-{}", std::process::id()));
        let options = GenerateOptions { size: Some([12, 12]), ..GenerateOptions::default() };
        let entries = suite(&options)?;
        let entry = &entries[0];
        let dir = cached_in(&root, entry, &options)?;
        assert!(dir.join("parameters.cfg").exists());
        let stamp = std::fs::read_to_string(dir.join(GENERATED_FROM))?;
        // What rslf generate reads: the same description back.
        assert_eq!(SceneDescription::parse(&stamp, Path::new(GENERATED_FROM))?, entry.description);
        // Same description: the folder is kept (a marker put in it survives).
        std::fs::write(dir.join("marker"), "")?;
        cached_in(&root, entry, &options)?;
        assert!(dir.join("marker").exists());
        // Another one (an older rslf's, or no record of it): generated again.
        std::fs::write(dir.join(GENERATED_FROM), stamp.replace("supersampling", "# supersampling"))?;
        cached_in(&root, entry, &options)?;
        assert!(!dir.join("marker").exists());
        assert_eq!(std::fs::read_to_string(dir.join(GENERATED_FROM))?, stamp);
        std::fs::remove_dir_all(&root)?;
        Ok(())
    }
}
