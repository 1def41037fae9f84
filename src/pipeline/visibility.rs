//! Which pixels of a view the scene model can explain: those that show a surface the central
//! view also sees. Elsewhere (background disoccluded by a foreground edge, a strip entering at
//! the image border) the Gaussians, sampled on the central view, hold nothing to render, and a
//! fit would bend the motion to shrink those residuals.

use crate::geometry::{Camera, ViewId, pose_at, readout_interval, rs_project};
use crate::io::{MotionRecord, Raster};
use crate::render::RenderOutput;
use burn::tensor::Tensor;

/// A `0/1` mask of the view at `offset = (c - cc, r - rc)` of a capture without motion: 1 where
/// some central-view pixel of `disparity` lands (forward warp to `(x - dx d, y - dy d)`, onto the
/// pixels around the landing point: its floor and ceiling in each axis), 0 at the pixels no
/// central pixel reaches and within `margin` pixels of one; the strips at the border as `border`
/// says.
pub fn explained_mask(disparity: &Raster, offset: (f64, f64), margin: usize, border: BorderStrips) -> Raster {
    let (dx, dy) = offset;
    mask_of_landings(disparity, margin, border, |x, y, d| Some((x - dx * d, y - dy * d)))
}

/// As [`explained_mask`], for `view` of a rolling-shutter capture under `motion`: each central
/// pixel, seen at the read-out time of its row, is lifted with its disparity, moved back to
/// t = 0 and re-imaged into `view` at the read-out time of the row it lands on. Where the motion
/// shears the scene the uncovered background moves with it; without motion this is
/// [`explained_mask`].
pub fn explained_mask_moving(
    disparity: &Raster,
    camera: &Camera,
    view: ViewId,
    motion: &MotionRecord,
    margin: usize,
    border: BorderStrips,
) -> Raster {
    let readout = readout_interval(camera.height, camera.line_time_s);
    mask_of_landings(disparity, margin, border, |x, y, d| {
        let z = camera.disparity_to_depth(d);
        if !(z.is_finite() && z > 0.0) {
            return None;
        }
        let observed = camera.back_project(x, y, z);
        let at_zero = pose_at(motion, camera.row_time(y), readout).inverse().apply(&observed);
        rs_project(camera, motion, view, &at_zero).map(|(u, v, _)| (u, v))
    })
}

/// Whether the strips a view brings in at the image border count as explained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BorderStrips {
    /// Left out, as what no central pixel reaches.
    LeftOut,
    /// Explained: the scene is taken to continue past the border as its border row or column
    /// does ([`BORDER_CONTINUATION_PX`]), so only what a foreground uncovers is left out.
    Explained,
}

/// How far past each border of the central view the scene is continued (pixels), each pixel
/// there with the disparity of the nearest border pixel, where the border strips count as
/// explained: wider than the strip four grid steps bring in at a disparity of 4 px, with a
/// motion's shift on top.
pub const BORDER_CONTINUATION_PX: isize = 32;

/// The mask of the pixels around where `landing(x, y, d)` puts each pixel `(x, y)` of disparity
/// `d` (finite) of the central view, continued past its borders where `border` says, with the
/// unreached pixels widened by `margin`.
fn mask_of_landings(
    disparity: &Raster,
    margin: usize,
    border: BorderStrips,
    landing: impl Fn(f64, f64, f64) -> Option<(f64, f64)>,
) -> Raster {
    let (w, h) = (disparity.width, disparity.height);
    if w == 0 || h == 0 {
        return Raster { width: w, height: h, channels: 1, data: Vec::new() };
    }
    let mut reached = vec![false; w * h];
    let pad = match border {
        BorderStrips::LeftOut => 0,
        BorderStrips::Explained => BORDER_CONTINUATION_PX,
    };
    for y in -pad..h as isize + pad {
        for x in -pad..w as isize + pad {
            let (cx, cy) = (x.clamp(0, w as isize - 1) as usize, y.clamp(0, h as isize - 1) as usize);
            let d = disparity.data[(cy * w + cx) * disparity.channels] as f64;
            let Some((px, py)) = d.is_finite().then(|| landing(x as f64, y as f64, d)).flatten() else { continue };
            for (xi, yi) in [(px.floor(), py.floor()), (px.ceil(), py.floor()), (px.floor(), py.ceil()), (px.ceil(), py.ceil())] {
                if xi >= 0.0 && yi >= 0.0 && (xi as usize) < w && (yi as usize) < h {
                    reached[yi as usize * w + xi as usize] = true;
                }
            }
        }
    }
    let m = margin as isize;
    let mut data = vec![1.0f32; w * h];
    for y in 0..h as isize {
        for x in 0..w as isize {
            if reached[y as usize * w + x as usize] {
                continue;
            }
            for yy in (y - m).max(0)..=(y + m).min(h as isize - 1) {
                for xx in (x - m).max(0)..=(x + m).min(w as isize - 1) {
                    data[yy as usize * w + xx as usize] = 0.0;
                }
            }
        }
    }
    Raster { width: w, height: h, channels: 1, data }
}

/// A band's render and target with both colours multiplied by `mask` (`[P, 1]`): where it is 0
/// every photometric term sees no difference, where it is in (0, 1) a proportionally smaller
/// one. Opacity and disparity are kept: they are the model's own, not compared with the view.
pub fn masked(rendered: RenderOutput, target: Tensor<2>, mask: Tensor<2>) -> (RenderOutput, Tensor<2>) {
    let colour = rendered.colour * mask.clone();
    (RenderOutput { colour, ..rendered }, target * mask)
}

#[cfg(test)]
mod tests {
    use super::BorderStrips::{Explained, LeftOut};
    use super::*;

    fn left_out(mask: &Raster) -> usize {
        mask.data.iter().filter(|&&m| m == 0.0).count()
    }

    fn camera() -> Camera {
        // b f = 2 px m: disparity 1 is a depth of 1.2 m; a row is read every millisecond.
        let grid = crate::geometry::ViewGrid { rows: 9, cols: 9 };
        Camera { grid, width: 40, height: 30, f_px: 100.0, baseline_m: 0.02, focus_m: 3.0, line_time_s: 1e-3 }
    }

    #[test]
    fn without_motion_the_moving_mask_is_the_static_one() {
        let cam = camera();
        let disparity =
            Raster::from_fn(40, 30, |x, y| if (10..22).contains(&x) && (8..20).contains(&y) { 1.3 } else { 0.1 + 0.01 * x as f32 });
        let view = ViewId { row: 8, col: 1 };
        let (dx, dy) = cam.grid.offset(view);
        let moving = explained_mask_moving(&disparity, &cam, view, &MotionRecord::zero(), 1, LeftOut);
        let fixed = explained_mask(&disparity, (dx, dy), 1, LeftOut);
        assert!(left_out(&fixed) > 100, "the test map must uncover something");
        assert_eq!(moving.data, fixed.data);
    }

    #[test]
    fn a_sideways_motion_opens_a_strip_on_the_side_the_later_rows_slide_away_from() {
        // A plane of disparity 0.9, seen from the top-centre view (dy = -4): each point lands
        // 3.6 rows lower, read 3.6 ms later, by which time a velocity v along x has carried it
        // f v 3.6 ms / z to the right: 3.5 px for the v set here. Rows 0-2 and columns 0-2 are
        // left uncovered; with the border strips explained, the plane continued past the border
        // reaches them.
        let cam = camera();
        let disparity = Raster::from_fn(40, 30, |_, _| 0.9);
        let v = 3.5 * cam.disparity_to_depth(0.9) / (cam.f_px * 3.6 * cam.line_time_s);
        let motion = MotionRecord::ConstantVelocity { omega_rad_s: [0.0; 3], velocity_m_s: [v, 0.0, 0.0] };
        let mask = explained_mask_moving(&disparity, &cam, ViewId { row: 0, col: 4 }, &motion, 0, LeftOut);
        for y in 0..30 {
            let row = &mask.data[y * 40..(y + 1) * 40];
            let expected = |x: usize| if y < 3 || x < 3 { 0.0 } else { 1.0 };
            assert!((0..40).all(|x| row[x] == expected(x)), "row {y}: {row:?}");
        }
        let mask = explained_mask_moving(&disparity, &cam, ViewId { row: 0, col: 4 }, &motion, 2, Explained);
        assert_eq!(left_out(&mask), 0, "{:?}", &mask.data[..40]);
    }

    #[test]
    fn a_foreground_square_outrunning_its_background_under_a_sideways_motion_uncovers_a_strip_beside_it() {
        // A square of disparity 1.6 (1.25 m) before a plane of 0.9 (2.2 m), seen from the
        // top-centre view (dy = -4): the plane lands 3.6 rows lower and the square 6.4, read
        // that much later. Moving along x at the speed that carries the plane 1 px in 3.6 ms,
        // the camera carries the nearer, later-read square further: its left edge (column 12)
        // lands to the right of the plane beside it (column 11), and between them, in the rows
        // the square lands on, is what no central pixel sees. Without the motion both keep
        // their columns and nothing there is left out.
        let cam = camera();
        let disparity = Raster::from_fn(40, 30, |x, y| if (12..24).contains(&x) && (10..20).contains(&y) { 1.6 } else { 0.9 });
        let view = ViewId { row: 0, col: 4 };
        let v = cam.disparity_to_depth(0.9) / (cam.f_px * 3.6 * cam.line_time_s);
        let motion = MotionRecord::ConstantVelocity { omega_rad_s: [0.0; 3], velocity_m_s: [v, 0.0, 0.0] };
        let still = explained_mask_moving(&disparity, &cam, view, &MotionRecord::zero(), 0, Explained);
        let moving = explained_mask_moving(&disparity, &cam, view, &motion, 0, Explained);
        // Per row the square lands on, the left-out pixels beside its left edge.
        let beside = |mask: &Raster| (17..=22).map(|y| (11..=16).filter(|&x| mask.data[y * 40 + x] == 0.0).count()).collect::<Vec<_>>();
        assert!(beside(&moving).iter().all(|&n| n >= 1), "{:?}", beside(&moving));
        assert!(beside(&still).iter().all(|&n| n == 0), "{:?}", beside(&still));
        let near_border =
            |mask: &Raster| (0..mask.data.len()).any(|i| mask.data[i] == 0.0 && (i % 40 < 3 || i % 40 > 36 || i / 40 < 3 || i / 40 > 26));
        assert!(!near_border(&still) && !near_border(&moving), "nothing is left out at the border");
    }

    #[test]
    fn the_central_view_itself_keeps_every_pixel() {
        let disparity = Raster::from_fn(32, 24, |x, y| 0.1 * x as f32 - 0.05 * y as f32);
        assert_eq!(left_out(&explained_mask(&disparity, (0.0, 0.0), 3, LeftOut)), 0);
    }

    #[test]
    fn a_view_beside_the_central_one_leaves_out_the_strip_entering_at_its_border() {
        // A plane of disparity 1 seen 4 views to the left (dx = -4) lands 4 px further right.
        let disparity = Raster::from_fn(40, 10, |_, _| 1.0);
        let mask = explained_mask(&disparity, (-4.0, 0.0), 0, LeftOut);
        for y in 0..10 {
            let row = &mask.data[y * 40..(y + 1) * 40];
            assert!(row[..4].iter().all(|&m| m == 0.0) && row[4..].iter().all(|&m| m == 1.0), "row {y}: {row:?}");
        }
        assert_eq!(left_out(&explained_mask(&disparity, (-4.0, 0.0), 1, LeftOut)), 5 * 10, "a margin of 1 widens the strip to 5");
        // Seen from the right the strip is on the right.
        let mask = explained_mask(&disparity, (4.0, 0.0), 0, LeftOut);
        assert!(mask.data[..40].iter().enumerate().all(|(x, &m)| (m == 0.0) == (x >= 36)));
    }

    #[test]
    fn a_view_beside_the_central_one_keeps_the_strip_entering_at_its_border() {
        // A plane of disparity 1 seen 4 views to the left (dx = -4) lands 4 px further right:
        // its first 4 columns are reached by the plane continued past the left border.
        let disparity = Raster::from_fn(40, 10, |_, _| 1.0);
        for offset in [(-4.0, 0.0), (4.0, 0.0), (0.0, 4.0), (-4.0, -4.0)] {
            assert_eq!(left_out(&explained_mask(&disparity, offset, 1, Explained)), 0, "{offset:?}");
        }
    }

    #[test]
    fn a_foreground_square_uncovers_background_on_the_side_it_moves_away_from() {
        // A square of disparity 2 before a background of disparity 0, seen from the top-left
        // corner (dx = dy = -4): it moves 8 px right and down; the background behind its old
        // top-left part is what no central pixel shows.
        let disparity = Raster::from_fn(48, 48, |x, y| if (15..25).contains(&x) && (15..25).contains(&y) { 2.0 } else { 0.0 });
        let mask = explained_mask(&disparity, (-4.0, -4.0), 0, LeftOut);
        let at = |x: usize, y: usize| mask.data[y * 48 + x];
        assert_eq!(at(19, 19), 0.0, "uncovered background");
        assert_eq!(at(28, 28), 1.0, "the square where it moved");
        assert_eq!((at(5, 40), at(40, 5), at(40, 40)), (1.0, 1.0, 1.0), "background far from the square");
        // Nothing on the far side of the square is left out.
        assert!((0..48).all(|y| (33..48).all(|x| at(x, y) == 1.0)));
        let hole = left_out(&mask);
        assert_eq!(hole, 10 * 10 - 2 * 2, "the square's old place, less what its new place overlaps");
    }
}
