//! The framework on something other than light fields: fitting 2D Gaussians to one image.
//!
//! The model is rslf's `Gaussians` module (disparity unused: one view), the forward function is
//! the splatting renderer, the objective is L1 + D-SSIM from the loss registry, and the stage is
//! `optim::optimise` with one learning rate per parameter group.
//!
//! `cargo run --release --example fit_image [-- IMAGE.png]` (default: a generated test image).

use burn::tensor::Device;
use rslf::config::LossConfig;
use rslf::eval::psnr_db;
use rslf::io::{Raster, read_image};
use rslf::loss::{LossInput, LossRegistry};
use rslf::model::Gaussians;
use rslf::optim::{GroupPlan, Plan, Schedule, Stage, optimise};
use rslf::pipeline::{LearningRates, image_tensor, sample_gaussians, with_gaussian_groups};
use rslf::render::{RenderSettings, render_rows};
use std::time::Instant;

/// What the fit achieved.
#[derive(Debug)]
struct Outcome {
    gaussians: usize,
    psnr_before_db: f64,
    psnr_after_db: f64,
    seconds: f64,
}

/// A 96x96 colour test image: soft rings, a disc and a checker corner.
fn test_image() -> Raster {
    let (w, h) = (96usize, 96usize);
    let mut data = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = (x as f32 / w as f32 - 0.5, y as f32 / h as f32 - 0.5);
            let r = (u * u + v * v).sqrt();
            let ring = 0.5 + 0.5 * (r * 40.0).sin();
            let disc = if ((u - 0.2).powi(2) + (v + 0.2).powi(2)).sqrt() < 0.12 { 1.0 } else { 0.0 };
            let checker = if x < 32 && y >= 64 && (x / 8 + y / 8) % 2 == 0 { 1.0 } else { 0.0 };
            data.extend([0.2 + 0.6 * ring * (1.0 - disc), 0.3 + 0.6 * disc, 0.15 + 0.7 * checker]);
        }
    }
    Raster { width: w, height: h, channels: 3, data }
}

/// Renders `g` as one whole image.
fn render_image(g: &Gaussians, w: usize, h: usize, settings: &RenderSettings, device: &Device) -> Raster {
    let out = render_rows(g, (0.0, 0.0), w, 0..h, settings, device);
    let data = rslf::device::host_values(out.colour);
    Raster { width: w, height: h, channels: g.colour.val().dims()[1], data: data.into_iter().map(|x| x.clamp(0.0, 1.0)).collect() }
}

/// Fits `n` Gaussians to `image` in `iterations` Adam steps.
fn fit(image: &Raster, n: usize, iterations: usize) -> Outcome {
    let device = rslf::device::device(rslf::config::DeviceChoice::Flex).expect("flex is always there");
    let (w, h) = (image.width, image.height);
    let settings = RenderSettings::default();
    let flat = Raster { width: w, height: h, channels: 1, data: vec![0.0; w * h] };
    let start = sample_gaussians(image, &flat, n, 0).to_module(&device);
    let region = vec![true; w * h];
    let psnr_before_db = psnr_db(&render_image(&start, w, h, &settings, &device), image, &region);

    let losses = LossRegistry::default().build(&[LossConfig::new("l1", 0.8), LossConfig::new("dssim", 0.2)]).expect("built-in terms");
    let lr = LearningRates { position: 0.2, disparity: 0.0, size: 0.02, colour: 0.02 };
    let default = GroupPlan { schedule: Schedule::Constant(0.0), adam_epsilon: 1e-8 };
    let stage = Stage { iterations, plan: with_gaussian_groups(Plan::new(default), &start, &lr, 1e-8) };
    let target = image_tensor(image, &device);
    let objective = |g: &Gaussians, _step: usize| {
        let rendered = render_rows(g, (0.0, 0.0), w, 0..h, &settings, &device);
        losses.evaluate(&LossInput { rendered: &rendered, target: &target, rows: h, width: w, motion: None })
    };
    let clock = Instant::now();
    let (fitted, _curve) = optimise(start, &stage, objective, |_| {});
    let seconds = clock.elapsed().as_secs_f64();
    let psnr_after_db = psnr_db(&render_image(&fitted, w, h, &settings, &device), image, &region);
    Outcome { gaussians: n, psnr_before_db, psnr_after_db, seconds }
}

#[cfg_attr(test, allow(dead_code))]
fn main() {
    let image = match std::env::args_os().nth(1) {
        Some(path) => read_image(path.as_ref()).unwrap_or_else(|e| {
            eprintln!("error: {e}");
            std::process::exit(1)
        }),
        None => test_image(),
    };
    let n = image.pixels() / 3;
    let o = fit(&image, n, 300);
    println!(
        "fitted {} Gaussians to a {}x{} image in {:.1} s: PSNR {:.2} dB -> {:.2} dB",
        o.gaussians, image.width, image.height, o.seconds, o.psnr_before_db, o.psnr_after_db
    );
}

#[cfg(test)]
mod tests {
    #[test]
    fn fitting_raises_psnr_well_above_the_sampled_start() {
        let o = super::fit(&super::test_image(), 3000, 300);
        println!("{o:?}");
        assert!(o.psnr_after_db > o.psnr_before_db + 3.0, "{o:?}");
        assert!(o.psnr_after_db > 25.0, "{o:?}");
    }
}
