//! Stage-1 initialisation of the Gaussians: positions sampled on the central view with a density
//! that rises with local image frequency, intensity from the pixel, disparity from the initial
//! map, size from the local spacing of the samples.

use crate::io::Raster;
use crate::model::GaussianSet;
use crate::random::Rng;

/// Share of the sampling density spread uniformly, so flat regions still get Gaussians.
const UNIFORM_SHARE: f64 = 0.25;

/// Local frequency of a grey image: gradient magnitude plus |Laplacian|, box-averaged over 5x5.
pub fn frequency_map(grey: &Raster) -> Vec<f64> {
    let (w, h) = (grey.width, grey.height);
    let at = |x: isize, y: isize| grey.get(x.clamp(0, w as isize - 1) as usize, y.clamp(0, h as isize - 1) as usize, 0) as f64;
    let mut raw = vec![0.0; w * h];
    for y in 0..h as isize {
        for x in 0..w as isize {
            let gx = 0.5 * (at(x + 1, y) - at(x - 1, y));
            let gy = 0.5 * (at(x, y + 1) - at(x, y - 1));
            let lap = at(x + 1, y) + at(x - 1, y) + at(x, y + 1) + at(x, y - 1) - 4.0 * at(x, y);
            raw[y as usize * w + x as usize] = (gx * gx + gy * gy).sqrt() + lap.abs();
        }
    }
    let r = 2isize;
    let mut out = vec![0.0; w * h];
    for y in 0..h as isize {
        for x in 0..w as isize {
            let (mut s, mut n) = (0.0, 0.0);
            for yy in (y - r).max(0)..=(y + r).min(h as isize - 1) {
                for xx in (x - r).max(0)..=(x + r).min(w as isize - 1) {
                    s += raw[yy as usize * w + xx as usize];
                    n += 1.0;
                }
            }
            out[y as usize * w + x as usize] = s / n;
        }
    }
    out
}

/// Samples `n` Gaussians on `central` (density rising with its local frequency), with colour from
/// the view and disparity from `disparity`. Deterministic for a given `seed`.
pub fn sample_gaussians(central: &Raster, disparity: &Raster, n: usize, seed: u64) -> GaussianSet {
    let (w, h) = (central.width, central.height);
    let freq = frequency_map(&central.to_grey());
    let mean = freq.iter().sum::<f64>() / freq.len() as f64;
    let density: Vec<f64> = freq.iter().map(|f| UNIFORM_SHARE * mean.max(1e-6) + (1.0 - UNIFORM_SHARE) * f).collect();
    let total: f64 = density.iter().sum();
    let mut cdf = Vec::with_capacity(density.len());
    let mut acc = 0.0;
    for d in &density {
        acc += d / total;
        cdf.push(acc);
    }
    let mut rng = Rng::new(seed);
    let ch = central.channels;
    let mut set = GaussianSet { u: vec![], v: vec![], disparity: vec![], size: vec![], colour: vec![], channels: ch };
    for i in 0..n {
        // Stratified draw: one sample per 1/n of the distribution, jittered.
        let q = (i as f64 + rng.unit()) / n as f64;
        let pixel = cdf.partition_point(|&c| c < q).min(w * h - 1);
        let (px, py) = (pixel % w, pixel / w);
        let u = (px as f64 + rng.unit() - 0.5).clamp(0.0, (w - 1) as f64) as f32;
        let v = (py as f64 + rng.unit() - 0.5).clamp(0.0, (h - 1) as f64) as f32;
        // n * density share of this pixel = samples per pixel here; spacing = its inverse sqrt.
        let per_pixel = n as f64 * density[pixel] / total;
        let spacing = 1.0 / per_pixel.max(1e-6).sqrt();
        set.u.push(u);
        set.v.push(v);
        set.size.push((0.6 * spacing).clamp(0.5, 8.0) as f32);
        set.disparity.push(disparity.sample_bilinear(u, v, 0).unwrap_or(0.0));
        for c in 0..ch {
            set.colour.push(central.sample_bilinear(u, v, c).unwrap_or(0.5));
        }
    }
    set
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn textured_regions_get_more_and_smaller_gaussians() {
        // Left half flat, right half a fine checkerboard.
        let (w, h) = (64, 32);
        let mut img = Raster::zeros(w, h, 1);
        for y in 0..h {
            for x in 0..w {
                img.set(x, y, 0, if x >= 32 && (x / 2 + y / 2) % 2 == 0 { 1.0 } else { 0.3 });
            }
        }
        let disp = Raster::from_vec(w, h, 1, vec![0.5; w * h]).unwrap();
        let set = sample_gaussians(&img, &disp, 400, 1);
        assert_eq!(set.len(), 400);
        let right = set.u.iter().filter(|&&u| u >= 34.0).count();
        let left = set.u.iter().filter(|&&u| u < 30.0).count();
        assert!(right > 2 * left, "right {right}, left {left}");
        let mean_size = |f: &dyn Fn(f32) -> bool| {
            let s: Vec<f32> = set.u.iter().zip(&set.size).filter(|(u, _)| f(**u)).map(|(_, s)| *s).collect();
            s.iter().sum::<f32>() / s.len() as f32
        };
        assert!(mean_size(&|u| u >= 34.0) < mean_size(&|u| u < 30.0));
        assert!(set.disparity.iter().all(|&d| d == 0.5));
        assert_eq!(set, sample_gaussians(&img, &disp, 400, 1), "deterministic for a seed");
    }
}
