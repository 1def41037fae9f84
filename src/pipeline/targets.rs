//! The observed views a fit compares against, cut into the bands of rows it renders.

use crate::geometry::ViewId;
use crate::io::{Raster, Scene};
use burn::tensor::{Device, Tensor, TensorData};
use std::ops::Range;

/// The present views of `views`, each with its offset `(c - cc, r - rc)`.
pub fn view_targets<'a>(scene: &'a Scene, views: &[ViewId]) -> Vec<((f32, f32), &'a Raster)> {
    views
        .iter()
        .filter_map(|&v| {
            let (dx, dy) = scene.grid.offset(v);
            Some(((dx as f32, dy as f32), scene.view(v)?))
        })
        .collect()
}

/// Rows `rows` of a view as a `[P, C]` tensor.
pub fn band_tensor(img: &Raster, rows: Range<usize>, device: &Device) -> Tensor<2> {
    let (w, c) = (img.width, img.channels);
    let data = img.data[rows.start * w * c..rows.end * w * c].to_vec();
    Tensor::from_data(TensorData::new(data, [rows.len() * w, c]), device)
}
