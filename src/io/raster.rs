//! `Raster`: a float image of 1 or 3 channels, the in-memory form of every view and map.

/// A `width x height` image with `channels` interleaved float channels, stored row by row from
/// the top. Views from 8/16-bit files hold values in [0, 1]; EXR views hold linear values as
/// stored; disparity and depth maps are single-channel rasters.
#[derive(Debug, Clone, PartialEq)]
pub struct Raster {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Channels per pixel: 1 (grey or a scalar map) or 3 (RGB).
    pub channels: usize,
    /// `height * width * channels` values, row-major, channels interleaved.
    pub data: Vec<f32>,
}

impl Raster {
    /// A raster of zeros.
    pub fn zeros(width: usize, height: usize, channels: usize) -> Self {
        Self { width, height, channels, data: vec![0.0; width * height * channels] }
    }

    /// A one-channel raster whose pixel (x, y) is `f(x, y)`.
    pub fn from_fn(width: usize, height: usize, f: impl Fn(usize, usize) -> f32) -> Self {
        Self { width, height, channels: 1, data: (0..width * height).map(|i| f(i % width, i / width)).collect() }
    }

    /// `from_fn` for tests written in f64: pixel (x, y) is `f(x, y)` at its integer coordinates.
    #[cfg(test)]
    pub(crate) fn from_f64_fn(width: usize, height: usize, f: impl Fn(f64, f64) -> f64) -> Self {
        Self::from_fn(width, height, |x, y| f(x as f64, y as f64) as f32)
    }

    /// Wraps `data`; `None` when its length does not match the size.
    pub fn from_vec(width: usize, height: usize, channels: usize, data: Vec<f32>) -> Option<Self> {
        (data.len() == width * height * channels).then_some(Self { width, height, channels, data })
    }

    /// Number of pixels.
    pub fn pixels(&self) -> usize {
        self.width * self.height
    }

    /// Value of channel `ch` at column `x`, row `y`.
    #[inline]
    pub fn get(&self, x: usize, y: usize, ch: usize) -> f32 {
        self.data[(y * self.width + x) * self.channels + ch]
    }

    /// Sets channel `ch` at column `x`, row `y`.
    #[inline]
    pub fn set(&mut self, x: usize, y: usize, ch: usize, value: f32) {
        self.data[(y * self.width + x) * self.channels + ch] = value;
    }

    /// Bilinear sample of channel `ch` at real position (`x`, `y`) in pixel units (pixel centres
    /// at integers); `None` outside the image.
    pub fn sample_bilinear(&self, x: f32, y: f32, ch: usize) -> Option<f32> {
        if !(x >= 0.0 && y >= 0.0 && x <= (self.width - 1) as f32 && y <= (self.height - 1) as f32) {
            return None;
        }
        let x0 = (x.floor() as usize).min(self.width.saturating_sub(2));
        let y0 = (y.floor() as usize).min(self.height.saturating_sub(2));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let x1 = (x0 + 1).min(self.width - 1);
        let y1 = (y0 + 1).min(self.height - 1);
        let top = self.get(x0, y0, ch) * (1.0 - fx) + self.get(x1, y0, ch) * fx;
        let bottom = self.get(x0, y1, ch) * (1.0 - fx) + self.get(x1, y1, ch) * fx;
        Some(top * (1.0 - fy) + bottom * fy)
    }

    /// The luminance (Rec. 709 weights) of an RGB raster, or a copy of a grey one.
    pub fn to_grey(&self) -> Raster {
        if self.channels == 1 {
            return self.clone();
        }
        let data = self.data.chunks_exact(self.channels).map(|p| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]).collect();
        Raster { width: self.width, height: self.height, channels: 1, data }
    }
}
