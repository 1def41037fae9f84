//! The observed views a fit compares against, cut into the bands of rows it renders.

use crate::geometry::ViewId;
use crate::io::{Raster, Scene};
use burn::tensor::{Device, Tensor, TensorData};
use std::ops::Range;

/// One observed view a fit compares against.
pub struct ViewTarget<'a> {
    /// Which view.
    pub view: ViewId,
    /// Its offset `(c - cc, r - rc)` from the central view.
    pub offset: (f32, f32),
    /// Its pixels.
    pub image: &'a Raster,
}

/// The present views of `views`.
pub fn view_targets<'a>(scene: &'a Scene, views: &[ViewId]) -> Vec<ViewTarget<'a>> {
    views
        .iter()
        .filter_map(|&view| {
            let (dx, dy) = scene.grid.offset(view);
            Some(ViewTarget { view, offset: (dx as f32, dy as f32), image: scene.view(view)? })
        })
        .collect()
}

/// Rows `rows` of a view as a `[P, C]` tensor.
pub fn band_tensor(img: &Raster, rows: Range<usize>, device: &Device) -> Tensor<2> {
    let (w, c) = (img.width, img.channels);
    let data = img.data[rows.start * w * c..rows.end * w * c].to_vec();
    Tensor::from_data(TensorData::new(data, [rows.len() * w, c]), device)
}
