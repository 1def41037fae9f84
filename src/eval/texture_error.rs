//! The image-space motion error split by the texture around each point in the central view.
//!
//! Where the texture runs one way only (stripes, a straight edge), the views show the motion
//! across it and nothing of the motion along it: the aperture problem. No fit can take that
//! component from those pixels; it follows only from the rigid motion that the rest of the
//! scene pins, carried to their depth. The split tells an error in what the scene shows from one
//! in what it hides (docs/results.md: `objects_fast1`'s far striped wall).

use super::motion_error::point_errors;
use crate::geometry::Camera;
use crate::io::{MotionRecord, Raster};
use serde::Serialize;

/// Half the side of the square window over which the structure tensor is summed, in px per 256
/// px of the image's longer side (at least 2 px): textures scale with the image, and a window
/// fixed in pixels would find the inside of a wide stripe flat.
const RADIUS_PER_256_PX: usize = 3;
/// The texture runs one way where the structure tensor's smaller eigenvalue is under this share
/// of its larger one (a coherence of about 0.82).
const ONE_WAY_RATIO: f64 = 0.1;
/// The texture is flat where the mean squared gradient over the window is under this (a
/// gradient of 0.01 of the intensity range per pixel).
const FLAT_GRADIENT2: f64 = 1e-4;

/// The points of one kind of texture.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TextureGroup {
    /// Their share of the points compared, over all views.
    pub share: f64,
    /// Their RMS image-space error (px); `null` in JSON where there are none.
    pub rms_error_px: f64,
}

/// The image-space error by the texture of the central view around each point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TextureSplit {
    /// Points whose texture runs one way.
    pub one_way: TextureGroup,
    /// Over those points, the RMS (px) of the error's component along the texture (what the
    /// views there cannot show)...
    pub along_px: f64,
    /// ...and across it.
    pub across_px: f64,
    /// Points textured both ways.
    pub both_ways: TextureGroup,
    /// Points on flat image.
    pub flat: TextureGroup,
}

/// The kind of texture around a pixel, from the structure tensor of `grey` over the window.
enum Texture {
    /// One way, with the unit direction across it (the dominant gradient's).
    OneWay((f64, f64)),
    BothWays,
    Flat,
}

fn texture_at(grey: &Raster, (u, v): (usize, usize), radius: usize) -> Texture {
    let (w, h) = (grey.width, grey.height);
    let at = |x: usize, y: usize| grey.data[y * w + x] as f64;
    let (mut sxx, mut syy, mut sxy, mut n) = (0.0, 0.0, 0.0, 0.0);
    for y in v.saturating_sub(radius)..=(v + radius).min(h - 1) {
        for x in u.saturating_sub(radius)..=(u + radius).min(w - 1) {
            let gx = 0.5 * (at((x + 1).min(w - 1), y) - at(x.saturating_sub(1), y));
            let gy = 0.5 * (at(x, (y + 1).min(h - 1)) - at(x, y.saturating_sub(1)));
            (sxx, syy, sxy, n) = (sxx + gx * gx, syy + gy * gy, sxy + gx * gy, n + 1.0);
        }
    }
    let (mean, spread) = (0.5 * (sxx + syy), (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt());
    let (larger, smaller) = (mean + spread, mean - spread);
    if larger / n < FLAT_GRADIENT2 {
        Texture::Flat
    } else if smaller < ONE_WAY_RATIO * larger {
        let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        Texture::OneWay((angle.cos(), angle.sin()))
    } else {
        Texture::BothWays
    }
}

/// Splits the error of `estimate` against `truth` on the t = 0 points of `gt_depth` (every
/// `stride`-th pixel, in the central view and the four corners, as
/// [`super::image_motion_error`]) by the texture of `central`, the captured central view,
/// around where it shows each point. `None` when no point is left or `central` is not the size
/// of `gt_depth`.
pub fn texture_error(
    camera: &Camera,
    estimate: &MotionRecord,
    truth: &MotionRecord,
    gt_depth: &Raster,
    central: &Raster,
    stride: usize,
) -> Option<TextureSplit> {
    if (central.width, central.height) != (gt_depth.width, gt_depth.height) {
        return None;
    }
    let grey = central.to_grey();
    let radius = (RADIUS_PER_256_PX * grey.width.max(grey.height) / 256).max(2);
    let points = point_errors(camera, estimate, truth, gt_depth, stride);
    // (count, sum of squared errors) per kind, and the squared components along and across.
    let (mut one_way, mut both_ways, mut flat) = ((0usize, 0.0), (0usize, 0.0), (0usize, 0.0));
    let (mut along2, mut across2) = (0.0, 0.0);
    for p in &points {
        let (ex, ey) = p.error;
        let group = match texture_at(&grey, p.seen_at, radius) {
            Texture::OneWay((cx, cy)) => {
                across2 += (ex * cx + ey * cy).powi(2);
                along2 += (ey * cx - ex * cy).powi(2);
                &mut one_way
            }
            Texture::BothWays => &mut both_ways,
            Texture::Flat => &mut flat,
        };
        group.0 += 1;
        group.1 += ex * ex + ey * ey;
    }
    let total = points.len() as f64;
    let summary = |(n, e2): (usize, f64)| TextureGroup { share: n as f64 / total, rms_error_px: (e2 / n as f64).sqrt() };
    (!points.is_empty()).then(|| TextureSplit {
        one_way: summary(one_way),
        along_px: (along2 / one_way.0 as f64).sqrt(),
        across_px: (across2 / one_way.0 as f64).sqrt(),
        both_ways: summary(both_ways),
        flat: summary(flat),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::motion_error::tests::camera;

    fn image(f: impl Fn(f64, f64) -> f64) -> Raster {
        let data = (0..64 * 48).map(|i| f((i % 64) as f64, (i / 64) as f64) as f32).collect();
        Raster { width: 64, height: 48, channels: 1, data }
    }

    fn split(central: &Raster, estimate: [f64; 3]) -> TextureSplit {
        let depth = Raster { width: 64, height: 48, channels: 1, data: vec![3.0; 64 * 48] };
        let truth = MotionRecord::ConstantVelocity { omega_rad_s: [0.0; 3], velocity_m_s: [0.5, 0.0, 0.0] };
        let estimate = MotionRecord::ConstantVelocity { omega_rad_s: [0.0; 3], velocity_m_s: estimate };
        texture_error(&camera(), &estimate, &truth, &depth, central, 3).expect("points")
    }

    /// Stripes running up to the right in the image (rows grow downwards): their gradient is
    /// along (1, 1), so they run along (1, -1).
    fn stripes() -> Raster {
        image(|x, y| 0.5 + 0.4 * (std::f64::consts::TAU * (x + y) / 6.0).sin())
    }

    #[test]
    fn an_error_along_stripes_is_told_from_one_across_them() {
        // A sideways slide off by +0.1 m/s and a vertical one by -0.1 m/s move the image along
        // (1, -1): along the stripes.
        let along = split(&stripes(), [0.6, -0.1, 0.0]);
        assert!(along.one_way.share > 0.95, "{along:?}");
        assert!(along.along_px > 10.0 * along.across_px && along.along_px > 0.01, "{along:?}");
        let total = (along.along_px.powi(2) + along.across_px.powi(2)).sqrt();
        assert!((total - along.one_way.rms_error_px).abs() < 1e-9, "{along:?}");
        // Both off by +0.1 m/s: across them.
        let across = split(&stripes(), [0.6, 0.1, 0.0]);
        assert!(across.across_px > 10.0 * across.along_px, "{across:?}");
        assert!((across.one_way.rms_error_px - along.one_way.rms_error_px).abs() < 0.05 * along.one_way.rms_error_px, "{across:?}");
    }

    #[test]
    fn texture_both_ways_and_flat_image_are_not_taken_for_stripes() {
        let checks = image(|x, y| 0.5 + 0.2 * (std::f64::consts::TAU * x / 6.0).sin() + 0.2 * (std::f64::consts::TAU * y / 6.0).sin());
        let both = split(&checks, [0.6, -0.1, 0.0]);
        assert!(both.both_ways.share > 0.95 && both.both_ways.rms_error_px > 0.01, "{both:?}");
        let flat = split(&image(|_, _| 0.5), [0.6, -0.1, 0.0]);
        assert!(flat.flat.share == 1.0 && flat.one_way.rms_error_px.is_nan(), "{flat:?}");
    }
}
