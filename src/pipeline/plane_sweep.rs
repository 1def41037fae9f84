//! Stage-1 initial disparity: a plane sweep over the views of the central row, and of the
//! central column when stage 1 fits some.
//!
//! The views of the central row read every image row at the same instant, so the disparity
//! between them holds no motion. For each candidate disparity `d`, each view (offset `(dx, dy)`)
//! is sampled at `(u - dx d, v - dy d)` and compared with the central view. Occlusions are
//! handled by keeping the better of the two half-rows (views left of centre, views right of
//! centre): a point hidden on one side is usually visible on the other. Views of the central
//! column, if given, form two half-columns kept the same way, and the row's and the column's
//! costs are averaged: the column pins the disparity of horizontal edges, which the row cannot
//! see move (the row alone is used when no column view is given). Costs are averaged over
//! a square window, the best candidate is refined to sub-pixel precision by a parabola, and the
//! depth of the cost minimum below the mean cost of all candidates is kept as a confidence.
//!
//! The minimum means nothing in two cases:
//! - the cost curve is flat (a uniform region, or stripes along the baseline, wider than the
//!   window seen from every candidate);
//! - its minimum is flat-bottomed: inside a uniform region (a checker square, a plain panel)
//!   every candidate that keeps the shifted window inside the region matches, while others
//!   bring in its border, so the curve is deep but the first of its equal minima, the lowest
//!   disparity, is arbitrary. A second pass over the candidates counts those within
//!   [`NEAR_BEST_SHARE`] of the curve's depth of the best; where they span more disparity
//!   than moves the window by its width less one pixel in the farthest view, the pixel is not
//!   trusted.
//!
//! An untrusted pixel takes the disparity of the nearest trusted pixels left, right, above and
//! below whose colour is close to its own, weighted by inverse distance, so that the fill does
//! not cross an outline into another surface. On the 512 px suite scenes this takes
//! BadPix(0.07) of the initialisation from 49-66 % to 14-34 %, on HCI antinous from 22.3 to
//! 22.2 % (docs/results.md, Stage 1).

use super::box_filter::box_mean;
use crate::geometry::ViewId;
use crate::io::{Raster, Scene};
use rayon::prelude::*;

/// Depth of the cost minimum (mean absolute intensity difference) under which a pixel's sweep
/// result is not trusted and is filled from its trusted neighbours.
pub const MIN_CONFIDENCE: f32 = 2e-3;

/// Share of a pixel's confidence (its cost curve's depth) within which a candidate's cost counts
/// as matching as well as the best one. A twentieth measured about as well, a fifth worse at
/// 512 px (docs/results.md).
pub const NEAR_BEST_SHARE: f32 = 0.1;

/// Largest difference in any colour channel (intensities in [0, 1]) between an untrusted pixel
/// and a trusted one for the second to fill the first, when the pixel has such a source. 0.05
/// measured about as well, 0.2 worse (docs/results.md).
pub const FILL_COLOUR_TOLERANCE: f32 = 0.1;

/// Settings of the sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneSweepSettings {
    /// Smallest and largest disparity tried, pixels.
    pub range: (f64, f64),
    /// Step between candidates, pixels.
    pub step: f64,
    /// Half-size of the square cost window (window = 2 r + 1).
    pub window_radius: usize,
}

/// A disparity map and its per-pixel confidence.
#[derive(Debug, Clone)]
pub struct DisparityEstimate {
    /// Disparity of the central view, pixels (FORMAT sign).
    pub disparity: Raster,
    /// Mean cost over all candidates minus the chosen cost (intensity units; higher = surer;
    /// near 0 where the cost curve is flat).
    pub confidence: Raster,
    /// Pixels whose minimum was not trusted (a flat cost curve, or a flat-bottomed minimum),
    /// their disparity filled from their trusted neighbours.
    pub untrusted: usize,
}

/// Mean absolute difference per pixel against the central view, over `views` (each with its
/// offset `(dx, dy)` from the central view), for disparity `d`; `INFINITY` where no view sees
/// the pixel.
fn half_cost(central: &Raster, views: &[((f32, f32), &Raster)], d: f32, out: &mut [f32]) {
    let (w, h, ch) = (central.width, central.height, central.channels);
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, cost) in row.iter_mut().enumerate() {
            let (mut sum, mut n) = (0.0f32, 0u32);
            for &((dx, dy), view) in views {
                let (xs, ys) = (x as f32 - dx * d, y as f32 - dy * d);
                if xs < 0.0 || xs > (w - 1) as f32 || ys < 0.0 || ys > (h - 1) as f32 {
                    continue;
                }
                let (x0, y0) = ((xs as usize).min(w.saturating_sub(2)), (ys as usize).min(h.saturating_sub(2)));
                let (fx, fy) = (xs - x0 as f32, ys - y0 as f32);
                let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
                let at = |xx: usize, yy: usize| (yy * w + xx) * ch;
                let (a, b, c, e) = (at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1));
                for k in 0..ch {
                    let top = view.data[a + k] * (1.0 - fx) + view.data[b + k] * fx;
                    // Row views (dy = 0) sample their own row only: fy is 0.
                    let s = if fy == 0.0 { top } else { top * (1.0 - fy) + (view.data[c + k] * (1.0 - fx) + view.data[e + k] * fx) * fy };
                    sum += (s - central.data[(y * w + x) * ch + k]).abs();
                }
                n += ch as u32;
            }
            *cost = if n == 0 { f32::INFINITY } else { sum / n as f32 };
        }
    });
}

/// Runs the sweep on `views` (views of the central row and of the central column; others are
/// ignored), calling `progress(done, total)` after each candidate of each of its two passes.
pub fn plane_sweep(
    scene: &Scene,
    views: &[ViewId],
    settings: &PlaneSweepSettings,
    mut progress: impl FnMut(usize, usize),
) -> DisparityEstimate {
    let central = scene.central();
    let (w, h) = (central.width, central.height);
    let centre = scene.central_id();
    // Half-rows (left, right) and half-columns (above, below) of the central view.
    let mut halves: [Vec<((f32, f32), &Raster)>; 4] = Default::default();
    for &v in views.iter().filter(|v| (v.row == centre.row) != (v.col == centre.col)) {
        if let Some(img) = scene.view(v) {
            let (dx, dy) = scene.grid.offset(v);
            let half = match (v.row == centre.row, dx < 0.0, dy < 0.0) {
                (true, true, _) => 0,
                (true, false, _) => 1,
                (false, _, true) => 2,
                (false, _, false) => 3,
            };
            halves[half].push(((dx as f32, dy as f32), img));
        }
    }
    let with_column = !halves[2].is_empty() || !halves[3].is_empty();
    // The row's and the column's costs are weighed by their views' total distance from the
    // centre: a longer baseline resolves the disparity more finely.
    let reach = |pair: &[Vec<((f32, f32), &Raster)>]| pair.iter().flatten().map(|((dx, dy), _)| dx.abs() + dy.abs()).sum::<f32>();
    let column_share = reach(&halves[2..]) / (reach(&halves[..2]) + reach(&halves[2..])).max(f32::MIN_POSITIVE);
    // Farthest any swept view lies from the centre along the row or the column, in baselines.
    let longest = halves.iter().flatten().map(|((dx, dy), _)| dx.abs().max(dy.abs())).fold(0.0f32, f32::max);
    let (lo, hi) = settings.range;
    let labels = (((hi - lo) / settings.step).round() as usize + 1).max(1);
    let n = w * h;
    let mut best = vec![(f32::INFINITY, 0usize); n];
    let mut before = vec![f32::INFINITY; n];
    let mut after = vec![f32::INFINITY; n];
    let mut previous = vec![f32::INFINITY; n];
    let mut total = vec![(0.0f32, 0u32); n];
    let mut raw = vec![0.0f32; n];
    // The better half of a pair, window-averaged: `INFINITY` where neither half sees the pixel.
    let mut pair = |a: &[((f32, f32), &Raster)], b: &[((f32, f32), &Raster)], d: f32| -> Vec<f32> {
        half_cost(central, a, d, &mut raw);
        let first = box_mean(&raw, w, h, settings.window_radius);
        half_cost(central, b, d, &mut raw);
        let second = box_mean(&raw, w, h, settings.window_radius);
        first.iter().zip(&second).map(|(x, y)| x.min(*y)).collect()
    };
    let mut label_cost = |l: usize| -> Vec<f32> {
        let d = (lo + l as f64 * settings.step) as f32;
        let mut cost = pair(&halves[0], &halves[1], d);
        if with_column {
            let column = pair(&halves[2], &halves[3], d);
            for (c, k) in cost.iter_mut().zip(&column) {
                *c = match (c.is_finite(), k.is_finite()) {
                    (true, true) => (1.0 - column_share) * *c + column_share * k,
                    (false, _) => *k,
                    (true, false) => *c,
                };
            }
        }
        cost
    };
    for l in 0..labels {
        let cost = label_cost(l);
        best.par_iter_mut()
            .zip(before.par_iter_mut())
            .zip(after.par_iter_mut())
            .zip(previous.par_iter_mut())
            .zip(total.par_iter_mut())
            .zip(cost.par_iter())
            .for_each(|(((((b, bf), af), prev), tot), &c)| {
                if c.is_finite() {
                    tot.0 += c;
                    tot.1 += 1;
                }
                if b.1 + 1 == l && l > 0 {
                    *af = c;
                }
                if c < b.0 {
                    *b = (c, l);
                    *bf = *prev;
                    *af = f32::INFINITY;
                }
                *prev = c;
            });
        progress(l + 1, 2 * labels);
    }
    let mut disparity = Raster::zeros(w, h, 1);
    let mut confidence = Raster::zeros(w, h, 1);
    for i in 0..n {
        let ((c0, l), cm, cp) = (best[i], before[i], after[i]);
        let mut offset = 0.0f64;
        if cm.is_finite() && cp.is_finite() {
            let curvature = cm + cp - 2.0 * c0;
            if curvature > 1e-12 {
                offset = (0.5 * (cm - cp) / curvature).clamp(-0.5, 0.5) as f64;
            }
        }
        disparity.data[i] = (lo + (l as f64 + offset) * settings.step) as f32;
        let (sum, count) = total[i];
        confidence.data[i] = if c0.is_finite() && count > 0 { (sum / count as f32 - c0).max(0.0) } else { 0.0 };
    }
    // Second pass: how many candidates match about as well as the best, each counting for
    // `step * longest` px of movement of the window in the farthest view. A flat bottom and
    // minima repeated across the range (a periodic texture) are both ambiguous.
    let mut near_best = vec![0u32; n];
    for l in 0..labels {
        let cost = label_cost(l);
        near_best.par_iter_mut().zip(&confidence.data).zip(&best).zip(&cost).for_each(|(((k, &depth), b), &c)| {
            if c.is_finite() && c <= b.0 + NEAR_BEST_SHARE * depth {
                *k += 1;
            }
        });
        progress(labels + l + 1, 2 * labels);
    }
    let span_limit = (2 * settings.window_radius) as f64;
    let trusted: Vec<bool> = confidence
        .data
        .iter()
        .zip(&near_best)
        .map(|(&c, &k)| c >= MIN_CONFIDENCE && k as f64 * settings.step * longest as f64 <= span_limit)
        .collect();
    fill_untrusted(&mut disparity, &trusted, central);
    let untrusted = trusted.iter().filter(|&&t| !t).count();
    DisparityEstimate { disparity, confidence, untrusted }
}

/// Replaces every pixel not `trusted` by the inverse-distance-weighted mean of the nearest
/// trusted pixel in each of the four axis directions whose colour in `image` lies within
/// [`FILL_COLOUR_TOLERANCE`] of its own (a fill does not cross an outline into another
/// surface); where no direction has one, of the nearest trusted pixels whatever their colour;
/// left as is when there is none. `image` has the map's size.
pub fn fill_untrusted(map: &mut Raster, trusted: &[bool], image: &Raster) {
    let (w, h) = (map.width, map.height);
    let ch = image.channels;
    let alike = |i: usize, j: usize| (0..ch).all(|k| (image.data[i * ch + k] - image.data[j * ch + k]).abs() <= FILL_COLOUR_TOLERANCE);
    // Per pixel: (sum, weight) over the like-coloured sources, then over any.
    let mut like = vec![(0.0f64, 0.0f64); w * h];
    let mut any = vec![(0.0f64, 0.0f64); w * h];
    // One scan along a line of pixel indices, carrying the last trusted pixel and its step.
    let mut scan = |line: &mut dyn Iterator<Item = usize>| {
        let mut last: Option<(usize, usize)> = None;
        for (step, i) in line.enumerate() {
            if trusted[i] {
                last = Some((i, step));
            } else if let Some((source, at)) = last {
                let (value, wt) = (map.data[source] as f64, 1.0 / (step - at) as f64);
                any[i].0 += wt * value;
                any[i].1 += wt;
                if alike(i, source) {
                    like[i].0 += wt * value;
                    like[i].1 += wt;
                }
            }
        }
    };
    for y in 0..h {
        scan(&mut (0..w).map(|x| y * w + x));
        scan(&mut (0..w).rev().map(|x| y * w + x));
    }
    for x in 0..w {
        scan(&mut (0..h).map(|y| y * w + x));
        scan(&mut (0..h).rev().map(|y| y * w + x));
    }
    for i in 0..w * h {
        let (sum, weight) = if like[i].1 > 0.0 { like[i] } else { any[i] };
        if !trusted[i] && weight > 0.0 {
            map.data[i] = (sum / weight) as f32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fill_takes_like_coloured_sources_first() {
        // A 6x1 row: trusted 1.0 on a dark surface at x = 0, three untrusted pixels of a light
        // surface, trusted 3.0 on it at x = 4, and an untrusted pixel of a third colour at x = 5.
        let mut map = Raster::from_vec(6, 1, 1, vec![1.0, -9.0, -9.0, -9.0, 3.0, -9.0]).unwrap();
        let image = Raster::from_vec(6, 1, 1, vec![0.2, 0.8, 0.8, 0.8, 0.8, 0.5]).unwrap();
        fill_untrusted(&mut map, &[true, false, false, false, true, false], &image);
        assert_eq!(&map.data[1..4], &[3.0, 3.0, 3.0], "the dark surface's value does not cross the outline");
        // No like-coloured source: the nearest trusted pixels, whatever their colour (x = 4 only).
        assert_eq!(map.data[5], 3.0);
    }

    #[test]
    fn untrusted_pixels_take_their_trusted_neighbours_values() {
        // A 5x1 row: trusted 1.0 at x = 0 and 3.0 at x = 4; the middle is filled by distance.
        let mut map = Raster::from_vec(5, 1, 1, vec![1.0, -9.0, -9.0, -9.0, 3.0]).unwrap();
        let image = Raster::zeros(5, 1, 1);
        fill_untrusted(&mut map, &[true, false, false, false, true], &image);
        assert_eq!(map.data[0], 1.0);
        assert!((map.data[2] - 2.0).abs() < 1e-6);
        assert!((map.data[1] - (1.0 + 3.0 / 3.0) / (1.0 + 1.0 / 3.0)).abs() < 1e-6);
        assert_eq!(map.data[4], 3.0);
    }
}
