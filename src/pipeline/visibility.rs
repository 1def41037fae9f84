//! Which pixels of a view the scene model can explain: those that show a surface the central
//! view also sees. Elsewhere (background disoccluded by a foreground edge, a strip entering at
//! the image border) the Gaussians, sampled on the central view, hold nothing to render, and a
//! fit would bend the motion to shrink those residuals.

use crate::io::Raster;
use crate::render::RenderOutput;
use burn::tensor::Tensor;

/// A `0/1` mask of the view at `offset = (c - cc, r - rc)`: 1 where some central-view pixel of
/// `disparity` lands (forward warp to `(x - dx d, y - dy d)`, onto the pixels around the landing
/// point: its floor and ceiling in each axis), 0 at the pixels no central pixel reaches and
/// within `margin` pixels of one.
pub fn explained_mask(disparity: &Raster, offset: (f64, f64), margin: usize) -> Raster {
    let (w, h) = (disparity.width, disparity.height);
    let (dx, dy) = offset;
    let mut reached = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            let d = disparity.data[(y * w + x) * disparity.channels] as f64;
            if !d.is_finite() {
                continue;
            }
            let (px, py) = (x as f64 - dx * d, y as f64 - dy * d);
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

/// A band's render and target with the pixels `mask` (`[P, 1]`, 0 or 1) leaves out set to zero
/// in both colours, so that every photometric term sees no difference there. Opacity and
/// disparity are kept: they are the model's own, not compared with the view.
pub fn masked(rendered: RenderOutput, target: Tensor<2>, mask: Tensor<2>) -> (RenderOutput, Tensor<2>) {
    let colour = rendered.colour * mask.clone();
    (RenderOutput { colour, ..rendered }, target * mask)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(w: usize, h: usize, d: impl Fn(usize, usize) -> f32) -> Raster {
        Raster { width: w, height: h, channels: 1, data: (0..w * h).map(|i| d(i % w, i / w)).collect() }
    }

    fn left_out(mask: &Raster) -> usize {
        mask.data.iter().filter(|&&m| m == 0.0).count()
    }

    #[test]
    fn the_central_view_itself_keeps_every_pixel() {
        let disparity = map(32, 24, |x, y| 0.1 * x as f32 - 0.05 * y as f32);
        assert_eq!(left_out(&explained_mask(&disparity, (0.0, 0.0), 3)), 0);
    }

    #[test]
    fn a_view_beside_the_central_one_leaves_out_the_strip_entering_at_its_border() {
        // A plane of disparity 1 seen 4 views to the left (dx = -4) lands 4 px further right.
        let disparity = map(40, 10, |_, _| 1.0);
        let mask = explained_mask(&disparity, (-4.0, 0.0), 0);
        for y in 0..10 {
            let row = &mask.data[y * 40..(y + 1) * 40];
            assert!(row[..4].iter().all(|&m| m == 0.0) && row[4..].iter().all(|&m| m == 1.0), "row {y}: {row:?}");
        }
        assert_eq!(left_out(&explained_mask(&disparity, (-4.0, 0.0), 1)), 5 * 10, "a margin of 1 widens the strip to 5");
        // Seen from the right the strip is on the right.
        let mask = explained_mask(&disparity, (4.0, 0.0), 0);
        assert!(mask.data[..40].iter().enumerate().all(|(x, &m)| (m == 0.0) == (x >= 36)));
    }

    #[test]
    fn a_foreground_square_uncovers_background_on_the_side_it_moves_away_from() {
        // A square of disparity 2 before a background of disparity 0, seen from the top-left
        // corner (dx = dy = -4): it moves 8 px right and down; the background behind its old
        // top-left part is what no central pixel shows.
        let disparity = map(48, 48, |x, y| if (15..25).contains(&x) && (15..25).contains(&y) { 2.0 } else { 0.0 });
        let mask = explained_mask(&disparity, (-4.0, -4.0), 0);
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
