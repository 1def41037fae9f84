//! Solid textures: colour as a function of the 3D point in an object's own frame, so that every
//! primitive is textured without a surface parametrisation and the texture moves with the object.

use crate::random::hash64;
use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

/// An RGB colour in [0, 1].
pub type Rgb = [f64; 3];

/// The kinds of texture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Texture {
    /// Alternating cubes of side `size` metres (squares on a plane).
    Checker {
        /// Side of a square, metres.
        size: f64,
        /// The two colours.
        colors: [Rgb; 2],
    },
    /// Band-limited gradient noise: `octaves` octaves from features of `scale` metres down.
    Noise {
        /// Size of the coarsest features, metres.
        scale: f64,
        /// Number of octaves (each half the size of the previous).
        octaves: u32,
        /// Colours at the two ends of the noise range.
        colors: [Rgb; 2],
        /// Seed of the noise lattice.
        #[serde(default)]
        seed: u64,
    },
    /// Parallel stripes of period `period` metres across `direction`.
    Stripes {
        /// Period, metres.
        period: f64,
        /// Direction across the stripes (object frame).
        direction: [f64; 3],
        /// The two colours.
        colors: [Rgb; 2],
    },
    /// A nearly uniform colour: a low-texture region, with faint noise of relative amplitude
    /// `variation` (0 = perfectly flat).
    Flat {
        /// The colour.
        color: Rgb,
        /// Amplitude of the faint noise, in colour units.
        #[serde(default)]
        variation: f64,
    },
}

fn lerp(a: &Rgb, b: &Rgb, t: f64) -> Rgb {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t]
}

/// A pseudo-random unit-ish gradient at lattice point (i, j, k).
fn gradient(i: i64, j: i64, k: i64, seed: u64) -> Vector3<f64> {
    let h =
        hash64((i as u64).wrapping_mul(0x8DA6_B343) ^ (j as u64).wrapping_mul(0xD816_3841) ^ (k as u64).wrapping_mul(0xCB1A_B31F) ^ seed);
    let c = |s: u32| ((h >> s) & 0xFFFF) as f64 / 32767.5 - 1.0;
    Vector3::new(c(0), c(16), c(32))
}

/// Gradient (Perlin-style) noise in about [-1, 1], smooth, with features of unit size.
pub fn gradient_noise(p: &Point3<f64>, seed: u64) -> f64 {
    let (fx, fy, fz) = (p.x.floor(), p.y.floor(), p.z.floor());
    let (i, j, k) = (fx as i64, fy as i64, fz as i64);
    let (x, y, z) = (p.x - fx, p.y - fy, p.z - fz);
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let (u, v, w) = (fade(x), fade(y), fade(z));
    let corner =
        |di: i64, dj: i64, dk: i64| gradient(i + di, j + dj, k + dk, seed).dot(&Vector3::new(x - di as f64, y - dj as f64, z - dk as f64));
    let l = |a: f64, b: f64, t: f64| a + (b - a) * t;
    let x00 = l(corner(0, 0, 0), corner(1, 0, 0), u);
    let x10 = l(corner(0, 1, 0), corner(1, 1, 0), u);
    let x01 = l(corner(0, 0, 1), corner(1, 0, 1), u);
    let x11 = l(corner(0, 1, 1), corner(1, 1, 1), u);
    (l(l(x00, x10, v), l(x01, x11, v), w) * 1.6).clamp(-1.0, 1.0)
}

impl Texture {
    /// The colour at point `p` of the object's frame.
    pub fn color(&self, p: &Point3<f64>) -> Rgb {
        match self {
            Texture::Checker { size, colors } => {
                // Cells are offset by half a cell so that flat shapes, whose local z is 0 up to
                // rounding, never sit on a cell boundary (which would flip cells at random).
                let cell = |v: f64| (v / size + 0.5).floor() as i64;
                let parity = (cell(p.x) + cell(p.y) + cell(p.z)).rem_euclid(2) as usize;
                colors[parity]
            }
            Texture::Noise { scale, octaves, colors, seed } => {
                let (mut sum, mut amp, mut norm, mut freq) = (0.0, 1.0, 0.0, 1.0 / scale);
                for o in 0..*octaves {
                    sum += amp * gradient_noise(&Point3::from(p.coords * freq), seed.wrapping_add(o as u64));
                    norm += amp;
                    amp *= 0.6;
                    freq *= 2.0;
                }
                lerp(&colors[0], &colors[1], (0.5 + 0.5 * sum / norm.max(1e-12)).clamp(0.0, 1.0))
            }
            Texture::Stripes { period, direction, colors } => {
                let dir = Vector3::from(*direction).try_normalize(1e-12).unwrap_or_else(Vector3::x);
                let phase = (p.coords.dot(&dir) / period).rem_euclid(1.0);
                colors[usize::from(phase >= 0.5)]
            }
            Texture::Flat { color, variation } => {
                if *variation == 0.0 {
                    return *color;
                }
                let n = variation * gradient_noise(&Point3::from(p.coords * 3.0), 7);
                [color[0] + n, color[1] + n, color[2] + n]
            }
        }
    }

    /// Checks the parameters; the error names the field.
    pub fn validate(&self) -> Result<(), String> {
        let positive =
            |name: &str, v: f64| if v > 0.0 && v.is_finite() { Ok(()) } else { Err(format!("texture `{name}` must be positive")) };
        match self {
            Texture::Checker { size, .. } => positive("size", *size),
            Texture::Noise { scale, octaves, .. } => {
                positive("scale", *scale)?;
                if *octaves == 0 || *octaves > 12 { Err("texture `octaves` must be 1 to 12".into()) } else { Ok(()) }
            }
            Texture::Stripes { period, .. } => positive("period", *period),
            Texture::Flat { .. } => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checker_alternates_and_noise_is_deterministic_and_bounded() {
        let t = Texture::Checker { size: 1.0, colors: [[0.0; 3], [1.0; 3]] };
        assert_ne!(t.color(&Point3::new(0.2, 0.2, 0.0)), t.color(&Point3::new(1.2, 0.2, 0.0)));
        assert_eq!(t.color(&Point3::new(0.2, 0.2, 0.0)), t.color(&Point3::new(1.2, 1.2, 0.0)));
        // A plane at z = 0 with rounding noise in z keeps clean cells.
        for z in [-1e-15, 0.0, 1e-15] {
            assert_eq!(t.color(&Point3::new(0.2, 0.2, z)), t.color(&Point3::new(0.2, 0.2, 0.0)));
        }
        let n = Texture::Noise { scale: 0.3, octaves: 4, colors: [[0.0; 3], [1.0; 3]], seed: 3 };
        let mut lo: f64 = 1.0;
        let mut hi: f64 = 0.0;
        for i in 0..2000 {
            let p = Point3::new(i as f64 * 0.0137, (i % 17) as f64 * 0.09, 0.2);
            let c = n.color(&p)[0];
            assert_eq!(c, n.color(&p)[0]);
            lo = lo.min(c);
            hi = hi.max(c);
        }
        assert!(lo >= 0.0 && hi <= 1.0 && hi - lo > 0.4, "noise range {lo}..{hi}");
    }
}
