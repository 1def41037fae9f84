//! Which pixels of an off-row view carry a motion cue that no disparity error can imitate.
//!
//! A point of disparity `d` seen in the view at offset `(a, b)` from the central one sits `(a d,
//! b d)` away from its central image and, being on a row `b d` rows away, is read `b d` line
//! times later: to first order the motion adds `b d t_line f` (`f` the image velocity there). A
//! disparity error `e` adds `(a e, b e)`. Horizontally the two differ (`a` against `b`: over the
//! four corners they are orthogonal patterns), but vertically both are `b` times a number:
//! vertical image motion is indistinguishable from a disparity error, unless the disparity is
//! pinned by the central row, which sees it only through horizontal intensity changes. At a
//! horizontal edge the row sees nothing, the fitted disparity is free, and the off-row residual
//! there measures the disparity error, not the motion. [`aperture_weights`] weighs each pixel by
//! the share of its local gradient energy that is horizontal: ~0 on horizontal edges, ~1 on
//! vertical ones, ~1/2 on texture.

use super::box_filter::window_sums;
use crate::io::Raster;

/// Per-pixel weights in `[0, 1]` of `image`: `(Sxx + eps/2) / (Sxx + Syy + eps)`, with `Sxx` and
/// `Syy` the squared horizontal and vertical central differences of its luminance, summed over a
/// `(2 radius + 1)²` window; flat regions get 1/2.
pub fn aperture_weights(image: &Raster, radius: usize, eps: f32) -> Raster {
    let grey = image.to_grey();
    let (w, h) = (grey.width, grey.height);
    let at = |x: usize, y: usize| grey.data[y * w + x];
    let mut gxx = vec![0.0f32; w * h];
    let mut gyy = vec![0.0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let gx = 0.5 * (at((x + 1).min(w - 1), y) - at(x.saturating_sub(1), y));
            let gy = 0.5 * (at(x, (y + 1).min(h - 1)) - at(x, y.saturating_sub(1)));
            gxx[y * w + x] = gx * gx;
            gyy[y * w + x] = gy * gy;
        }
    }
    let (sxx, syy) = (window_sums(&gxx, w, h, radius), window_sums(&gyy, w, h, radius));
    let data = sxx.iter().zip(&syy).map(|(&(a, _), &(b, _))| (a + 0.5 * eps) / (a + b + eps)).collect();
    Raster { width: w, height: h, channels: 1, data }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(r: &Raster, x: usize, y: usize) -> f32 {
        r.data[y * r.width + x]
    }

    #[test]
    fn horizontal_edges_weigh_nothing_vertical_edges_everything_flat_and_texture_half() {
        let eps = 1e-4;
        // Stripes 4 px wide: horizontal ones vary along y only, vertical ones along x only.
        let horizontal = aperture_weights(&Raster::from_fn(32, 32, |_, y| ((y / 4) % 2) as f32), 2, eps);
        let vertical = aperture_weights(&Raster::from_fn(32, 32, |x, _| ((x / 4) % 2) as f32), 2, eps);
        let flat = aperture_weights(&Raster::from_fn(32, 32, |_, _| 0.3), 2, eps);
        let checker = aperture_weights(&Raster::from_fn(32, 32, |x, y| ((x / 4 + y / 4) % 2) as f32), 2, eps);
        for (x, y) in [(10, 8), (16, 16), (20, 11)] {
            assert!(at(&horizontal, x, y) < 1e-3, "horizontal edge at ({x}, {y}): {}", at(&horizontal, x, y));
            assert!(at(&vertical, x, y) > 0.999, "vertical edge at ({x}, {y}): {}", at(&vertical, x, y));
            assert!((at(&flat, x, y) - 0.5).abs() < 1e-6);
        }
        // The checkerboard is symmetric under swapping x and y, so on the diagonal both
        // gradients weigh the same.
        for k in [10, 13, 16, 21] {
            assert!((at(&checker, k, k) - 0.5).abs() < 1e-4, "texture at ({k}, {k}): {}", at(&checker, k, k));
        }
    }

    #[test]
    fn colour_is_weighed_by_its_luminance() {
        let grey = Raster::from_fn(16, 16, |x, y| ((x + 2 * y) % 5) as f32 / 5.0);
        let rgb = Raster { width: 16, height: 16, channels: 3, data: grey.data.iter().flat_map(|&v| [v, v, v]).collect() };
        let (a, b) = (aperture_weights(&grey, 1, 1e-4), aperture_weights(&rgb, 1, 1e-4));
        assert!(a.data.iter().zip(&b.data).all(|(p, q)| (p - q).abs() < 1e-5));
    }
}
