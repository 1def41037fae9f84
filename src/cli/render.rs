//! `rslf render MODEL --out DIR`: a saved model's whole light field as a new scene folder.

use crate::config::DeviceChoice;
use crate::eval::psnr_db;
use crate::io::{Scene, view_file_name, write_folder, write_png};
use crate::model::SavedModel;
use crate::pipeline::{Moment, render_light_field};
use crate::render::RenderSettings;
use std::path::PathBuf;

/// Arguments of `rslf render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// A saved model: `models/<run>` or its `model.json`.
    pub model: PathBuf,
    /// The scene folder to write (views `input_CamNNN.png` and `parameters.cfg`).
    #[arg(long)]
    pub out: PathBuf,
    /// `t0`: the scene at t = 0, rolling shutter compensated (a global-shutter light field);
    /// `capture`: as the camera read it, under the estimated motion.
    #[arg(long, value_enum, default_value = "t0")]
    pub at: Moment,
    /// Scene to compare with (PSNR per view); default: the folder the model was fitted to.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Device.
    #[arg(long, value_enum, default_value = "flex")]
    pub device: DeviceChoice,
    /// Replace `--out` if it exists.
    #[arg(long)]
    pub force: bool,
}

/// Renders the light field, writes it as a scene folder, and prints the PSNR against the input
/// views when the render reproduces the capture (`--at capture`, or a model without motion).
pub fn run(args: RenderArgs) -> crate::Result<()> {
    let saved = SavedModel::load(&args.model)?;
    let device = crate::device::device(args.device)?;
    let [w, h] = saved.size;
    outln!(
        "model {}: {} Gaussians, {}x{} px, {}x{} views, {}",
        args.model.display(),
        saved.gaussians.len(),
        w,
        h,
        saved.grid[0],
        saved.grid[1],
        match saved.motion_record() {
            Some(m) => format!("`{}` motion", m.model_name()),
            None => "no motion".into(),
        }
    );
    // Checked again when writing; checked here too so that a refused run renders nothing.
    if args.out.exists() && !args.force {
        return Err(crate::Error::Usage(format!("{}: already exists (pass --force to replace it)", args.out.display())));
    }
    let bar = crate::progress::bar((saved.grid[0] * saved.grid[1]) as u64, "render: views");
    let views = render_light_field(&saved, args.at, &RenderSettings::default(), &device, |done, _| bar.set_position(done as u64))?;
    bar.finish_and_clear();

    // At t = 0 every row is read at once: the written scene is a global-shutter capture.
    let parameters = saved.scene_parameters().map(|mut p| {
        if args.at == Moment::T0 {
            p.line_time_s = None;
        }
        p
    });
    write_folder(&args.out, args.force, |dir| {
        for (i, view) in views.iter().enumerate() {
            write_png(&dir.join(view_file_name(i)), view)?;
        }
        match &parameters {
            Some(p) => p.write(&dir.join("parameters.cfg")),
            None => Ok(()),
        }
    })?;
    outln!("wrote {} ({} views{})", args.out.display(), views.len(), if parameters.is_some() { ", parameters.cfg" } else { "" });

    let reproduces_capture = args.at == Moment::Capture || saved.motion.is_none();
    if !reproduces_capture {
        outln!("PSNR: not computed; the t = 0 light field differs from the captured views by the motion (use --at capture)");
        return Ok(());
    }
    let scene_dir = args.scene.unwrap_or_else(|| saved.scene.clone());
    let scene = match Scene::load(&scene_dir) {
        Ok(scene) if scene.width() == w && scene.height() == h && scene.grid.len() == views.len() => scene,
        Ok(_) => return Err(crate::Error::Usage(format!("{}: not the size or grid of the model", scene_dir.display()))),
        Err(e) => {
            outln!("PSNR: not computed, the input scene does not load ({e}); pass --scene DIR");
            return Ok(());
        }
    };
    let region = vec![true; w * h];
    let scores: Vec<(usize, f64)> = scene
        .present_views()
        .into_iter()
        .map(|v| {
            let i = scene.grid.index(v);
            (i, psnr_db(&views[i], scene.view(v).expect("present"), &region))
        })
        .collect();
    out!("{}", psnr_grid(&scene, &scores));
    let mean = scores.iter().map(|(_, db)| db).sum::<f64>() / scores.len() as f64;
    let (worst_view, worst) = scores.iter().copied().min_by(|a, b| a.1.total_cmp(&b.1)).expect("a scene has its central view");
    outln!(
        "PSNR against the {} input views of {}: mean {mean:.2} dB, lowest {worst:.2} dB (view {worst_view})",
        scores.len(),
        scene_dir.display()
    );
    Ok(())
}

/// The PSNR of each view laid out as the view grid: one line per view row (top to bottom),
/// one column per view column (left to right), `-` for a view the scene lacks. Read along a
/// row or column, it shows how the model holds up away from the views it was fitted to.
fn psnr_grid(scene: &Scene, scores: &[(usize, f64)]) -> String {
    let grid = scene.grid;
    let mut cells = vec![None; grid.len()];
    for &(i, db) in scores {
        cells[i] = Some(db);
    }
    let mut text = String::from("PSNR (dB) per view, by view row and column:\n     ");
    for col in 0..grid.cols {
        text += &format!(" {:>6}", format!("c{col}"));
    }
    for row in 0..grid.rows {
        text += &format!("\n  {:>3}", format!("r{row}"));
        for col in 0..grid.cols {
            match cells[grid.index(crate::geometry::ViewId { row, col })] {
                Some(db) => text += &format!(" {db:>6.2}"),
                None => text += &format!(" {:>6}", "-"),
            }
        }
    }
    text + "\n"
}
