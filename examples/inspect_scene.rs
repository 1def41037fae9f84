//! Loads a scene folder and prints what rslf makes of it: the grid, which views are present,
//! the camera, and how disparity maps to depth and to each view.
//!
//! `cargo run --example inspect_scene -- ../shared/data/hci/cotton`

use rslf::io::Scene;
use std::path::PathBuf;

fn main() {
    let dir: PathBuf = std::env::args_os().nth(1).map(PathBuf::from).unwrap_or_else(|| "../shared/data/hci/cotton".into());
    let scene = match Scene::load(&dir) {
        Ok(scene) => scene,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    println!("{}: {}x{} px, {} channel(s)", dir.display(), scene.width(), scene.height(), scene.channels());
    println!("grid {}x{}, {} views present:", scene.grid.rows, scene.grid.cols, scene.present_views().len());
    for r in 0..scene.grid.rows {
        let row: String = (0..scene.grid.cols).map(|c| if scene.views[r * scene.grid.cols + c].is_some() { 'o' } else { '.' }).collect();
        println!("  {row}");
    }
    let Some(cam) = scene.camera() else {
        println!("no parameters.cfg: disparity only");
        return;
    };
    println!("f = {:.2} px, baseline = {} m, focus = {} m, line time = {} s", cam.f_px, cam.baseline_m, cam.focus_m, cam.line_time_s);
    let corner = scene.grid.corners()[0];
    for d in [-1.0, 0.0, 1.0] {
        let (u, v) = scene.grid.position_in_view(corner, cam.u0(), cam.v0(), d);
        println!(
            "disparity {d:+.1} px = depth {:.3} m; the centre pixel appears in the top-left view at ({u:.1}, {v:.1})",
            cam.disparity_to_depth(d)
        );
    }
}
