//! FORMAT conventions checked against the real HCI benchmark scenes in `../shared/data/hci`.

mod common;

use common::{hci, rslf};
use rslf::geometry::{ViewGrid, ViewId};
use rslf::io::{Scene, read_pfm};
use rslf::pipeline::{BorderStrips, stage1_views};

#[test]
fn antinous_loads_81_views_of_512x512_without_a_camera() {
    let scene = Scene::load(&hci("antinous")).unwrap();
    assert_eq!(scene.grid, ViewGrid { rows: 9, cols: 9 });
    assert_eq!(scene.present_views().len(), 81);
    assert_eq!((scene.width(), scene.height(), scene.channels()), (512, 512, 3));
    assert!(scene.params.is_none() && scene.camera().is_none());
    assert_eq!(scene.central_id(), ViewId { row: 4, col: 4 });
}

#[test]
fn cotton_loads_33_views_with_its_central_row_corners_and_camera() {
    let scene = Scene::load(&hci("cotton")).unwrap();
    assert_eq!(scene.present_views().len(), 33);
    assert_eq!(scene.central_row_views().len(), 9);
    for corner in scene.grid.corners() {
        assert!(scene.view(corner).is_some(), "corner {corner:?} missing");
    }
    assert!(scene.view(ViewId { row: 0, col: 1 }).is_none(), "cotton ships 33 of 81 views");
    let cam = scene.camera().unwrap();
    assert!((cam.f_px - 100.0 * 512.0 / 35.0).abs() < 1e-9);
    assert!((cam.baseline_m - 0.025).abs() < 1e-12 && (cam.focus_m - 4.25).abs() < 1e-12);
    assert!(!scene.is_rolling_shutter());
    assert_eq!(scene.params.as_ref().unwrap().disparity_range, Some((-1.6, 1.5)));
}

#[test]
fn stage_1_takes_cotton_central_row_then_its_central_column_nearest_first() {
    let scene = Scene::load(&hci("cotton")).unwrap();
    let v = |row, col| ViewId { row, col };
    // The paper's choice: the central row only.
    assert_eq!(stage1_views(&scene, 5, 0), (2..7).map(|c| v(4, c)).collect::<Vec<_>>());
    // Cotton ships its whole central column: the nearest views above and below come first.
    assert_eq!(stage1_views(&scene, 3, 2), vec![v(4, 3), v(4, 4), v(4, 5), v(3, 4), v(5, 4)]);
    let all = stage1_views(&scene, 9, 20);
    assert_eq!(all.len(), 17, "9 views of the row and the 8 others of the column: {all:?}");
    assert!(all.iter().all(|x| x.row == 4 || x.col == 4));
}

#[test]
fn the_shipped_config_fits_the_central_column_only_without_a_rolling_shutter() {
    let config = rslf::config::Config::read(&common::project_path("configs/constant_velocity.toml")).unwrap();
    let s1 = &config.stage1;
    assert_eq!(s1.column_views, None, "the shipped config leaves the choice to the capture");
    // Cotton is a global-shutter capture: no motion bends its column, so the fit takes as many
    // of its views as of the row's.
    let scene = Scene::load(&hci("cotton")).unwrap();
    assert!(!scene.is_rolling_shutter());
    let views = stage1_views(&scene, s1.views, s1.column_views_for(scene.is_rolling_shutter()));
    let v = |row, col| ViewId { row, col };
    assert_eq!(views, vec![v(4, 2), v(4, 3), v(4, 4), v(4, 5), v(4, 6), v(2, 4), v(3, 4), v(5, 4), v(6, 4)]);
    // With a rolling shutter the paper's central row only; a count in the config wins.
    assert_eq!(s1.column_views_for(true), 0);
    let explicit = rslf::config::Stage1Config { column_views: Some(0), ..s1.clone() };
    assert_eq!(explicit.column_views_for(false), 0);
}

#[test]
fn the_disparity_sign_of_format_reproduces_antinous_central_view() {
    let dir = hci("antinous");
    let scene = Scene::load(&dir).unwrap();
    let gt = read_pfm(&dir.join("gt_disp_lowres.pfm")).unwrap();
    // Corners and the ends of the central row and column: every direction of the rule.
    let views = [(0, 0), (0, 8), (8, 0), (8, 8), (4, 0), (4, 8), (0, 4), (8, 4)];
    for (row, col) in views {
        let view = ViewId { row, col };
        let right = common::warp_error(&scene, &gt, view, 1.0, 20);
        let wrong = common::warp_error(&scene, &gt, view, -1.0, 20);
        assert!(right < 0.02, "view {view:?}: error {right} with FORMAT's sign");
        assert!(wrong > 3.0 * right, "view {view:?}: FORMAT's sign {right} vs opposite {wrong}");
    }
}

#[test]
fn hci_ground_truth_pfm_reads_as_a_512x512_map_in_the_scene_range() {
    let gt = read_pfm(&hci("antinous").join("gt_disp_lowres.pfm")).unwrap();
    assert_eq!((gt.width, gt.height, gt.channels), (512, 512, 1));
    assert!(gt.data.iter().all(|v| v.is_finite() && (-3.5..3.0).contains(v)));
    // Bottom-first storage: the rows read back top-first must match the file read by hand.
    let bytes = std::fs::read(hci("antinous").join("gt_disp_lowres.pfm")).unwrap();
    let data = &bytes[bytes.len() - 512 * 512 * 4..];
    let first_stored = f32::from_le_bytes(data[..4].try_into().unwrap());
    assert_eq!(gt.get(0, 511, 0).to_bits(), first_stored.to_bits());
}

#[test]
fn pfm_round_trips_hci_ground_truth_bit_exactly() {
    let dir = common::tempdir();
    let gt = read_pfm(&hci("antinous").join("gt_disp_lowres.pfm")).unwrap();
    let path = dir.path().join("copy.pfm");
    rslf::io::write_pfm(&path, &gt).unwrap();
    let back = read_pfm(&path).unwrap();
    assert_eq!(back.data.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), gt.data.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
    assert_eq!(std::fs::read(&path).unwrap(), std::fs::read(hci("antinous").join("gt_disp_lowres.pfm")).unwrap());
}

#[test]
fn eval_of_antinous_ground_truth_against_itself_is_perfect() {
    let scene = hci("antinous");
    let result = common::tempdir();
    std::fs::copy(scene.join("gt_disp_lowres.pfm"), result.path().join("disparity.pfm")).unwrap();
    let (ok, stdout, stderr) = rslf(&["eval", "--scene", scene.to_str().unwrap(), "--result", result.path().to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("MSE x100 0.0000"), "{stdout}");
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(result.path().join("metrics.json")).unwrap()).unwrap();
    let disp = &json["disparity"];
    assert_eq!(disp["mse_x100"], 0.0);
    assert_eq!(disp["pixels"], (512 - 30) * (512 - 30));
    for entry in disp["badpix_percent"].as_array().unwrap() {
        assert_eq!(entry[1], 0.0, "{entry}");
    }
    assert!(json["depth"].is_null(), "antinous has no parameters.cfg: no depth");
}

/// Reads the central view where the central-view disparity at a corner pixel says that pixel
/// came from; the mean colour error at the pixels `explained_mask` keeps and at those it leaves out.
fn backward_warp_errors(scene: &Scene, gt: &rslf::io::Raster, view: ViewId, mask: &rslf::io::Raster) -> (f64, f64) {
    let (central, img) = (scene.central(), scene.view(view).unwrap());
    let (dx, dy) = scene.grid.offset(view);
    let mut sums = [(0.0f64, 0usize); 2];
    for y in 0..img.height {
        for x in 0..img.width {
            let d = gt.get(x, y, 0) as f64;
            let (xs, ys) = (x as f64 + dx * d, y as f64 + dy * d);
            for ch in 0..img.channels {
                if let Some(s) = central.sample_bilinear(xs as f32, ys as f32, ch) {
                    let slot = &mut sums[(mask.get(x, y, 0) == 1.0) as usize];
                    slot.0 += (s - img.get(x, y, ch)).abs() as f64;
                    slot.1 += 1;
                }
            }
        }
    }
    (sums[1].0 / sums[1].1 as f64, sums[0].0 / sums[0].1.max(1) as f64)
}

#[test]
fn the_disocclusion_mask_of_antinous_corners_leaves_out_what_the_central_view_does_not_see() {
    let dir = hci("antinous");
    let scene = Scene::load(&dir).unwrap();
    let gt = read_pfm(&dir.join("gt_disp_lowres.pfm")).unwrap();
    for view in scene.grid.corners() {
        let mask = rslf::pipeline::explained_mask(&gt, scene.grid.offset(view), 1, BorderStrips::LeftOut);
        let kept = mask.data.iter().sum::<f32>() / mask.data.len() as f32;
        assert!((0.9..0.999).contains(&kept), "view {view:?}: {kept} kept");
        let (kept_error, left_out_error) = backward_warp_errors(&scene, &gt, view, &mask);
        assert!(left_out_error > 8.0 * kept_error, "view {view:?}: error {kept_error} kept vs {left_out_error} left out");
    }
}

#[test]
fn stage_2_takes_cottons_corners_and_without_them_the_outermost_views_of_each_quadrant() {
    use rslf::config::ViewSelection::{AllOffRow, Corners, Diagonals};
    use rslf::pipeline::stage2_views;
    let source = hci("cotton");
    let scene = Scene::load(&source).unwrap();
    assert_eq!(stage2_views(&scene, Corners), scene.grid.corners().to_vec());
    assert_eq!(stage2_views(&scene, AllOffRow).len(), 24, "33 views less the 9 of the central row");
    // HCI's 33 views hold, off the central row and column, the two diagonals and nothing else.
    let off_column: Vec<ViewId> = stage2_views(&scene, AllOffRow).into_iter().filter(|v| v.col != 4).collect();
    assert_eq!(stage2_views(&scene, Diagonals), off_column);
    assert_eq!(off_column.len(), 16);
    // Cotton copied without some of its views: `keep(row, col)` says which stay.
    let without = |keep: &dyn Fn(usize, usize) -> bool| {
        let dir = common::tempdir();
        for entry in std::fs::read_dir(&source).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_str().unwrap().to_string();
            let index = name.strip_prefix("input_Cam").and_then(|n| n.strip_suffix(".png")).map(|n| n.parse::<usize>().unwrap());
            if index.is_none_or(|i| keep(i / 9, i % 9)) {
                std::fs::copy(&path, dir.path().join(&name)).unwrap();
            }
        }
        let scene = Scene::load(dir.path()).unwrap();
        (dir, scene)
    };
    let v = |row, col| ViewId { row, col };
    // Without the corners (as a plenoptic camera's vignetted corner views often are), the next
    // views along its diagonals stand in.
    let (_dir, cornerless) = without(&|r, c| !((r == 0 || r == 8) && (c == 0 || c == 8)));
    assert_eq!(cornerless.present_views().len(), 29);
    assert_eq!(stage2_views(&cornerless, Corners), vec![v(1, 1), v(1, 7), v(7, 1), v(7, 7)]);
    // The central row and column alone: no view in any quadrant, so the column's eight are taken.
    let (_dir, cross) = without(&|r, c| r == 4 || c == 4);
    let column = (0..9).filter(|&r| r != 4).map(|r| v(r, 4)).collect::<Vec<_>>();
    assert_eq!(stage2_views(&cross, Corners), column);
    assert_eq!(stage2_views(&cross, Diagonals), column);
}
