//! Rolling-shutter cues measured straight from the views, with no scene model.
//!
//! The views of the central row read each image row at the same time, so a patch moves between
//! them by its disparity alone: `a d` between views `a` columns apart. A view `(r, c)` off the
//! central row sees the same patch `b = r - rc` view rows away, `b d` image rows up or down,
//! read that much earlier or later; under a motion it sits `μ` off where the disparity alone
//! puts it. Tracking a textured patch of the central-row view of that view's column into another
//! view of the central row (which gives `d`) and into the view (same column: no horizontal
//! parallax) measures `μ`: [`measure_cues`]. With a still camera every `μ` is zero up to the
//! tracking noise.
//!
//! Stage 2 can weigh these against the cues its motion predicts ([`super::cue_term`]); the
//! photometric fit alone compares the corners with renders of the stage-1 model, whose errors
//! there are far larger than `μ` (docs/results.md).

use super::spline_image::SplineImage;
use super::view_tracking::{PatchTexture, Track, TrackSettings, classified_points, pinning_centres, track_warped};
use crate::geometry::{Camera, ViewId, pose_at, readout_interval, rs_project};
use crate::io::{MotionRecord, Raster, Scene};
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};

/// The least horizontal share of an edge's or a stripe's normal for its patch to give a cue: the
/// disparity is matched along the row, and a nearly horizontal edge does not pin it.
const MIN_ACROSS_X: f64 = 0.5;

/// The largest residual, as a share of the patch's contrast ([`Track::relative_residual`]), of
/// either match of an edge or a stripe. On a still `objects` scene its one-way patches where an
/// outline crosses the striped wall sat up to 0.15 px off zero in the corners, every group of
/// them biased the same way (their residuals a median 0.18 of their contrast in the row view
/// and 0.42 in the corners, against 0.07 and 0.05 for the one-way patches as a whole); past
/// this share every group sits within 0.014 px (docs/results.md). A patch textured both ways
/// has no such test: its row match must come out level instead.
const MAX_EDGE_RESIDUAL: f64 = 0.2;

/// How many times the scene's median unexplained share of contrast (over its patches textured
/// both ways) either match of such a patch may leave ([`drop_outlying_matches`]). A cue's
/// error against the true motion grows with that share: on `vegetation_slow2` (256 px) the
/// fifth of the cues with the lowest share miss it by 0.012 px on average, the other fifths by
/// 0.035-0.081 px, with vertical means of up to 0.06 px a corner, and on `checkerboards_slow2`
/// the top fifth misses by 0.049 px against 0.021-0.025. A fixed bound does not fit every
/// texture: those medians are 0.31 and 0.11, and a bound of 0.2 or 0.3 left `vegetation_slow2`
/// too few cues (0.087 -> 0.202 and 0.103 px) while it helped `checkerboards_slow2`
/// (0.104 -> 0.085 and 0.077 px). Twice the median: 0.074 and 0.081 px (docs/results.md). The
/// default of `[stage2] cue_outlier_bound`; `constant_acceleration`'s config keeps every match.
pub const MAX_RESIDUAL_OVER_MEDIAN: f64 = 2.0;

/// Half-size of the larger patch each grid point is also tracked with, in grid steps (13 x 13 px
/// up to 256 x 256, 25 x 25 at 512; the base patch is two steps: 9 x 9 and 17 x 17). More pixels
/// average more of the bias a texture that is not band-limited leaves in a match, where one
/// displacement explains them all; where a patch holds two depths (a fence's thin bars before a
/// backdrop) it is the larger patch that mixes them (docs/results.md).
const LARGE_PATCH_STEPS: usize = 3;

/// The largest share of its contrast ([`Track::relative_residual`]) that either match of a
/// larger patch may leave unexplained for its cue to replace the base patch's. On the 256 px
/// suite 72 % of `checkerboards_slow2`'s cues pass and 12 % of `vegetation_slow2`'s; with 13 x 13
/// patches everywhere `checkerboards_slow2` went from 0.068 to 0.028 px and `vegetation_slow2`
/// from 0.078 to 0.239 px (docs/results.md).
const MAX_LARGE_PATCH_RESIDUAL: f64 = 0.15;

/// How far apart along x (in grid steps) a patch textured both ways may pin its horizontal and
/// its vertical displacement (`pinning_centres`: the centroids of its squared x and y
/// gradients) and still give a cue ([`tracked_cues`]; `[stage2] cue_lever_bound`). A cue's
/// vertical component is the off-row match's vertical displacement, pinned where the patch's
/// horizontal texture lies, plus `b` times the disparity, pinned where its vertical texture
/// lies; carried to one point by the disparity gradient, it is off by `b` times the gradient's
/// error times the distance between the two. What the patch does
/// not pin of the gradient (the stretch along x of a patch whose vertical texture is one slanted
/// edge, a checker's corner on a receding floor) comes from its neighbours' plane, which see the
/// same corner: on the README's scene (512 px, 4 px steps) such cues were off by up to 0.5 px
/// along their edges, `b`-signed (a tilt), and a bound of one step takes its motion from 0.152
/// to 0.127 px, 8.9 % of its shift (docs/results.md).
pub const MAX_LEVER_STEPS: f64 = 1.0;

/// A measured rolling-shutter cue: a textured patch, where it is in the central view, and where
/// it sits in one off-row view against where its disparity alone would put it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cue {
    /// The patch centre in the central view (px).
    pub at: (f64, f64),
    /// Its disparity (px), tracked from the central-row view of the view's column over the
    /// row's longest baseline.
    pub disparity: f64,
    /// The off-row view.
    pub view: ViewId,
    /// Its offset in that view from the position its disparity gives (px). For a patch textured
    /// across `across` only, the measured component times that direction.
    pub offset: (f64, f64),
    /// `None` for a patch textured in both directions, whose whole offset is measured; the unit
    /// direction its texture varies along for an edge or a stripe, of whose offset only the
    /// component along it is measured (the aperture problem).
    pub across: Option<(f64, f64)>,
    /// The larger share of the patch's contrast that its two matches (into the row view and
    /// into the off-row view) leave unexplained ([`Track::relative_residual`]).
    pub residual: f64,
}

impl Cue {
    /// The unit image directions along which this cue's offset is measured, each with its kind:
    /// x and y for a patch textured both ways, the one across an edge or a stripe.
    pub fn measured_axes(&self) -> Vec<(CueAxis, (f64, f64))> {
        match self.across {
            None => vec![(CueAxis::Horizontal, (1.0, 0.0)), (CueAxis::Vertical, (0.0, 1.0))],
            Some(normal) => vec![(CueAxis::Across, normal)],
        }
    }
}

/// The kind of direction a measured cue component lies along (their noise differs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum CueAxis {
    /// Image x, of a patch textured both ways.
    Horizontal,
    /// Image y, of a patch textured both ways.
    Vertical,
    /// Across the edges of a patch textured one way.
    Across,
}

/// The measured cues of `scene` in `views` (e.g. the four corners), column by column: the
/// textured patches of the central-row view of a view's column (on a grid of about 128 x 128),
/// each tracked into the view of the central row farthest from it (which gives its disparity)
/// and into the view. A patch textured in both directions gives the whole cue. With `edges`, an
/// edge or a stripe, matched along the row and then across itself, gives the cue's component
/// across it (`Cue::across`), unless it is too nearly horizontal to give the disparity; its
/// disparity then also joins its neighbours' local planes (below).
/// `guess` (a disparity map of the central view, e.g. the plane sweep's) only starts the
/// tracking. Patches lost in either view, or found more than 0.25 px up or down in the row view
/// (the row views are read at the same time, so that is a mismatch), are left out. Views of the
/// central row (no vertical offset, no cue) or of the central column, views the scene lacks, and
/// columns whose central-row view it lacks give no cues.
///
/// A patch on a surface slanted in depth is sheared between row views and stretched between
/// a row view and an off-row view by its disparity gradient, and a translation-only match of a
/// deformed patch lands where its gradient energy is centred, which differs between the
/// horizontal match that gives `d` and the vertical one that gives `μ`: on a receding floor that
/// biases every `μ` the same way. So the tracking is done twice: a first pass gives each patch's
/// disparity, a plane fitted to its neighbours' gives the local gradient, and the second pass
/// matches with the deformation that gradient predicts (`track_warped`). Patches whose
/// neighbours fit no plane (a depth edge, a bad match) are left out too, and so are the patches
/// textured both ways that pin their horizontal and their vertical displacement more than
/// [`MAX_LEVER_STEPS`] grid steps apart.
///
/// Both matches resample the second view by cubic B-spline ([`SplineImage`]): a cue is a small
/// fraction of a pixel sideways, where bilinear resampling would carry every match about
/// 0.01 px too far.
///
/// Each grid point is tracked with two patches, the base one and a larger one
/// (`LARGE_PATCH_STEPS`); the larger one's cue is kept where both of its matches leave little
/// of it unexplained (`MAX_LARGE_PATCH_RESIDUAL`): more pixels average more of the bias of a
/// texture that is not band-limited (a checker's sharp edges), but where a patch holds two
/// depths it is the larger one that mixes them, and the base patch's cue stays.
///
/// A match that leaves much of its patch unexplained is off more than most, and its error is
/// shared by its neighbours (a fence's thin bars before a backdrop, a texture finer than the
/// pixels): the patches textured both ways whose matches leave over twice the scene's median
/// share of their contrast give no cue ([`drop_outlying_matches`]).
pub fn measure_cues(scene: &Scene, guess: &Raster, views: &[ViewId], edges: bool) -> Vec<Cue> {
    let mut cues = tracked_cues(scene, guess, views, edges, MAX_LEVER_STEPS).cues;
    let _ = drop_outlying_matches(&mut cues, MAX_RESIDUAL_OVER_MEDIAN);
    cues
}

/// What [`tracked_cues`] found: the cues, and how many patches the lever bound left out.
#[derive(Debug, Clone, Default)]
pub struct TrackedCues {
    /// Every cue tracked, before [`drop_outlying_matches`].
    pub cues: Vec<Cue>,
    /// The base patches textured both ways that reached the lever bound, summed over columns.
    pub base_lever: LeverTally,
    /// The larger patches (`LARGE_PATCH_STEPS`) likewise.
    pub large_lever: LeverTally,
}

/// Patches textured both ways that the lever bound ([`MAX_LEVER_STEPS`]) judged, and those it
/// left out.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LeverTally {
    /// Patches textured both ways with a local plane, so judged by the bound.
    pub judged: usize,
    /// Those whose two matches pin their displacements too far apart: they give no cue.
    pub left_out: usize,
}

/// Every cue [`measure_cues`] tracks, before it leaves out the patches textured both ways whose
/// matches are outliers ([`drop_outlying_matches`]); each with its [`Cue::residual`]. Patches
/// textured both ways whose two matches pin their displacements more than `max_lever_steps` grid
/// steps apart along x give none ([`MAX_LEVER_STEPS`]; 0: no bound, and nothing judged).
pub fn tracked_cues(scene: &Scene, guess: &Raster, views: &[ViewId], edges: bool, max_lever_steps: f64) -> TrackedCues {
    let stride = ((scene.width() * scene.height()) as f64 / 16384.0).sqrt().round().max(2.0) as usize;
    // Patches grow with the grid, so that they cover the same share of the scene at any size:
    // 9 x 9 px up to 256 x 256 (stride 2), 17 x 17 at 512. At 512 px 9 x 9 patches gave
    // 4,714 cues on the README's scene and shared errors of up to 0.03 px a corner; 17 x 17
    // ones 12,495 and 0.004 px (docs/results.md).
    let (base, base_lever) = patch_cues(scene, guess, views, edges, 2 * stride, stride, max_lever_steps);
    let (large, large_lever) = patch_cues(scene, guess, views, edges, LARGE_PATCH_STEPS * stride, stride, max_lever_steps);
    TrackedCues { cues: prefer_large_patches(base, large), base_lever, large_lever }
}

/// A cue with the grid point of the central-row view whose patch gave it.
type PatchCue = ((usize, usize), Cue);

/// The cues of `base` patches, each replaced by its `large` patch's where both of that one's
/// matches leave at most [`MAX_LARGE_PATCH_RESIDUAL`] of its contrast unexplained, and the large
/// patches' cues that pass that test where the base patch gave none (too little texture, or
/// lost), after them.
fn prefer_large_patches(base: Vec<PatchCue>, large: Vec<PatchCue>) -> Vec<Cue> {
    let key = |(at, cue): &PatchCue| (cue.view, *at);
    let sure: HashMap<_, Cue> = large.iter().filter(|p| p.1.residual <= MAX_LARGE_PATCH_RESIDUAL).map(|p| (key(p), p.1)).collect();
    let in_base: HashSet<_> = base.iter().map(key).collect();
    let mut cues: Vec<Cue> = base.iter().map(|p| sure.get(&key(p)).copied().unwrap_or(p.1)).collect();
    cues.extend(large.iter().filter(|p| !in_base.contains(&key(p)) && sure.contains_key(&key(p))).map(|p| p.1));
    cues
}

/// The cues of the patches of half-size `radius` on the grid of step `stride`, column by column
/// ([`tracked_cues`]), and the lever bound's tally over the columns.
fn patch_cues(
    scene: &Scene,
    guess: &Raster,
    views: &[ViewId],
    edges: bool,
    radius: usize,
    stride: usize,
    max_lever_steps: f64,
) -> (Vec<PatchCue>, LeverTally) {
    let grid = scene.grid;
    let (Some(centre), w) = (grid.central(), scene.width()) else { return (Vec::new(), LeverTally::default()) };
    let settings = TrackSettings { radius, ..TrackSettings::default() };
    let mut cues = Vec::new();
    let mut lever = LeverTally::default();
    // The views column by column: those of a column are tracked from the same row view.
    let views: Vec<ViewId> = views.iter().copied().filter(|v| v.row != centre.row && v.col != centre.col).collect();
    let mut columns: Vec<usize> = views.iter().map(|v| v.col).collect();
    columns.sort();
    columns.dedup();
    // The partner views, splined once each: the columns on one side of the centre share one.
    let mut partners: HashMap<ViewId, SplineImage> = HashMap::new();
    for col in columns {
        let targets: Vec<(ViewId, SplineImage)> =
            views.iter().filter(|v| v.col == col).filter_map(|&v| Some((v, SplineImage::new(scene.view(v)?)))).collect();
        let Some(row_img) = scene.view(ViewId { row: centre.row, col }).filter(|_| !targets.is_empty()) else { continue };
        let a = grid.offset(ViewId { row: centre.row, col }).0;
        // The disparity is measured against the row view farthest from this one: a match's
        // own bias (a fixed fraction of a pixel) divides by the baseline, and returns `b` times
        // over in the vertical cue.
        let Some((partner, baseline)) = longest_row_baseline(scene, a) else { continue };
        let Some(partner_img) = scene.view(partner) else { continue };
        let partner = &*partners.entry(partner).or_insert_with(|| SplineImage::new(partner_img));
        let row_img = row_img.to_grey();
        // Edges and stripes, when asked for, measure the disparity only with horizontal texture
        // across them.
        let patches: Vec<((usize, usize), PatchTexture)> = classified_points(&row_img, settings.radius, stride, 0.1)
            .into_iter()
            .filter(|(_, texture)| match texture {
                PatchTexture::Both => true,
                PatchTexture::Across { normal } => edges && normal.0.abs() >= MIN_ACROSS_X,
            })
            .collect();
        // An edge or a stripe is kept only where one displacement explains the patch.
        let fits = |track: &Track, texture: PatchTexture| texture == PatchTexture::Both || track.relative_residual() <= MAX_EDGE_RESIDUAL;
        // The patch of the row view, found in the partner view `baseline d` to the right: `d`.
        // A patch textured both ways is matched freely and must come out level; an edge or a
        // stripe is matched along the row.
        let to_partner = |(x, y): (usize, usize), texture: PatchTexture, start: f64, slope: (f64, f64)| {
            let linear = [[baseline * slope.0, baseline * slope.1], [0.0, 0.0]];
            let guess = (baseline * start, 0.0);
            let along = texture.normal().map(|_| (1.0, 0.0));
            let found = track_warped(&row_img, partner, (x, y), guess, linear, along, &settings).filter(|t| fits(t, texture))?;
            let (dx, dy) = found.displacement;
            (dy.abs() <= 0.25).then_some((dx / baseline, found.relative_residual()))
        };
        let first: Vec<Option<f64>> = patches
            .par_iter()
            .map(|&((x, y), texture)| {
                let gx = ((x as f64 + a * guess_d0(guess, x, y)?).round().max(0.0) as usize).min(w - 1);
                to_partner((x, y), texture, guess_d0(guess, gx, y)?, (0.0, 0.0)).map(|(d, _)| d)
            })
            .collect();
        let points: Vec<(usize, usize)> = patches.iter().map(|p| p.0).collect();
        let first = PatchDisparities::new(&points, first, stride);
        // The neighbours a gradient is fitted to: those within a patch (two grid steps).
        let reach = settings.radius;
        // Each patch's cues, and whether the lever bound judged it (`Some`) and left it out
        // (`Some(true)`).
        let found: Vec<(Vec<PatchCue>, Option<bool>)> = patches
            .par_iter()
            .zip(&first.values)
            .filter_map(|(&((x, y), texture), &d1)| {
                let slope = first.slope_at((x, y), reach)?;
                // A patch textured both ways only where its two matches pin their displacements
                // near each other ([`MAX_LEVER_STEPS`]).
                let mut judged = None;
                if texture == PatchTexture::Both && max_lever_steps > 0.0 {
                    let (along_x, along_y) = pinning_centres(&row_img, (x, y), settings.radius)?;
                    if (along_y.0 - along_x.0).abs() > max_lever_steps * stride as f64 {
                        return Some((Vec::new(), Some(true)));
                    }
                    judged = Some(false);
                }
                let Some((d, row_residual)) = d1.and_then(|d1| to_partner((x, y), texture, d1, slope)) else {
                    return Some((Vec::new(), judged));
                };
                // The same patch in each view of its column: `b d` rows up or down, and `μ` (its
                // component across the edges of an edge or a stripe).
                let in_views = targets.iter().filter_map(|(view, image)| {
                    let b = grid.offset(*view).1;
                    let linear = [[0.0, 0.0], [-b * slope.0, -b * slope.1]];
                    let across = texture.normal();
                    let track =
                        track_warped(&row_img, image, (x, y), (0.0, -b * d), linear, across, &settings).filter(|t| fits(t, texture))?;
                    let (dx, dy) = track.displacement;
                    let residual = row_residual.max(track.relative_residual());
                    Some((
                        (x, y),
                        Cue { at: (x as f64 + a * d, y as f64), disparity: d, view: *view, offset: (dx, dy + b * d), across, residual },
                    ))
                });
                Some((in_views.collect(), judged))
            })
            .collect();
        for (patch_cues, judged) in found {
            lever.judged += usize::from(judged.is_some());
            lever.left_out += usize::from(judged == Some(true));
            cues.extend(patch_cues);
        }
    }
    (cues, lever)
}

/// Leaves out the cues of patches textured both ways whose matches leave more than
/// `over_median` times the median share of contrast unexplained ([`MAX_RESIDUAL_OVER_MEDIAN`]
/// by default), the median taken over those patches' cues in `cues` (edges and stripes pass
/// their own, fixed test). Returns the bound applied, `None` where `cues` holds no patch
/// textured both ways or `over_median` is 0 (then none is left out).
pub fn drop_outlying_matches(cues: &mut Vec<Cue>, over_median: f64) -> Option<f64> {
    if over_median <= 0.0 {
        return None;
    }
    let bound = over_median * median_two_way_residual(cues)?;
    cues.retain(|c| c.across.is_some() || c.residual <= bound);
    Some(bound)
}

/// The median [`Cue::residual`] of the cues of patches textured both ways (the upper one of an
/// even count), `None` where there are none.
pub fn median_two_way_residual(cues: &[Cue]) -> Option<f64> {
    let mut residuals: Vec<f64> = cues.iter().filter(|c| c.across.is_none()).map(|c| c.residual).collect();
    residuals.sort_by(f64::total_cmp);
    residuals.get(residuals.len() / 2).copied()
}

/// The present view of the central row farthest from the one `a` views right of the centre,
/// and the baseline `B` between them (views): a patch of disparity `d` in the view at `a` is
/// `B d` to the right in it.
fn longest_row_baseline(scene: &Scene, a: f64) -> Option<(ViewId, f64)> {
    scene
        .central_row_views()
        .into_iter()
        .map(|v| (v, a - scene.grid.offset(v).0))
        .filter(|&(_, baseline)| baseline != 0.0)
        .max_by(|p, q| p.1.abs().total_cmp(&q.1.abs()))
}

/// The first-pass disparities of the patches, looked up by position.
struct PatchDisparities {
    values: Vec<Option<f64>>,
    at: HashMap<(usize, usize), usize>,
    /// The step of the grid the patches lie on (px).
    step: usize,
}

impl PatchDisparities {
    fn new(points: &[(usize, usize)], values: Vec<Option<f64>>, step: usize) -> Self {
        Self { values, at: points.iter().enumerate().map(|(i, &p)| (p, i)).collect(), step: step.max(1) }
    }

    /// The disparity gradient `(∂d/∂x, ∂d/∂y)` at `p`: the least-squares plane through the
    /// disparities of the patches within `radius` px each way. `None` with fewer than eight of
    /// them, when they do not span both directions, or when they lie off the plane by more than
    /// 0.05 px RMS.
    fn slope_at(&self, p: (usize, usize), radius: usize) -> Option<(f64, f64)> {
        // Only grid points can hold a patch.
        let (r, step) = ((radius / self.step * self.step) as isize, self.step);
        let near: Vec<(f64, f64, f64)> = (-r..=r)
            .step_by(step)
            .flat_map(|dy| (-r..=r).step_by(step).map(move |dx| (dx, dy)))
            .filter_map(|(dx, dy)| {
                let q = (p.0.checked_add_signed(dx)?, p.1.checked_add_signed(dy)?);
                Some((dx as f64, dy as f64, (*self.values.get(*self.at.get(&q)?)?)?))
            })
            .collect();
        if near.len() < 8 {
            return None;
        }
        let (mut normal, mut rhs) = (Matrix3::<f64>::zeros(), Vector3::<f64>::zeros());
        for &(x, y, d) in &near {
            let row = Vector3::new(1.0, x, y);
            normal += row * row.transpose();
            rhs += row * d;
        }
        // Both directions spanned: the offsets' covariance is well away from singular.
        let n = near.len() as f64;
        let (mx, my) = (normal[(0, 1)] / n, normal[(0, 2)] / n);
        let (vx, vy, cxy) = (normal[(1, 1)] / n - mx * mx, normal[(2, 2)] / n - my * my, normal[(1, 2)] / n - mx * my);
        if vx * vy - cxy * cxy < 0.25 * (radius as f64).powi(4) / 9.0 {
            return None;
        }
        let plane = normal.lu().solve(&rhs)?;
        let rms = (near.iter().map(|&(x, y, d)| (plane[0] + plane[1] * x + plane[2] * y - d).powi(2)).sum::<f64>() / n).sqrt();
        (rms <= 0.05).then_some((plane[1], plane[2]))
    }
}

/// The guess's disparity at (x, y), when finite.
fn guess_d0(guess: &Raster, x: usize, y: usize) -> Option<f64> {
    let d = *guess.data.get(y * guess.width + x)? as f64;
    d.is_finite().then_some(d)
}

/// The cue `estimate` predicts for a patch: where it puts the point seen at `cue.at` with
/// `cue.disparity` (the scene at that row's read-out time) in `cue.view`, less where no motion
/// puts it. `None` when either cannot image it.
pub fn predicted_cue(camera: &Camera, estimate: &MotionRecord, cue: &Cue) -> Option<(f64, f64)> {
    let z = camera.disparity_to_depth(cue.disparity);
    if !(z.is_finite() && z > 0.0) {
        return None;
    }
    let (u, v) = cue.at;
    let seen = camera.back_project(u, v, z);
    let at_zero = pose_at(estimate, camera.row_time(v), readout_interval(camera.height, camera.line_time_s)).inverse().apply(&seen);
    let moved = rs_project(camera, estimate, cue.view, &at_zero)?;
    let still = rs_project(camera, &MotionRecord::zero(), cue.view, &seen)?;
    Some((moved.0 - still.0, moved.1 - still.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Patches every 2 px over a 40 x 40 area, with disparities `d(x, y)`.
    fn patches(d: impl Fn(f64, f64) -> f64) -> PatchDisparities {
        let points: Vec<(usize, usize)> = (0..20).flat_map(|j| (0..20).map(move |i| (10 + 2 * i, 10 + 2 * j))).collect();
        let values: Vec<Option<f64>> = points.iter().map(|&(x, y)| Some(d(x as f64, y as f64))).collect();
        PatchDisparities::new(&points, values, 2)
    }

    #[test]
    fn two_way_matches_over_twice_the_median_residual_are_left_out_and_edges_are_not() {
        let cue = |residual: f64, across: Option<(f64, f64)>| Cue {
            at: (10.0, 10.0),
            disparity: 0.5,
            view: ViewId { row: 0, col: 0 },
            offset: (0.0, 0.0),
            across,
            residual,
        };
        // Seven two-way residuals, median 0.16: 0.32 is twice it, 0.33 is over.
        let mut cues: Vec<Cue> = [0.33, 0.1, 0.12, 0.32, 0.15, 0.16, 0.2].iter().map(|&r| cue(r, None)).collect();
        // An edge's residual does not count towards the median and is not judged by it.
        cues.push(cue(0.19, Some((1.0, 0.0))));
        assert_eq!(drop_outlying_matches(&mut cues, MAX_RESIDUAL_OVER_MEDIAN), Some(0.32));
        let kept: Vec<(f64, bool)> = cues.iter().map(|c| (c.residual, c.across.is_some())).collect();
        assert_eq!(kept, vec![(0.1, false), (0.12, false), (0.32, false), (0.15, false), (0.16, false), (0.2, false), (0.19, true)]);
        // No two-way cue, nothing to judge by.
        let mut edges = vec![cue(0.5, Some((0.0, 1.0)))];
        assert_eq!(drop_outlying_matches(&mut edges, MAX_RESIDUAL_OVER_MEDIAN), None);
        assert_eq!(edges.len(), 1);
    }

    #[test]
    fn a_large_patch_replaces_the_base_one_only_where_one_displacement_explains_it() {
        // A cue told apart by its offset: 1 for the base patches, 2 for the large ones.
        let cue = |col: usize, offset: f64, residual: f64| Cue {
            at: (10.0, 10.0),
            disparity: 0.5,
            view: ViewId { row: 0, col },
            offset: (offset, 0.0),
            across: None,
            residual,
        };
        let (clean, mixed) = (MAX_LARGE_PATCH_RESIDUAL, MAX_LARGE_PATCH_RESIDUAL + 0.01);
        let base = vec![((4, 4), cue(0, 1.0, 0.3)), ((4, 4), cue(8, 1.0, 0.05)), ((6, 4), cue(0, 1.0, 0.05))];
        // The same patch in another view is another cue; (8, 4) has no base cue.
        let large =
            vec![((4, 4), cue(8, 2.0, mixed)), ((4, 4), cue(0, 2.0, clean)), ((8, 4), cue(0, 2.0, 0.0)), ((10, 4), cue(0, 2.0, mixed))];
        let cues = prefer_large_patches(base, large);
        let got: Vec<(usize, f64)> = cues.iter().map(|c| (c.view.col, c.offset.0)).collect();
        assert_eq!(got, vec![(0, 2.0), (8, 1.0), (0, 1.0), (0, 2.0)]);
        assert_eq!(cues[3].residual, 0.0);
    }

    #[test]
    fn the_disparity_gradient_is_the_plane_through_the_neighbours() {
        let slanted = patches(|x, y| 0.3 + 0.01 * x - 0.02 * y);
        let (sx, sy) = slanted.slope_at((30, 30), 4).unwrap();
        assert!((sx - 0.01).abs() < 1e-9 && (sy + 0.02).abs() < 1e-9, "{sx} {sy}");
        // Beyond the corner of the area only four patches lie within reach.
        assert!(slanted.slope_at((8, 8), 4).is_none());
    }

    #[test]
    fn a_depth_edge_or_a_sparse_neighbourhood_gives_no_gradient() {
        // A foreground half 0.5 px nearer than the background: no plane fits across it.
        let edge = patches(|x, _| if x < 30.0 { 0.5 } else { 0.0 });
        assert!(edge.slope_at((30, 30), 4).is_none());
        assert!(edge.slope_at((20, 30), 4).is_some());
        // Neighbours on one row only do not fix the vertical gradient.
        let row = PatchDisparities::new(
            &[(8, 20), (10, 20), (12, 20), (14, 20), (16, 20), (6, 20), (4, 20), (18, 20), (20, 20)],
            vec![Some(0.1); 9],
            2,
        );
        assert!(row.slope_at((12, 20), 4).is_none());
    }
}
