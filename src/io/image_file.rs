//! Reading views from PNG (8/16-bit, grey or RGB, alpha dropped) and EXR (linear float), and
//! writing 8-bit PNGs.

use super::atomic::write_atomic;
use super::error::{IoError, IoResult};
use super::raster::Raster;
use image::ImageEncoder;
use std::path::Path;

/// Reads a PNG or EXR image (chosen by extension) into a raster of 1 or 3 channels.
/// PNG values are scaled to [0, 1]; EXR values are kept as stored.
pub fn read_image(path: &Path) -> IoResult<Raster> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let bytes = std::fs::read(path).map_err(|e| IoError::os(path, e))?;
    match ext.as_str() {
        "png" => decode_png(&bytes),
        "exr" => decode_exr(&bytes),
        _ => Err(format!("unsupported image type `.{ext}` (expected .png or .exr)")),
    }
    .map_err(|problem| IoError::new(path, problem))
}

fn decode_png(bytes: &[u8]) -> Result<Raster, String> {
    use image::DynamicImage as D;
    let img = image::load_from_memory_with_format(bytes, image::ImageFormat::Png).map_err(|e| format!("unreadable PNG: {e}"))?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    let (channels, data): (usize, Vec<f32>) = match img {
        D::ImageLuma8(b) => (1, b.into_raw().into_iter().map(|v| v as f32 / 255.0).collect()),
        D::ImageLumaA8(_) => (1, img.to_luma8().into_raw().into_iter().map(|v| v as f32 / 255.0).collect()),
        D::ImageLuma16(b) => (1, b.into_raw().into_iter().map(|v| v as f32 / 65535.0).collect()),
        D::ImageLumaA16(_) => (1, img.to_luma16().into_raw().into_iter().map(|v| v as f32 / 65535.0).collect()),
        D::ImageRgb8(b) => (3, b.into_raw().into_iter().map(|v| v as f32 / 255.0).collect()),
        D::ImageRgba8(_) => (3, img.to_rgb8().into_raw().into_iter().map(|v| v as f32 / 255.0).collect()),
        D::ImageRgb16(b) => (3, b.into_raw().into_iter().map(|v| v as f32 / 65535.0).collect()),
        D::ImageRgba16(_) => (3, img.to_rgb16().into_raw().into_iter().map(|v| v as f32 / 65535.0).collect()),
        other => (3, other.to_rgb32f().into_raw()),
    };
    Raster::from_vec(w, h, channels, data).ok_or_else(|| "PNG data does not match its size".to_string())
}

fn decode_exr(bytes: &[u8]) -> Result<Raster, String> {
    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .pedantic()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| format!("unreadable EXR: {e}"))?;
    let layer = &image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    let list = &layer.channel_data.list;
    // Channel names may carry a layer prefix ("beauty.R"); match on the last component.
    let find = |name: &str| {
        list.iter().find(|c| {
            let full = c.name.to_string();
            full.rsplit('.').next().is_some_and(|n| n.eq_ignore_ascii_case(name))
        })
    };
    let picked: Vec<_> = match (find("R"), find("G"), find("B"), find("Y")) {
        (Some(r), Some(g), Some(b), _) => vec![r, g, b],
        (_, _, _, Some(y)) => vec![y],
        _ if list.len() == 1 => vec![&list[0]],
        _ => {
            let names: Vec<String> = list.iter().map(|c| c.name.to_string()).collect();
            return Err(format!("EXR has channels {names:?}; expected R, G, B or Y"));
        }
    };
    let planes: Vec<Vec<f32>> = picked.iter().map(|c| c.sample_data.values_as_f32().collect()).collect();
    if planes.iter().any(|p| p.len() != w * h) {
        return Err("EXR channel data does not match its size".into());
    }
    let channels = planes.len();
    let mut data = vec![0.0; w * h * channels];
    for (ch, plane) in planes.iter().enumerate() {
        for (i, v) in plane.iter().enumerate() {
            data[i * channels + ch] = *v;
        }
    }
    Ok(Raster { width: w, height: h, channels, data })
}

/// Writes a 1- or 3-channel raster as an 8-bit PNG (values clamped to [0, 1]), whole or not at all.
pub fn write_png(path: &Path, img: &Raster) -> IoResult<()> {
    let to_u8 = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    let bytes: Vec<u8> = img.data.iter().map(|&v| to_u8(v)).collect();
    let color = match img.channels {
        1 => image::ExtendedColorType::L8,
        3 => image::ExtendedColorType::Rgb8,
        n => return Err(IoError::new(path, format!("cannot write a {n}-channel PNG"))),
    };
    let mut encoded = Vec::new();
    image::codecs::png::PngEncoder::new(&mut encoded)
        .write_image(&bytes, img.width as u32, img.height as u32, color)
        .map_err(|e| IoError::new(path, format!("PNG encoding failed: {e}")))?;
    write_atomic(path, &encoded)
}

/// Writes a mask (non-zero = set) as an 8-bit grey PNG of 0 and 255.
pub fn write_mask_png(path: &Path, mask: &[bool], width: usize, height: usize) -> IoResult<()> {
    let data = mask.iter().map(|&m| if m { 1.0 } else { 0.0 }).collect();
    let raster = Raster::from_vec(width, height, 1, data).ok_or_else(|| IoError::new(path, "mask length does not match its size"))?;
    write_png(path, &raster)
}
