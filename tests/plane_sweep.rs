//! The stage-1 initial disparity on real data: HCI antinous and its ground truth.

mod common;

use common::hci;
use rslf::geometry::ViewId;
use rslf::io::{Raster, Scene, read_pfm};
use rslf::pipeline::{PlaneSweepSettings, aperture_weights, plane_sweep, stage1_views};

/// Share of pixels (away from an 8-pixel border) whose disparity is off by more than 0.07 px.
fn bad_pixels(estimate: &Raster, truth: &Raster) -> f64 {
    bad_pixels_where(estimate, truth, |_, _| true)
}

/// As [`bad_pixels`], over the pixels `(x, y)` where `keep` holds.
fn bad_pixels_where(estimate: &Raster, truth: &Raster, keep: impl Fn(usize, usize) -> bool) -> f64 {
    let (w, h) = (truth.width, truth.height);
    let (mut bad, mut n) = (0usize, 0usize);
    for y in 8..h - 8 {
        for x in (8..w - 8).filter(|&x| keep(x, y)) {
            bad += ((estimate.get(x, y, 0) - truth.get(x, y, 0)).abs() > 0.07) as usize;
            n += 1;
        }
    }
    bad as f64 / n.max(1) as f64
}

/// BadPix(0.07) of the sweep over the central row, then over the row and the `column` views of
/// the central column nearest the centre.
fn row_then_with_column(scene: &Scene, truth: &Raster, settings: &PlaneSweepSettings, column: usize) -> (f64, f64) {
    let row = scene.central_row_views();
    let with_column: Vec<ViewId> = row.iter().copied().chain(stage1_views(scene, 0, column)).collect();
    let sweep = |views: &[ViewId]| bad_pixels(&plane_sweep(scene, views, settings, |_, _| {}).disparity, truth);
    (sweep(&row), sweep(&with_column))
}

#[test]
fn the_central_column_finds_the_disparity_of_horizontal_stripes_the_row_cannot_see() {
    // Stripes that vary along y only: every view of the central row shows the same image
    // whatever the disparity, the views of the central column show them shifted by (r-rc) d.
    let dir = common::tempdir();
    let d = 0.8;
    common::write_plane_scene_with(
        dir.path(),
        64,
        64,
        5,
        d,
        |_| true,
        |_, y, ch| (0.5 + 0.3 * (0.7 * y + ch as f64).sin() + 0.1 * (0.23 * y).cos()) as f32,
    );
    let scene = Scene::load(dir.path()).unwrap();
    let truth = Raster::from_vec(64, 64, 1, vec![d as f32; 64 * 64]).unwrap();
    let settings = PlaneSweepSettings { range: (-2.0, 2.0), step: 0.05, window_radius: 2 };
    let (alone, both) = row_then_with_column(&scene, &truth, &settings, 2);
    eprintln!("BadPix(0.07): central row {:.1} %, with two central-column views {:.1} %", 100.0 * alone, 100.0 * both);
    assert!(alone > 0.9, "the row cannot see horizontal stripes move: {alone}");
    assert!(both < 0.01, "two views of the column pin them: {both}");
}

#[test]
fn a_uniform_square_wider_than_the_window_takes_its_surroundings_disparity() {
    // One textured plane at disparity 0.8 with a uniform 16 x 16 px square in it, seen by a
    // 9 x 9 grid. Inside the square every candidate that keeps the shifted 5 x 5 window inside
    // it matches exactly (from about -0.7 to the range's top, 2), while lower ones bring the
    // texture into the farthest views: the cost curve is deep but flat-bottomed, and its first
    // minimum is arbitrary. The sweep must not trust it.
    let dir = common::tempdir();
    let d = 0.8;
    let square = |x: f64, y: f64| (24.0..40.0).contains(&x) && (24.0..40.0).contains(&y);
    let texture = |x: f64, y: f64, ch: usize| {
        if square(x, y) { 0.4 } else { (0.5 + 0.2 * (0.9 * x + ch as f64).sin() * (0.7 * y).cos() + 0.1 * (0.31 * (x + y)).sin()) as f32 }
    };
    common::write_plane_scene_with(dir.path(), 64, 64, 9, d, |_| true, texture);
    let scene = Scene::load(dir.path()).unwrap();
    let truth = Raster::from_vec(64, 64, 1, vec![d as f32; 64 * 64]).unwrap();
    let settings = PlaneSweepSettings { range: (-2.0, 2.0), step: 0.05, window_radius: 2 };
    let estimate = plane_sweep(&scene, &scene.central_row_views(), &settings, |_, _| {});
    // The square's interior, more than a window away from its edges.
    let inside = |x: usize, y: usize| (27..37).contains(&x) && (27..37).contains(&y);
    let worst_inside = (27..37)
        .flat_map(|y| (27..37).map(move |x| (x, y)))
        .map(|(x, y)| (estimate.disparity.get(x, y, 0) as f64 - d).abs())
        .fold(0.0, f64::max);
    let bad_outside = bad_pixels_where(&estimate.disparity, &truth, |x, y| !inside(x, y));
    eprintln!(
        "inside the square: largest error {worst_inside:.3} px; elsewhere BadPix(0.07) {:.1} %; {} px filled",
        100.0 * bad_outside,
        estimate.untrusted
    );
    // Measured: 0.17 px at most inside (the square's rim pins it slightly high), 2.5 %
    // elsewhere; before the sweep judged flat-bottomed minima, 2.0 px inside and 3.4 %.
    assert!(estimate.untrusted >= 10 * 10, "the square's interior is filled: {}", estimate.untrusted);
    assert!(worst_inside < 0.25, "{worst_inside}");
    assert!(bad_outside < 0.15, "{bad_outside}");
}

/// HCI antinous, its ground-truth disparity and sweep settings covering its range.
fn antinous() -> (Scene, Raster, PlaneSweepSettings) {
    let dir = hci("antinous");
    let truth = read_pfm(&dir.join("gt_disp_lowres.pfm")).unwrap();
    (Scene::load(&dir).unwrap(), truth, PlaneSweepSettings { range: (-3.5, 3.0), step: 0.05, window_radius: 2 })
}

#[test]
fn on_antinous_the_central_column_does_not_make_the_sweep_worse() {
    let (scene, truth, settings) = antinous();
    let (alone, both) = row_then_with_column(&scene, &truth, &settings, 8);
    eprintln!("BadPix(0.07): central row {:.1} %, with the central column {:.1} %", 100.0 * alone, 100.0 * both);
    // Measured: 26.5 % and 26.0 %. A statue has few edges the row cannot see move.
    assert!(alone < 0.3, "the row-only sweep the pipeline has always used: {alone}");
    assert!(both < alone, "{both} against {alone}");
}

#[test]
fn on_antinous_the_row_gets_horizontal_edges_wrong_more_often() {
    // Stage 2's `aperture_weighting` rests on this: the central row fixes the disparity of
    // intensity changes along the row, not across it. Measured: 31.0 % BadPix(0.07) where the
    // weight is under 0.05 (3,109 pixels, nearly pure horizontal edges), 26.5 % elsewhere. Only
    // that extreme shows it (with the sweep before stop 60, 31.1 and 26.5 % here): under 0.2 it
    // was 25.5 % against 26.7 %, as the sweep's 5x5 window mostly holds some texture along the
    // row, and over 0.7 (vertical edges, the statue's outline among them, where disparity
    // jumps) 34.9 %.
    let (scene, truth, settings) = antinous();
    let estimate = plane_sweep(&scene, &scene.central_row_views(), &settings, |_, _| {}).disparity;
    let weights = aperture_weights(scene.central(), 2, 1e-4);
    let horizontal = |x: usize, y: usize| weights.get(x, y, 0) < 0.05;
    let on_edges = bad_pixels_where(&estimate, &truth, horizontal);
    let elsewhere = bad_pixels_where(&estimate, &truth, |x, y| !horizontal(x, y));
    eprintln!("BadPix(0.07) of the central-row sweep: horizontal edges {:.1} %, elsewhere {:.1} %", 100.0 * on_edges, 100.0 * elsewhere);
    assert!(on_edges > 1.1 * elsewhere, "{on_edges} against {elsewhere}");
}
