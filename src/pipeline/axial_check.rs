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
//! motion that one region of the image alone pins is not confirmed.

use super::cue_support::{WeighedComponent, weighed_components};
use super::measured_cues::Cue;
use crate::geometry::Camera;
use crate::model::motion::MotionModel;

/// The central view is cut into this many blocks along each side for the jackknife.
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
    /// Blocks of the central view with cues.
    pub blocks: usize,
}

impl AxialSupport {
    /// Whether the cues confirm the axial part at the threshold `min_share`: its support lies
    /// at or over it by at least two standard errors.
    pub fn confirms(&self, min_share: f64) -> bool {
        self.share - 2.0 * self.standard_error >= min_share
    }
}

/// The entries of `model`'s parameter vector along or about the optical axis (Z).
pub fn axial_entries(model: &dyn MotionModel) -> Vec<usize> {
    model.parameters().iter().enumerate().filter(|(_, k)| k.axis == 2).map(|(i, _)| i).collect()
}

/// The support `cues` give the axial entries of `parameters` (SI) against the same motion with
/// them at 0. `None` when the model has no such entries, they are all 0, fewer than 100 cues are
/// imaged or fewer than six blocks of the view hold cues.
pub fn axial_support(camera: &Camera, model: &dyn MotionModel, parameters: &[f64], cues: &[Cue]) -> Option<AxialSupport> {
    let axial = axial_entries(model);
    if axial.iter().all(|&i| parameters[i] == 0.0) {
        return None;
    }
    let mut without = parameters.to_vec();
    axial.iter().for_each(|&i| without[i] = 0.0);
    let (components, _) = weighed_components(camera, &model.record(&without), &model.record(parameters), cues)?;
    block_jackknife(camera, &components)
}

/// The least-squares share `1 + Σ w r p / Σ w p²` of the components and its delete-one-block
/// jackknife standard error, `sqrt((B-1)/B Σ (s₋ᵦ - s̄)²)`.
fn block_jackknife(camera: &Camera, components: &[WeighedComponent]) -> Option<AxialSupport> {
    let side = |x: f64, extent: usize| ((x / extent as f64 * BLOCKS_PER_SIDE as f64).floor().max(0.0) as usize).min(BLOCKS_PER_SIDE - 1);
    let mut sums = vec![(0.0, 0.0); BLOCKS_PER_SIDE * BLOCKS_PER_SIDE];
    for c in components {
        let block = side(c.at.1, camera.height) * BLOCKS_PER_SIDE + side(c.at.0, camera.width);
        sums[block].0 += c.weight * c.residual * c.part;
        sums[block].1 += c.weight * c.part * c.part;
    }
    let filled: Vec<(f64, f64)> = sums.into_iter().filter(|&(_, den)| den > 0.0).collect();
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
    use crate::io::MotionRecord;
    use crate::model::motion::ConstantVelocity;
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

    #[test]
    fn a_true_roll_and_forward_motion_is_confirmed() {
        let truth = [0.0, 0.2, 0.6, 0.5, 0.0, 3.0];
        let support = axial_support(&camera(), &ConstantVelocity, &truth, &cues(|_, _| record(&truth))).expect("judged");
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
        let support = axial_support(&camera(), &ConstantVelocity, &spurious, &measured).expect("judged");
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
    fn a_motion_without_an_axial_part_is_not_judged() {
        let pan = [0.0, 0.1, 0.0, 0.4, 0.0, 0.0];
        assert_eq!(axial_support(&camera(), &ConstantVelocity, &pan, &cues(|_, _| record(&pan))), None);
        assert_eq!(axial_entries(&ConstantVelocity), vec![2, 5]);
    }
}
