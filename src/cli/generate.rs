//! `rslf generate SCENE.toml --out DIR` and `rslf generate --suite --out DIR`.

use crate::synth::{GenerateOptions, SceneDescription, generate_with_progress, suite};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `rslf generate`.
#[derive(Debug, clap::Args)]
pub struct GenerateArgs {
    /// Scene description (TOML; see configs/scenes/). Not with --suite.
    #[arg(required_unless_present = "suite", conflicts_with = "suite")]
    pub scene: Option<PathBuf>,
    /// Output folder: the scene folder, or with --suite the folder of all suite scenes.
    #[arg(long, required_unless_present = "list")]
    pub out: Option<PathBuf>,
    /// Generate the whole built-in suite (every base scene: static, 5 slow, 5 fast motions).
    #[arg(long)]
    pub suite: bool,
    /// Image size: `N` (N x N) or `WxH`; overrides the description's.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<[usize; 2]>,
    /// Seed mixed into every random choice (noise, branches); same seed, same scene.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Replace scene folders that already exist.
    #[arg(long)]
    pub force: bool,
    /// With --suite: print the scenes and their motions without rendering anything.
    #[arg(long, requires = "suite")]
    pub list: bool,
}

fn parse_size(s: &str) -> Result<[usize; 2], String> {
    let parse = |v: &str| v.trim().parse::<usize>().map_err(|_| format!("`{s}` is not a size (N or WxH)"));
    let [w, h] = match s.split_once(['x', 'X']) {
        Some((w, h)) => [parse(w)?, parse(h)?],
        None => [parse(s)?; 2],
    };
    if !(8..=8192).contains(&w) || !(8..=8192).contains(&h) {
        return Err(format!("size {w}x{h} must be 8 to 8192 pixels a side"));
    }
    Ok([w, h])
}

fn one(description: &SceneDescription, options: &GenerateOptions, out: &std::path::Path, force: bool) -> crate::Result<f64> {
    if out.exists() && !force {
        return Err(crate::io::IoError::new(out, "already exists (pass --force to replace it)").into());
    }
    let start = Instant::now();
    let scene = generate_with_progress(description, options).map_err(crate::Error::Usage)?;
    let seconds = start.elapsed().as_secs_f64();
    scene.write(out, force)?;
    Ok(seconds)
}

/// Generates one scene or the suite.
pub fn run(args: GenerateArgs) -> crate::Result<()> {
    let options = GenerateOptions { size: args.size, seed: args.seed };
    if args.suite {
        let entries = suite(&options)?;
        match &args.out {
            Some(out) if !args.list => outln!("suite: {} scenes into {}", entries.len(), out.display()),
            _ => outln!("suite: {} scenes", entries.len()),
        }
        for entry in &entries {
            let timing = match (&args.out, args.list) {
                (Some(out), false) => format!("  [{:.1} s]", one(&entry.description, &options, &out.join(&entry.name), args.force)?),
                _ => String::new(),
            };
            let motion = entry.description.motion().map_err(crate::Error::Usage)?;
            let groups = motion.groups();
            let round = |v: &[f64]| v.iter().map(|x| (x * 1e4).round() / 1e4).collect::<Vec<_>>();
            outln!(
                "{:<22} {:<6} max shift {:>5.2} px  omega {:?} rad/s  v {:?} m/s{timing}",
                entry.name,
                entry.category,
                entry.max_shift_px,
                round(&groups[0].1),
                round(&groups[1].1),
            );
        }
        return Ok(());
    }
    let (Some(path), Some(out)) = (args.scene, args.out) else {
        return Err(crate::Error::Usage("rslf generate needs SCENE.toml and --out DIR (or --suite)".into()));
    };
    let description = SceneDescription::read(&path)?;
    let seconds = one(&description, &options, &out, args.force)?;
    outln!("wrote {} ({} views rendered in {seconds:.1} s)", out.display(), description.camera.num_cams.pow(2));
    Ok(())
}
