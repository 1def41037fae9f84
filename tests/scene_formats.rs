//! Scene folders in every form FORMAT allows: 8/16-bit, grey/RGB(A) PNG, EXR, missing views.

mod common;

use common::{params, write_plane_scene};
use rslf::geometry::{ViewGrid, ViewId};
use rslf::io::{Scene, read_image};

#[test]
fn png_bit_depths_and_channels_are_scaled_to_unit_range() {
    let dir = common::tempdir();
    let p = |n: &str| dir.path().join(n);
    image::GrayImage::from_fn(3, 2, |x, _| image::Luma([(x * 127) as u8])).save(p("g8.png")).unwrap();
    image::ImageBuffer::<image::Luma<u16>, _>::from_fn(3, 2, |x, _| image::Luma([(x * 32767) as u16])).save(p("g16.png")).unwrap();
    image::RgbaImage::from_fn(3, 2, |_, y| image::Rgba([255, 0, (y * 255) as u8, 7])).save(p("rgba8.png")).unwrap();
    image::ImageBuffer::<image::Rgb<u16>, _>::from_fn(3, 2, |_, _| image::Rgb([65535u16, 0, 32768])).save(p("rgb16.png")).unwrap();

    let g8 = read_image(&p("g8.png")).unwrap();
    assert_eq!((g8.width, g8.height, g8.channels), (3, 2, 1));
    assert!((g8.get(1, 0, 0) - 127.0 / 255.0).abs() < 1e-6);
    let g16 = read_image(&p("g16.png")).unwrap();
    assert!((g16.get(2, 1, 0) - 65534.0 / 65535.0).abs() < 1e-6);
    let rgba = read_image(&p("rgba8.png")).unwrap();
    assert_eq!(rgba.channels, 3, "alpha is dropped");
    assert_eq!((rgba.get(0, 1, 0), rgba.get(0, 1, 1), rgba.get(0, 1, 2)), (1.0, 0.0, 1.0));
    let rgb16 = read_image(&p("rgb16.png")).unwrap();
    assert!((rgb16.get(0, 0, 2) - 32768.0 / 65535.0).abs() < 1e-7);
}

#[test]
fn exr_views_keep_their_linear_values() {
    let dir = common::tempdir();
    let path = dir.path().join("input_Cam000.exr");
    exr::prelude::write_rgb_file(&path, 4, 3, |x, y| (x as f32 * 2.5, y as f32, -0.25f32)).unwrap();
    let img = read_image(&path).unwrap();
    assert_eq!((img.width, img.height, img.channels), (4, 3, 3));
    assert_eq!((img.get(3, 2, 0), img.get(3, 2, 1), img.get(3, 2, 2)), (7.5, 2.0, -0.25));
}

#[test]
fn a_scene_of_exr_views_loads_like_png() {
    let dir = common::tempdir();
    for i in 0..9 {
        let v = i as f32;
        exr::prelude::write_rgb_file(dir.path().join(format!("input_Cam{i:03}.exr")), 5, 4, |_, _| (v, v, v)).unwrap();
    }
    let scene = Scene::load(dir.path()).unwrap();
    assert_eq!(scene.grid, ViewGrid { rows: 3, cols: 3 });
    assert_eq!(scene.central().get(0, 0, 0), 4.0);
}

#[test]
fn missing_views_are_left_empty_and_the_rest_used() {
    let dir = common::tempdir();
    // The 33-view pattern of HCI's cotton on a 5x5 grid: central row, column and diagonals.
    let keep = |i: usize| {
        let (r, c) = (i / 5, i % 5);
        r == 2 || c == 2 || r == c || r + c == 4
    };
    write_plane_scene(dir.path(), 16, 12, 5, 0.5, keep);
    params(16, 12, 5).write(&dir.path().join("parameters.cfg")).unwrap();
    let scene = Scene::load(dir.path()).unwrap();
    assert_eq!(scene.present_views().len(), 17);
    assert_eq!(scene.central_row_views().len(), 5);
    assert!(scene.view(ViewId { row: 0, col: 1 }).is_none());
    assert!(scene.view(ViewId { row: 4, col: 4 }).is_some());
}

#[test]
fn without_parameters_the_grid_is_the_smallest_square_holding_every_view() {
    let dir = common::tempdir();
    write_plane_scene(dir.path(), 8, 8, 5, 0.0, |i| i == 12 || i == 24);
    let scene = Scene::load(dir.path()).unwrap();
    assert_eq!(scene.grid, ViewGrid { rows: 5, cols: 5 });
    assert!(scene.camera().is_none());
}

#[test]
fn a_view_outside_the_configured_grid_is_refused() {
    let dir = common::tempdir();
    write_plane_scene(dir.path(), 8, 8, 5, 0.0, |i| i == 4 || i == 12);
    params(8, 8, 3).write(&dir.path().join("parameters.cfg")).unwrap();
    let err = Scene::load(dir.path()).unwrap_err();
    assert!(err.path.ends_with("input_Cam012.png"), "{err}");
    assert!(err.problem.contains("outside the 3x3 grid"), "{err}");
}

#[test]
fn grey_and_rgb_views_cannot_be_mixed() {
    let dir = common::tempdir();
    write_plane_scene(dir.path(), 8, 8, 3, 0.0, |_| true);
    rslf::io::write_png(&dir.path().join("input_Cam007.png"), &rslf::io::Raster::zeros(8, 8, 1)).unwrap();
    let err = Scene::load(dir.path()).unwrap_err();
    assert!(err.to_string().contains("input_Cam007.png: view has 1 channels but the central view has 3"), "{err}");
}
