//! The discrete bookkeeping of the renderer, outside autodiff: for each pixel of a band of rows,
//! the K nearest Gaussians (largest disparity first) whose footprint covers it.

use super::RenderSettings;
use std::ops::Range;

/// The per-pixel Gaussian lists of one band of one view.
#[derive(Debug, Clone, PartialEq)]
pub struct PixelBins {
    /// Image width, pixels.
    pub width: usize,
    /// The rows of the band.
    pub rows: Range<usize>,
    /// Slots per pixel.
    pub k: usize,
    /// `rows.len() * width * k` Gaussian indices, front to back; 0 in empty slots.
    pub indices: Vec<i64>,
    /// 1 for a used slot, 0 for an empty one, same layout.
    pub valid: Vec<f32>,
}

impl PixelBins {
    /// Number of pixels in the band.
    pub fn pixels(&self) -> usize {
        self.rows.len() * self.width
    }

    /// Fraction of pixels whose K slots are all used (some Gaussians behind were dropped).
    pub fn saturated_fraction(&self) -> f64 {
        let full = self.valid.chunks_exact(self.k).filter(|s| s[self.k - 1] > 0.0).count();
        full as f64 / self.pixels().max(1) as f64
    }
}

/// Bins Gaussians with (view-shifted) centres `(u, v)`, disparities `d` and sizes `sigma` over
/// `rows` of an image `width` wide. A Gaussian covers the pixels within `settings.cutoff_sigma`
/// sizes of its centre. Each pixel keeps the `settings.max_per_pixel` front-most (largest
/// disparity; ties by index).
pub fn bin(u: &[f32], v: &[f32], d: &[f32], sigma: &[f32], width: usize, rows: Range<usize>, settings: &RenderSettings) -> PixelBins {
    let (k, cutoff) = (settings.max_per_pixel, settings.cutoff_sigma);
    let p = rows.len() * width;
    let mut indices = vec![0i64; p * k];
    let mut valid = vec![0.0f32; p * k];
    let mut count = vec![0u16; p];
    let mut order: Vec<usize> = (0..u.len()).collect();
    order.sort_by(|&a, &b| d[b].total_cmp(&d[a]).then(a.cmp(&b)));
    let (y_lo, y_hi) = (rows.start as f32, rows.end as f32 - 1.0);
    for i in order {
        let r = (cutoff * sigma[i]).max(0.5);
        let (cu, cv) = (u[i], v[i]);
        if !(cu.is_finite() && cv.is_finite() && r.is_finite()) || cv + r < y_lo || cv - r > y_hi {
            continue;
        }
        let x0 = (cu - r).ceil().max(0.0) as usize;
        let x1 = ((cu + r).floor()).min(width as f32 - 1.0);
        let y0 = (cv - r).ceil().max(y_lo) as usize;
        let y1 = (cv + r).floor().min(y_hi);
        if x1 < 0.0 || y1 < 0.0 {
            continue;
        }
        let (x1, y1) = (x1 as usize, y1 as usize);
        let r2 = r * r;
        for y in y0..=y1 {
            let dy = y as f32 - cv;
            for x in x0..=x1 {
                let dx = x as f32 - cu;
                if dx * dx + dy * dy > r2 {
                    continue;
                }
                let px = (y - rows.start) * width + x;
                let c = count[px] as usize;
                if c < k {
                    indices[px * k + c] = i as i64;
                    valid[px * k + c] = 1.0;
                    count[px] += 1;
                }
            }
        }
    }
    PixelBins { width, rows, k, indices, valid }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_keep_the_front_most_gaussians_in_depth_order() {
        // Three Gaussians over pixel (2, 1); the far one is dropped with k = 2.
        let (u, v) = ([2.0, 2.2, 1.8], [1.0, 1.1, 0.9]);
        let d = [0.5, 2.0, 1.0];
        let bins = bin(&u, &v, &d, &[1.0; 3], 5, 0..3, &RenderSettings { max_per_pixel: 2, cutoff_sigma: 3.0 });
        let px = 5 + 2; // row 1, column 2
        assert_eq!(&bins.indices[px * 2..px * 2 + 2], &[1, 2]);
        assert_eq!(&bins.valid[px * 2..px * 2 + 2], &[1.0, 1.0]);
        assert!(bins.saturated_fraction() > 0.9);
    }

    #[test]
    fn footprints_are_cut_off_and_bands_are_offset() {
        let bins = bin(&[10.0], &[10.0], &[0.0], &[1.0], 20, 8..12, &RenderSettings { max_per_pixel: 4, cutoff_sigma: 2.0 });
        let at = |x: usize, y: usize| bins.valid[((y - 8) * 20 + x) * 4];
        assert_eq!(at(10, 10), 1.0);
        assert_eq!(at(12, 10), 1.0); // distance 2 = cutoff
        assert_eq!(at(12, 11), 0.0); // distance sqrt(5) > 2
        assert_eq!(at(10, 8), 1.0);
        assert_eq!(bins.pixels(), 80);
    }
}
