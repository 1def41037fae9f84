//! Sums and means over the square window around each pixel of a map, clipped at its borders;
//! non-finite entries (unseen pixels) are left out.

use rayon::prelude::*;

/// For each pixel of `src` (`w x h`), the sum and the count of the finite entries in the
/// `(2r+1)^2` window around it, clipped at the borders. Separable: rows, then columns.
pub fn window_sums(src: &[f32], w: usize, h: usize, r: usize) -> Vec<(f32, u32)> {
    let mut rows = vec![(0.0f32, 0u32); w * h];
    rows.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let (lo, hi) = (x.saturating_sub(r), (x + r).min(w - 1));
            let (mut s, mut n) = (0.0, 0);
            for v in &src[y * w + lo..=y * w + hi] {
                if v.is_finite() {
                    s += v;
                    n += 1;
                }
            }
            *o = (s, n);
        }
    });
    let mut out = vec![(0.0f32, 0u32); w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let (lo, hi) = (y.saturating_sub(r), (y + r).min(h - 1));
        for (x, o) in row.iter_mut().enumerate() {
            let (mut s, mut n) = (0.0, 0);
            for yy in lo..=hi {
                let (a, b) = rows[yy * w + x];
                s += a;
                n += b;
            }
            *o = (s, n);
        }
    });
    out
}

/// Mean over the `(2r+1)^2` window, ignoring non-finite entries (`INFINITY` if none is finite).
pub fn box_mean(src: &[f32], w: usize, h: usize, r: usize) -> Vec<f32> {
    window_sums(src, w, h, r).into_iter().map(|(s, n)| if n == 0 { f32::INFINITY } else { s / n as f32 }).collect()
}
