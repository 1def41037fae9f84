//! Sub-pixel displacement of small image patches between two views (Lucas–Kanade, translation
//! only, inverse compositional), and the choice of patches that pin it.
//!
//! A patch textured in both directions fixes its whole displacement. A patch whose texture
//! varies in one direction only (an edge, a stripe) fixes only the displacement across it (the
//! aperture problem): [`textured_points`] tells the two apart by the patch's structure tensor,
//! and [`track_warped`] tracks the second kind along one direction.
//!
//! The second view is resampled by cubic B-spline interpolation ([`SplineImage`]): bilinear
//! resampling would carry a match whose true displacement is a small fraction of a pixel about
//! 0.01 px too far.

use super::spline_image::SplineImage;
use crate::io::Raster;

/// How patches are tracked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackSettings {
    /// Patch half-size: the patch is `(2 radius + 1)²` pixels.
    pub radius: usize,
    /// Most Gauss–Newton steps.
    pub iterations: usize,
    /// Largest distance (px) the result may lie from the guess; farther, the patch is taken as lost.
    pub max_correction: f64,
}

impl Default for TrackSettings {
    fn default() -> Self {
        Self { radius: 4, iterations: 30, max_correction: 1.5 }
    }
}

/// A tracked patch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Track {
    /// Displacement `(dx, dy)` (px) from the patch in the first view to its match in the second.
    pub displacement: (f64, f64),
    /// RMS intensity difference of the matched patches.
    pub residual_rms: f64,
    /// RMS deviation of the first view's patch from its mean intensity: the scale a residual
    /// is judged against ([`Track::relative_residual`]).
    pub contrast: f64,
}

impl Track {
    /// The residual as a share of the patch's contrast. A patch on one surface matches to the
    /// tracking noise (a few hundredths); one holding two surfaces at different depths (an
    /// outline across another surface's texture) cannot be matched by one displacement, and
    /// leaves a sizeable share unexplained.
    pub fn relative_residual(&self) -> f64 {
        if self.contrast > 0.0 { self.residual_rms / self.contrast } else { f64::INFINITY }
    }
}

/// The pixels of the patch of half-size `radius` centred on the integer pixel (`x`, `y`) of the
/// grey image `grey`, row by row: `(dx, dy, value, gx, gy)`, with the offset from the centre and
/// central-difference gradients; `None` when the patch (with its one-pixel rim) leaves the image.
fn patch(grey: &Raster, x: usize, y: usize, radius: usize) -> Option<impl Iterator<Item = (f64, f64, f64, f64, f64)> + '_> {
    let (w, h) = (grey.width, grey.height);
    if x < radius + 1 || y < radius + 1 || x + radius + 1 >= w || y + radius + 1 >= h {
        return None;
    }
    let at = move |x: usize, y: usize| grey.data[y * w + x] as f64;
    Some((y - radius..=y + radius).flat_map(move |yy| {
        (x - radius..=x + radius).map(move |xx| {
            let gx = 0.5 * (at(xx + 1, yy) - at(xx - 1, yy));
            let gy = 0.5 * (at(xx, yy + 1) - at(xx, yy - 1));
            (xx as f64 - x as f64, yy as f64 - y as f64, at(xx, yy), gx, gy)
        })
    }))
}

/// The structure tensor `(Σ gx², Σ gx gy, Σ gy²)` of a patch's pixels.
fn structure_tensor(pixels: impl Iterator<Item = (f64, f64, f64, f64, f64)>) -> (f64, f64, f64) {
    pixels.fold((0.0, 0.0, 0.0), |(sxx, sxy, syy), (_, _, _, gx, gy)| (sxx + gx * gx, sxy + gx * gy, syy + gy * gy))
}

/// The smaller eigenvalue of the symmetric 2x2 matrix `[[a, b], [b, c]]`.
fn smaller_eigenvalue((a, b, c): (f64, f64, f64)) -> f64 {
    0.5 * (a + c) - (0.25 * (a - c).powi(2) + b * b).sqrt()
}

/// How a patch's texture pins its displacement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PatchTexture {
    /// Textured in both directions: the whole displacement is pinned.
    Both,
    /// Textured across the unit direction `normal` only (an edge, a stripe along the other
    /// direction): only the displacement's component along `normal` is pinned.
    Across {
        /// The unit direction the intensity varies along.
        normal: (f64, f64),
    },
}

impl PatchTexture {
    /// The direction the texture varies along, for a patch textured one way.
    pub fn normal(&self) -> Option<(f64, f64)> {
        match self {
            PatchTexture::Both => None,
            PatchTexture::Across { normal } => Some(*normal),
        }
    }
}

/// Pixels of the grey image `grey`, on a grid of step `stride`, whose patch is textured in both
/// directions: the structure tensor's smaller eigenvalue is at least `share` of the 90th
/// percentile of that eigenvalue over the grid, and at least a quarter of the larger one (no
/// edges or stripes). Returned top to bottom, left to right.
pub fn textured_points(grey: &Raster, radius: usize, stride: usize, share: f64) -> Vec<(usize, usize)> {
    classified_points(grey, radius, stride, share).into_iter().filter(|p| p.1 == PatchTexture::Both).map(|p| p.0).collect()
}

/// [`textured_points`], and with them the patches textured in one direction only whose larger
/// eigenvalue passes the same floor: as much texture across them as the two-way patches have
/// in their weaker direction. Returned top to bottom, left to right.
pub fn classified_points(grey: &Raster, radius: usize, stride: usize, share: f64) -> Vec<((usize, usize), PatchTexture)> {
    let stride = stride.max(1);
    let margin = radius + 1;
    let scored: Vec<_> = (margin..grey.height.saturating_sub(margin))
        .step_by(stride)
        .flat_map(|y| (margin..grey.width.saturating_sub(margin)).step_by(stride).map(move |x| (x, y)))
        .filter_map(|(x, y)| Some(((x, y), structure_tensor(patch(grey, x, y, radius)?))))
        .collect();
    let mut smalls: Vec<f64> = scored.iter().map(|s| smaller_eigenvalue(s.1)).collect();
    if smalls.is_empty() {
        return Vec::new();
    }
    smalls.sort_by(f64::total_cmp);
    let p90 = smalls[(smalls.len() * 9 / 10).min(smalls.len() - 1)];
    let floor = (share * p90).max(1e-12);
    scored
        .into_iter()
        .filter_map(|(at, t)| {
            let small = smaller_eigenvalue(t);
            let large = t.0 + t.2 - small;
            if small >= floor && small >= 0.25 * large {
                Some((at, PatchTexture::Both))
            } else if large >= floor && small < 0.25 * large {
                Some((at, PatchTexture::Across { normal: larger_eigenvector(t, large) }))
            } else {
                None
            }
        })
        .collect()
}

/// The unit eigenvector of the symmetric 2x2 matrix `[[a, b], [b, c]]` for its eigenvalue
/// `large` (the larger one).
fn larger_eigenvector((a, b, c): (f64, f64, f64), large: f64) -> (f64, f64) {
    // Rows of `M - large I` are orthogonal to the eigenvector; take the longer one for accuracy.
    let (r1, r2) = ((a - large, b), (b, c - large));
    let (x, y) = if r1.0.hypot(r1.1) >= r2.0.hypot(r2.1) { (-r1.1, r1.0) } else { (-r2.1, r2.0) };
    let n = x.hypot(y);
    if n > 0.0 { (x / n, y / n) } else { (1.0, 0.0) }
}

/// Where the patch of half-size `radius` at `at` pins a displacement along x and along y: the
/// offsets from its centre of the centroids of its squared horizontal and vertical gradients.
pub fn pinning_centres(grey: &Raster, at: (usize, usize), radius: usize) -> Option<((f64, f64), (f64, f64))> {
    let (mut wx, mut xx, mut xy, mut wy, mut yx, mut yy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (ox, oy, _, gx, gy) in patch(grey, at.0, at.1, radius)? {
        let (a, b) = (gx * gx, gy * gy);
        wx += a;
        xx += a * ox;
        xy += a * oy;
        wy += b;
        yx += b * ox;
        yy += b * oy;
    }
    (wx > 0.0 && wy > 0.0).then(|| ((xx / wx, xy / wx), (yx / wy, yy / wy)))
}

/// Tracks the patch of the grey image `from` centred on the integer pixel `at` into `to` (the
/// spline of an image of the same size), starting at displacement `guess`. `None` when the
/// patch is flat or leaves either image, the iteration does not settle, or it ends farther than
/// `settings.max_correction` from the guess.
pub fn track(from: &Raster, to: &SplineImage, at: (usize, usize), guess: (f64, f64), settings: &TrackSettings) -> Option<Track> {
    track_warped(from, to, at, guess, [[0.0; 2]; 2], None, settings)
}

/// [`track`] for a patch that also deforms by a known linear map: the pixel at offset `o` from
/// the centre moves by the tracked displacement plus `linear · o`. Only the displacement is
/// estimated. A surface slanted in depth stretches or shears a patch between views by its
/// disparity gradient; a translation-only match then lands where the patch's gradient energy
/// is centred, not at its centre, which differs between horizontal and vertical matches.
///
/// With `along` (a unit vector) the displacement moves from `guess` along it only: for a patch
/// textured in one direction ([`PatchTexture::Across`]), whose displacement along its edges no
/// match can tell, and for a match whose direction is known (the horizontal parallax between
/// views of one row). `None` also when the patch has no texture along `along`.
pub fn track_warped(
    from: &Raster,
    to: &SplineImage,
    at: (usize, usize),
    guess: (f64, f64),
    linear: [[f64; 2]; 2],
    along: Option<(f64, f64)>,
    settings: &TrackSettings,
) -> Option<Track> {
    let r = settings.radius;
    if (from.width, from.height) != (to.width, to.height) {
        return None;
    }
    let (x0, y0) = at;
    // The template and its gradients, whose structure tensor is the Hessian of every step.
    let template: Vec<_> = patch(from, x0, y0, r)?.collect();
    let (sxx, sxy, syy) = structure_tensor(template.iter().copied());
    // The Hessian's determinant in both directions, or its value along `along`: too small, the
    // patch does not pin the displacement.
    let (det, along_h) = match along {
        None => (sxx * syy - sxy * sxy, 0.0),
        Some((nx, ny)) => (0.0, nx * nx * sxx + 2.0 * nx * ny * sxy + ny * ny * syy),
    };
    let pinned = match along {
        None => det > 1e-18 * (sxx + syy).powi(2).max(1e-30),
        Some(_) => along_h > 1e-9 * (sxx + syy).max(1e-30),
    };
    if !pinned {
        return None;
    }
    let [[l00, l01], [l10, l11]] = linear;
    let (mut dx, mut dy) = guess;
    for _ in 0..settings.iterations {
        let (mut bx, mut by, mut ss) = (0.0, 0.0, 0.0);
        for &(ox, oy, t, gx, gy) in &template {
            let (wx, wy) = (ox + l00 * ox + l01 * oy, oy + l10 * ox + l11 * oy);
            let s = to.sample(x0 as f64 + wx + dx, y0 as f64 + wy + dy)?;
            let e = s - t;
            bx += gx * e;
            by += gy * e;
            ss += e * e;
        }
        // Inverse compositional step: solve H Δ = b with the template's Hessian (restricted to
        // `along` when given), then move back by Δ.
        let (step_x, step_y) = match along {
            None => ((syy * bx - sxy * by) / det, (sxx * by - sxy * bx) / det),
            Some((nx, ny)) => {
                let s = (nx * bx + ny * by) / along_h;
                (s * nx, s * ny)
            }
        };
        dx -= step_x;
        dy -= step_y;
        if (dx - guess.0).hypot(dy - guess.1) > settings.max_correction {
            return None;
        }
        if step_x.hypot(step_y) < 1e-4 {
            let n = template.len() as f64;
            let mean = template.iter().map(|p| p.2).sum::<f64>() / n;
            let contrast = (template.iter().map(|p| (p.2 - mean).powi(2)).sum::<f64>() / n).sqrt();
            return Some(Track { displacement: (dx, dy), residual_rms: (ss / n).sqrt(), contrast });
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth 2D texture shifted by (sx, sy): the value at (x, y) is the texture's at (x - sx, y - sy).
    fn texture(w: usize, h: usize, sx: f64, sy: f64) -> Raster {
        // Wavelengths of 25-50 px.
        let f = |x: f64, y: f64| {
            0.5 + 0.2 * (0.21 * x + 0.13 * y).sin() + 0.2 * (0.17 * y - 0.09 * x).cos() + 0.1 * (0.12 * x + 0.19 * y).sin()
        };
        Raster::from_f64_fn(w, h, |x, y| f(x - sx, y - sy))
    }

    #[test]
    fn a_known_subpixel_shift_is_recovered() {
        let from = texture(64, 64, 0.0, 0.0);
        let to = SplineImage::new(&texture(64, 64, 2.37, -1.62));
        let t = track(&from, &to, (32, 30), (2.0, -1.0), &TrackSettings::default()).expect("a textured patch is tracked");
        assert!((t.displacement.0 - 2.37).abs() < 2e-3 && (t.displacement.1 + 1.62).abs() < 2e-3, "{t:?}");
        assert!(t.residual_rms < 1e-3, "{t:?}");
    }

    #[test]
    fn a_patch_of_two_surfaces_moving_apart_leaves_a_large_share_of_its_contrast_unmatched() {
        // Stripes along the diagonal, on two layers: left of x = 32 moved 0.2 px down, right of
        // it 1.8 px down (two depths under a vertical parallax); a patch on one layer matches.
        let f = |x: f64, y: f64| 0.5 + 0.3 * (0.5 * (x + y)).sin();
        let from = Raster::from_f64_fn(64, 64, f);
        let to = SplineImage::new(&Raster::from_f64_fn(64, 64, |x, y| if x < 32.0 { f(x, y - 0.2) } else { f(x, y - 1.8) }));
        let normal = (0.5f64.sqrt(), 0.5f64.sqrt());
        let settings = TrackSettings::default();
        let on = |x| track_warped(&from, &to, (x, 32), (0.0, 0.0), [[0.0; 2]; 2], Some(normal), &settings);
        let (one, both) = (on(20).expect("tracked at 20"), on(32).expect("tracked at 32"));
        assert!(one.relative_residual() < 0.02, "{one:?}");
        assert!(both.relative_residual() > 0.2, "{both:?}");
    }

    #[test]
    fn a_small_fraction_of_a_pixel_on_a_fine_texture_is_not_overshot() {
        // Texture near 1 rad/px moved 0.1 px sideways, a rolling-shutter cue's size: bilinear
        // resampling would find it about 0.012 px too far, the same way for every patch.
        let fine = |sx: f64| {
            Raster::from_f64_fn(48, 48, |x, y| 0.5 + 0.2 * (1.1 * (x - sx) + 0.3 * y).sin() + 0.2 * (0.9 * y - 0.8 * (x - sx)).cos())
        };
        for shift in [0.05, 0.1, -0.1, 0.2] {
            let t = track(&fine(0.0), &SplineImage::new(&fine(shift)), (24, 24), (0.0, 0.0), &TrackSettings::default())
                .expect("a textured patch is tracked");
            assert!((t.displacement.0 - shift).abs() < 2.5e-3 && t.displacement.1.abs() < 2.5e-3, "{shift}: {t:?}");
        }
    }

    #[test]
    fn a_stretched_patch_is_found_at_its_centre_when_the_stretch_is_known() {
        // A texture whose contrast grows down the patch, stretched vertically by 8 % about the
        // patch centre (32, 32) and moved by (0.4, -2.3): the vertical parallax of a receding
        // floor between a row view and a corner.
        let (c, stretch, shift) = (32.0, 0.08, (0.4, -2.3));
        let f = |x: f64, y: f64| 0.5 + (0.05 + 0.02 * (y - c).max(-2.5)) * ((0.9 * x + 0.4 * y).sin() + (1.1 * y - 0.3 * x).cos());
        let from = Raster::from_f64_fn(64, 64, f);
        let to = SplineImage::new(&Raster::from_f64_fn(64, 64, |x, y| f(x - shift.0, c + (y - c - shift.1) / (1.0 + stretch))));
        let settings = TrackSettings::default();
        let plain = track(&from, &to, (32, 32), (0.0, -2.0), &settings).expect("plain match").displacement;
        let warped = track_warped(&from, &to, (32, 32), (0.0, -2.0), [[0.0, 0.0], [0.0, stretch]], None, &settings)
            .expect("warped match")
            .displacement;
        let miss = |d: (f64, f64)| (d.0 - shift.0).hypot(d.1 - shift.1);
        assert!(miss(warped) < 0.02, "warped {warped:?}");
        assert!(miss(plain) > 3.0 * miss(warped), "translation only {plain:?}, warped {warped:?}");
    }

    #[test]
    fn a_corner_pins_its_horizontal_displacement_on_one_edge_and_its_vertical_on_the_other() {
        // A dark quadrant whose vertical edge runs down x = 27 (5 px left of the patch centre)
        // from y = 30 and whose horizontal edge runs along y = 30 from x = 27 rightwards.
        let corner = Raster::from_f64_fn(64, 64, |x, y| {
            let step = |t: f64| 0.5 * (1.0 + (2.0 * t).tanh());
            0.2 + 0.6 * step(x - 27.0) * step(y - 30.0)
        });
        let (along_x, along_y) = pinning_centres(&corner, (32, 32), 8).expect("a corner pins both ways");
        assert!((along_x.0 + 5.0).abs() < 0.2 && along_x.1 > 2.0, "{along_x:?}");
        assert!((along_y.1 + 2.0).abs() < 0.2 && along_y.0 > 1.0, "{along_y:?}");
    }

    #[test]
    fn a_sharp_texture_rendered_as_the_generator_renders_is_matched_within_two_hundredths_of_a_pixel() {
        // A rotated checker of 3.3 x 2.7 px cells, each pixel the mean of 2 x 2 samples (as the
        // generator renders views): not band-limited, so every resampling is off somewhere.
        // Its patches moved by whole and fractional pixels are found 0.023-0.030 px RMS off,
        // and their mean is off by up to 0.012 px (measured): a bias shared by every patch of
        // a texture, the size of the per-view cue biases on the suite (docs/results.md).
        let render = |sx: f64, sy: f64| {
            let cell = |x: f64, y: f64| {
                let (u, v) = (0.87 * x + 0.49 * y, -0.49 * x + 0.87 * y);
                if ((u / 3.3).floor() + (v / 2.7).floor()) as i64 % 2 == 0 { 0.8 } else { 0.2 }
            };
            let samples = [(-0.25, -0.25), (0.25, -0.25), (-0.25, 0.25), (0.25, 0.25)];
            Raster::from_f64_fn(64, 64, |x, y| samples.iter().map(|(dx, dy)| cell(x - sx + dx, y - sy + dy)).sum::<f64>() / 4.0)
        };
        let from = render(0.0, 0.0);
        for shift in [(0.0, 0.1), (0.0, 0.4), (0.0, 2.6), (0.0, -4.8), (0.25, 0.0), (-1.3, 0.0), (7.6, 0.0)] {
            let to = SplineImage::new(&render(shift.0, shift.1));
            let guess = (shift.0.round(), shift.1.round());
            let errors: Vec<(f64, f64)> = (16..48)
                .step_by(3)
                .flat_map(|y| (16..48).step_by(3).map(move |x| (x, y)))
                .filter_map(|at| track(&from, &to, at, guess, &TrackSettings::default()))
                .map(|t| (t.displacement.0 - shift.0, t.displacement.1 - shift.1))
                .collect();
            let n = errors.len() as f64;
            let mean = (errors.iter().map(|e| e.0).sum::<f64>() / n, errors.iter().map(|e| e.1).sum::<f64>() / n);
            let rms = (errors.iter().map(|e| e.0 * e.0 + e.1 * e.1).sum::<f64>() / n).sqrt();
            assert!(
                n > 100.0 && mean.0.abs() < 0.02 && mean.1.abs() < 0.02 && rms < 0.05,
                "{shift:?}: {n} matched, mean {mean:?}, rms {rms}"
            );
        }
    }

    #[test]
    fn a_stripe_pins_one_direction_only_and_is_not_chosen() {
        // Vertical stripes: no vertical texture.
        let stripes = Raster::from_f64_fn(48, 48, |x, _| 0.5 + 0.4 * (x * 0.5).sin());
        assert!(textured_points(&stripes, 4, 4, 0.1).is_empty());
        assert!(track(&stripes, &SplineImage::new(&stripes), (24, 24), (0.0, 0.0), &TrackSettings::default()).is_none());
        let tex = texture(48, 48, 0.0, 0.0);
        assert!(!textured_points(&tex, 4, 4, 0.1).is_empty());
        // Beside a two-way texture (whose patches set the floor), every stripe patch is classed
        // as varying along x.
        let side_by_side = Raster::from_f64_fn(96, 48, |x, y| {
            if x < 48.0 { tex.data[y as usize * 48 + x as usize] as f64 } else { stripes.data[y as usize * 48 + x as usize - 48] as f64 }
        });
        let classes = classified_points(&side_by_side, 4, 4, 0.1);
        assert!(classes.iter().any(|p| p.0.0 < 43 && p.1 == PatchTexture::Both), "{classes:?}");
        let striped: Vec<_> = classes.iter().filter(|p| p.0.0 >= 53).collect();
        assert!(!striped.is_empty(), "{classes:?}");
        for (at, class) in striped {
            let PatchTexture::Across { normal } = class else { panic!("{at:?}: {class:?}") };
            assert!(normal.0.abs() > 0.999, "{at:?}: {normal:?}");
        }
    }

    #[test]
    fn a_diagonal_stripe_is_tracked_across_itself_and_along_the_row() {
        // Stripes varying along n = (0.8, -0.6), moved by (0.7, 0.9): only n · shift = 0.02 px
        // is seen; along the row, the same stripe is found 0.02 / 0.8 px to the side.
        let n = (0.8, -0.6);
        let stripes = |sx: f64, sy: f64| {
            Raster::from_f64_fn(64, 64, move |x, y| {
                let s = n.0 * (x - sx) + n.1 * (y - sy);
                0.5 + 0.3 * (0.7 * s).sin() + 0.1 * (1.3 * s).cos()
            })
        };
        let (from, shift) = (stripes(0.0, 0.0), (0.7, 0.9));
        let to = SplineImage::new(&stripes(shift.0, shift.1));
        let across = n.0 * shift.0 + n.1 * shift.1;
        let classes = classified_points(&from, 4, 8, 0.1);
        assert!(!classes.is_empty());
        let settings = TrackSettings::default();
        for (at, class) in classes {
            let PatchTexture::Across { normal } = class else { panic!("{at:?}: {class:?}") };
            assert!((normal.0 * n.0 + normal.1 * n.1).abs() > 0.999, "{at:?}: {normal:?}");
            let Some(t) = track_warped(&from, &to, at, (0.0, 0.0), [[0.0; 2]; 2], Some(normal), &settings) else {
                panic!("{at:?}: lost across the stripe")
            };
            let found = t.displacement.0 * normal.0 + t.displacement.1 * normal.1;
            let expected = across * (normal.0 * n.0 + normal.1 * n.1);
            assert!((found - expected).abs() < 2e-3, "{at:?}: {found} against {expected}");
            // The displacement stays along the normal: nothing is invented along the stripe.
            assert!((t.displacement.0 * normal.1 - t.displacement.1 * normal.0).abs() < 1e-12, "{t:?}");
            let Some(row) = track_warped(&from, &to, at, (0.0, 0.0), [[0.0; 2]; 2], Some((1.0, 0.0)), &settings) else {
                panic!("{at:?}: lost along the row")
            };
            assert!((row.displacement.0 - across / n.0).abs() < 3e-3 && row.displacement.1 == 0.0, "{row:?}");
        }
        // Along the stripes themselves nothing can be tracked.
        assert!(track_warped(&from, &to, (32, 32), (0.0, 0.0), [[0.0; 2]; 2], Some((0.6, 0.8)), &settings).is_none());
    }

    #[test]
    fn a_patch_leaving_the_image_or_too_far_from_the_guess_is_lost() {
        let from = texture(40, 40, 0.0, 0.0);
        let to = SplineImage::new(&texture(40, 40, 3.0, 0.0));
        assert!(track(&from, &to, (2, 20), (0.0, 0.0), &TrackSettings::default()).is_none());
        // The truth is 3 px away from a zero guess, beyond the allowed correction.
        let tight = TrackSettings { max_correction: 1.0, ..TrackSettings::default() };
        assert!(track(&from, &to, (20, 20), (0.0, 0.0), &tight).is_none());
    }
}
