//! Whether the cues measured between the views bear out the part of a fitted motion along and
//! about the optical axis (forward translation and roll), judged with a standard error from
//! blocks of the image.
//!
//! Forward motion and roll are the least observed rates: they move a pixel in proportion to its
//! distance from the image centre, not to the focal length, so their cues are a few hundredths
//! of a pixel on a slow motion. The cues' own errors are not independent from patch to patch:
//! a fence or a cluster of branches shares one bias of the matching, and the check's standard
//! error ([`super::CueSupport`]), which assumes independence, is then far too small. Here the
//! error comes from a jackknife over blocks of the central view instead, so a part of the
//! motion that one region of the image alone pins is not confirmed. A model with a set of rates
//! per segment of the read-out has each segment's judged on its own, over the blocks of the rows
//! it moves.

use super::cue_support::{WeighedComponent, weighed_components};
use super::measured_cues::Cue;
use crate::geometry::Camera;
use crate::io::MotionRecord;
use crate::model::motion::MotionModel;

/// The central view is cut into this many columns of blocks for the jackknife, and this many
/// rows per group of axial entries ([`axial_groups`]).
pub const BLOCKS_PER_SIDE: usize = 4;
/// Fewest blocks with cues a judgement is made from.
const MIN_BLOCKS: usize = 6;

/// The support the measured cues give the axial part of an estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxialSupport {
    /// The scale of the axial part's predicted cues that fits the measured ones best, the rest
    /// of the motion held (1: borne out; 0: the cues show none of it).
    pub share: f64,
    /// Its standard error: the delete-one-block jackknife's over the blocks with cues.
    pub standard_error: f64,
    /// Blocks of the central view with cues that the part moves.
    pub blocks: usize,
}

impl AxialSupport {
    /// Whether the cues confirm the axial part at the threshold `min_share`: its support lies
    /// at or over it by at least two standard errors.
    pub fn confirms(&self, min_share: f64) -> bool {
        self.share - 2.0 * self.standard_error >= min_share
    }
}

/// The entries of `model`'s parameter vector along or about the optical axis (Z), in groups:
/// the k-th entry of each kind (quantity and order) goes to group k. A model with one set of
/// rates has one group; `piecewise_constant` has one per segment, so that each segment's roll
/// and forward motion is judged by the cues of the rows it moves.
pub fn axial_groups(model: &dyn MotionModel) -> Vec<Vec<usize>> {
    let kinds = model.parameters();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, kind) in kinds.iter().enumerate().filter(|(_, k)| k.axis == 2) {
        let k = kinds[..i].iter().filter(|&earlier| earlier == kind).count();
        if groups.len() <= k {
            groups.resize(k + 1, Vec::new());
        }
        groups[k].push(i);
    }
    groups
}

/// One group of axial entries and what the cues show of it.
#[derive(Debug, Clone, PartialEq)]
pub struct AxialJudgement {
    /// The group's index among [`axial_groups`] (the segment of a piecewise model).
    pub group: usize,
    /// The group's entries in the parameter vector.
    pub entries: Vec<usize>,
    /// The cues' support; `None` where fewer than 100 cues are imaged or fewer than six blocks
    /// hold cues that the group moves.
    pub support: Option<AxialSupport>,
}

/// The support `cues` give each group of axial entries of `parameters` (SI; [`axial_groups`])
/// against the same motion with that group at 0 and the rest as it is, with the view cut into
/// 4 columns and 4 rows per group of blocks. One judgement per group with an entry that is not
/// 0, in the groups' order.
pub fn axial_support(camera: &Camera, model: &dyn MotionModel, parameters: &[f64], cues: &[Cue]) -> Vec<AxialJudgement> {
    let groups = axial_groups(model);
    let block_rows = BLOCKS_PER_SIDE * groups.len().max(1);
    let estimate = model.record(parameters);
    groups
        .into_iter()
        .enumerate()
        .filter(|(_, entries)| entries.iter().any(|&i| parameters[i] != 0.0))
        .map(|(group, entries)| {
            let mut without = parameters.to_vec();
            entries.iter().for_each(|&i| without[i] = 0.0);
            let support = weighed_components(camera, &model.record(&without), &estimate, cues)
                .and_then(|(components, _)| block_jackknife(camera, &components, block_rows));
            AxialJudgement { group, entries, support }
        })
        .collect()
}

/// The support `cues` give the part of `estimate` that `base` lacks, with the block jackknife's
/// standard error over `BLOCKS_PER_SIDE` x `BLOCKS_PER_SIDE` blocks of the view, as
/// [`axial_support`] judges one group. `None` where fewer than 100 cues are imaged or fewer
/// than six blocks hold cues that the part moves.
pub fn part_support(camera: &Camera, base: &MotionRecord, estimate: &MotionRecord, cues: &[Cue]) -> Option<AxialSupport> {
    weighed_components(camera, base, estimate, cues).and_then(|(components, _)| block_jackknife(camera, &components, BLOCKS_PER_SIDE))
}

/// The least-squares share `1 + Σ w r p / Σ w p²` of the components and its delete-one-block
/// jackknife standard error, `sqrt((B-1)/B Σ (s₋ᵦ - s̄)²)`, over `BLOCKS_PER_SIDE` columns and
/// `block_rows` rows of blocks. Blocks whose `Σ w p²` is under 1e-9 of the largest block's hold
/// no cue the part moves and are left out.
fn block_jackknife(camera: &Camera, components: &[WeighedComponent], block_rows: usize) -> Option<AxialSupport> {
    let index = |x: f64, extent: usize, blocks: usize| ((x / extent as f64 * blocks as f64).floor().max(0.0) as usize).min(blocks - 1);
    let mut sums = vec![(0.0, 0.0); BLOCKS_PER_SIDE * block_rows];
    for c in components {
        let block = index(c.at.1, camera.height, block_rows) * BLOCKS_PER_SIDE + index(c.at.0, camera.width, BLOCKS_PER_SIDE);
        sums[block].0 += c.weight * c.residual * c.part;
        sums[block].1 += c.weight * c.part * c.part;
    }
    let largest = sums.iter().map(|&(_, den)| den).fold(0.0, f64::max);
    let filled: Vec<(f64, f64)> = sums.into_iter().filter(|&(_, den)| den > 1e-9 * largest).collect();
    let (num, den) = filled.iter().fold((0.0, 0.0), |(n, d), &(bn, bd)| (n + bn, d + bd));
    if filled.len() < MIN_BLOCKS || den <= 1e-12 {
        return None;
    }
    let left_one_out: Vec<f64> =
        filled.iter().filter(|&&(_, bd)| den - bd > 1e-12 * den).map(|&(bn, bd)| 1.0 + (num - bn) / (den - bd)).collect();
    let b = left_one_out.len() as f64;
    if left_one_out.len() < MIN_BLOCKS {
        return None;
    }
    let mean = left_one_out.iter().sum::<f64>() / b;
    let variance = (b - 1.0) / b * left_one_out.iter().map(|s| (s - mean).powi(2)).sum::<f64>();
    Some(AxialSupport { share: 1.0 + num / den, standard_error: variance.sqrt(), blocks: filled.len() })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::readout_interval;
    use crate::io::MotionRecord;
    use crate::model::motion::{ConstantVelocity, PiecewiseConstant};
    use crate::pipeline::cue_support::tests::camera;
    use crate::pipeline::predicted_cue;
    use crate::random::Rng;

    /// Two-way cues on a 20 x 20 grid of each corner, with disparities from -1.5 to 1.5 px,
    /// measured under `truth(x, y)` (the motion at the patch) with Gaussian noise of 0.02 px.
    fn cues(truth: impl Fn(f64, f64) -> MotionRecord) -> Vec<Cue> {
        let cam = camera();
        let mut rng = Rng::new(5);
        let mut normal = move || (-2.0 * rng.unit().max(1e-12).ln()).sqrt() * (std::f64::consts::TAU * rng.unit()).cos();
        let mut out = Vec::new();
        for view in cam.grid.corners() {
            for i in 0..400 {
                let at = (12.0 + (i % 20) as f64 * 12.0, 12.0 + (i / 20) as f64 * 12.0);
                let disparity = -1.5 + 3.0 * ((i * 7919) % 400) as f64 / 399.0;
                let mut cue = Cue { at, disparity, view, offset: (0.0, 0.0), across: None, residual: 0.0 };
                let Some(p) = predicted_cue(&cam, &truth(at.0, at.1), &cue) else { continue };
                cue.offset = (p.0 + 0.02 * normal(), p.1 + 0.02 * normal());
                out.push(cue);
            }
        }
        out
    }

    fn record(p: &[f64; 6]) -> MotionRecord {
        ConstantVelocity.record(p)
    }

    /// The one judgement of a constant-velocity estimate.
    fn judged(parameters: &[f64; 6], measured: &[Cue]) -> AxialSupport {
        let judgements = axial_support(&camera(), &ConstantVelocity, parameters, measured);
        assert_eq!(judgements.len(), 1, "{judgements:?}");
        assert_eq!(judgements[0].entries, vec![2, 5]);
        judgements[0].support.expect("judged")
    }

    #[test]
    fn a_true_roll_and_forward_motion_is_confirmed() {
        let truth = [0.0, 0.2, 0.6, 0.5, 0.0, 3.0];
        let support = judged(&truth, &cues(|_, _| record(&truth)));
        assert!((support.share - 1.0).abs() < 0.05, "{support:?}");
        assert!(support.confirms(0.5) && support.blocks == 16, "{support:?}");
    }

    #[test]
    fn an_axial_part_that_one_region_alone_shows_is_not_confirmed() {
        // A pan with a sideways slide, and the same with a small roll and forward motion.
        let truth = [0.0, 0.1, 0.0, 0.4, 0.0, 0.0];
        let spurious = [0.0, 0.1, 0.05, 0.4, 0.0, -0.6];
        // The bottom quarter of the image (a fence, say) shows three times the spurious part; the
        // rest shows none of it.
        let bottom = [0.0, 0.1, 0.15, 0.4, 0.0, -1.8];
        let measured = cues(|_, y| record(if y >= 192.0 { &bottom } else { &truth }));
        let support = judged(&spurious, &measured);
        // Taken as independent, the cues would confirm it: their standard error is small.
        let without = [0.0, 0.1, 0.0, 0.4, 0.0, 0.0];
        let (components, _) = weighed_components(&camera(), &record(&without), &record(&spurious), &measured).unwrap();
        let independent = components.iter().map(|c| c.weight * c.part * c.part).sum::<f64>().sqrt().recip();
        assert!(support.share - 2.0 * independent >= 0.5, "{support:?}, independent error {independent}");
        // The blocks tell that one region carries it.
        assert!(!support.confirms(0.5), "{support:?}");
        assert!(support.standard_error > 3.0 * independent, "{support:?}, independent error {independent}");
    }

    #[test]
    fn a_move_the_cues_show_is_confirmed_and_one_that_one_region_alone_shows_is_not() {
        // A pan with a sideways slide; a fit off it along the trade of the two (the pan short,
        // the slide long), moved back to the truth: the cues bear the move out everywhere (to
        // within their noise: along the trade the move's cues are small).
        let truth = [0.0, 0.1, 0.0, 0.4, 0.0, 0.0];
        let off = [0.0, 0.02, 0.0, 0.8, 0.0, 0.0];
        let support = part_support(&camera(), &record(&off), &record(&truth), &cues(|_, _| record(&truth))).expect("judged");
        assert!(support.confirms(0.5) && (support.share - 1.0).abs() < 2.5 * support.standard_error, "{support:?}");
        // The same move where only the bottom quarter of the image shows it (twice over) and the
        // rest shows the fit: the blocks disagree.
        let bottom = [0.0, 0.18, 0.0, 0.0, 0.0, 0.0];
        let measured = cues(|_, y| record(if y >= 192.0 { &bottom } else { &off }));
        let support = part_support(&camera(), &record(&off), &record(&truth), &measured).expect("judged");
        assert!(!support.confirms(0.5), "{support:?}");
    }

    #[test]
    fn a_motion_without_an_axial_part_is_not_judged() {
        let pan = [0.0, 0.1, 0.0, 0.4, 0.0, 0.0];
        assert_eq!(axial_support(&camera(), &ConstantVelocity, &pan, &cues(|_, _| record(&pan))), vec![]);
        assert_eq!(axial_groups(&ConstantVelocity), vec![vec![2, 5]]);
    }

    #[test]
    fn each_segment_s_roll_and_forward_motion_is_judged_by_its_own_rows() {
        let cam = camera();
        let model = PiecewiseConstant { segments: 2, readout: readout_interval(cam.height, cam.line_time_s) };
        assert_eq!(axial_groups(&model), vec![vec![2, 5], vec![8, 11]]);
        // A pan with a sideways slide throughout, and a roll with a forward motion in the second
        // half of the read-out (the lower half of the image) only.
        let truth = [0.0, 0.1, 0.0, 0.4, 0.0, 0.0, 0.0, 0.1, 0.6, 0.4, 0.0, 3.0];
        // The estimate adds a roll and a forward motion to the first half.
        let estimate = [0.0, 0.1, 0.3, 0.4, 0.0, 2.0, 0.0, 0.1, 0.6, 0.4, 0.0, 3.0];
        let judgements = axial_support(&cam, &model, &estimate, &cues(|_, _| model.record(&truth)));
        assert_eq!(judgements.iter().map(|j| (j.group, j.entries.clone())).collect::<Vec<_>>(), vec![(0, vec![2, 5]), (1, vec![8, 11])]);
        let (first, second) = (judgements[0].support.expect("judged"), judgements[1].support.expect("judged"));
        assert!(!first.confirms(0.5) && first.share.abs() < 0.1, "{first:?}");
        assert!(second.confirms(0.5) && (second.share - 1.0).abs() < 0.1, "{second:?}");
        // Each is judged over the blocks of the rows it moves: 4 columns by 4 rows of the 8.
        assert!(first.blocks <= 20 && second.blocks <= 20, "{first:?} {second:?}");
    }
}
