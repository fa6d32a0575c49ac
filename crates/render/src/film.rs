//! The image being rendered and its outputs: per-pixel sums (and sums of
//! squares, for standard errors) over the samples taken so far, written as a
//! linear OpenEXR file and a tone-mapped sRGB PNG, each atomically (a
//! temporary file in the same directory, then a rename).
//!
//! The PNG's tone map is a clamp of `exposure * L` followed by the sRGB
//! transfer function (IEC 61966-2-1).

use crate::error::RenderError;
use paperbsdf_core::Rgb;
use std::path::Path;

/// Per-pixel accumulators; pixel `(x, y)` is at index `y * width + x`, `(0, 0)` top-left.
#[derive(Clone, Debug)]
pub struct Film {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Sum of the radiance samples of each pixel.
    pub sum: Vec<[f64; 3]>,
    /// Sum of the squared samples.
    pub sum_sq: Vec<[f64; 3]>,
    /// Number of samples taken in each pixel.
    pub count: Vec<u32>,
}

impl Film {
    /// An empty film.
    pub fn new(width: usize, height: usize) -> Film {
        let n = width * height;
        Film {
            width,
            height,
            sum: vec![[0.0; 3]; n],
            sum_sq: vec![[0.0; 3]; n],
            count: vec![0; n],
        }
    }
    /// The pixel's mean radiance (zero before any sample).
    pub fn mean(&self, i: usize) -> Rgb {
        let n = self.count[i].max(1) as f64;
        Rgb(self.sum[i]) / n
    }
    /// The variance of the pixel's mean (sample variance / n), per channel.
    pub fn var_of_mean(&self, i: usize) -> Rgb {
        let n = self.count[i] as f64;
        if n < 2.0 {
            return Rgb::splat(f64::INFINITY);
        }
        let m = Rgb(self.sum[i]) / n;
        let ex2 = Rgb(self.sum_sq[i]) / n;
        (ex2 - m * m).map(|v| v.max(0.0) * n / (n - 1.0) / n)
    }
    /// Mean radiance image, row-major.
    pub fn image(&self) -> Vec<Rgb> {
        (0..self.width * self.height).map(|i| self.mean(i)).collect()
    }
    /// Smallest sample count over the pixels.
    pub fn min_count(&self) -> u32 {
        self.count.iter().copied().min().unwrap_or(0)
    }
}

/// Writes `write(tmp)` then renames it to `path`, with the project's shared
/// atomic writer (symbolic links written through, non-regular targets refused,
/// temporary files removed by the Ctrl-C handler).
fn atomic(path: &Path, write: impl FnOnce(&Path) -> Result<(), RenderError>) -> Result<(), RenderError> {
    paperbsdf_io::atomic::write_atomic_with(path, write).map_err(RenderError::Output)
}

/// The error of reading or writing the image file `path` in `format`.
fn file_error(verb: &'static str, format: &'static str, path: &Path, reason: impl std::fmt::Display) -> RenderError {
    RenderError::ImageFile {
        verb,
        format,
        path: path.to_path_buf(),
        reason: reason.to_string(),
    }
}

/// Writes a linear RGB image (row-major, top row first) as 32-bit float OpenEXR, atomically.
pub fn write_exr(path: &Path, width: usize, height: usize, pixels: &[Rgb]) -> Result<(), RenderError> {
    use exr::prelude::*;
    atomic(path, |tmp| {
        let layer = Layer::new(
            (width, height),
            LayerAttributes::named("rgb"),
            Encoding::FAST_LOSSLESS,
            SpecificChannels::rgb(|p: Vec2<usize>| {
                let c = pixels[p.y() * width + p.x()].0;
                (c[0] as f32, c[1] as f32, c[2] as f32)
            }),
        );
        Image::from_layer(layer)
            .write()
            .to_file(tmp)
            .map_err(|e| file_error("write", "EXR", path, e))
    })
}

/// Reads the RGB channels of an OpenEXR file: `(width, height, pixels)`, top row first.
pub fn read_exr(path: &Path) -> Result<(usize, usize, Vec<Rgb>), RenderError> {
    use exr::prelude::*;
    let img = read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), res.height(), vec![Rgb::ZERO; res.width() * res.height()]),
        |(w, _h, px): &mut (usize, usize, Vec<Rgb>), pos: Vec2<usize>, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = Rgb::new(r as f64, g as f64, b as f64);
        },
    )
    .map_err(|e| file_error("read", "EXR", path, e))?;
    let (w, h, px) = img.layer_data.channel_data.pixels;
    Ok((w, h, px))
}

/// The sRGB transfer function of a linear value in [0, 1].
pub fn linear_to_srgb(v: f64) -> f64 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Writes `exposure * pixels`, clamped and sRGB-encoded, as an 8-bit PNG, atomically.
pub fn write_png(path: &Path, width: usize, height: usize, pixels: &[Rgb], exposure: f64) -> Result<(), RenderError> {
    let mut buf = Vec::with_capacity(width * height * 3);
    for p in pixels {
        for c in 0..3 {
            let v = (p.0[c] * exposure).clamp(0.0, 1.0);
            let v = if v.is_nan() { 0.0 } else { v };
            buf.push((linear_to_srgb(v) * 255.0 + 0.5) as u8);
        }
    }
    let img = image::RgbImage::from_raw(width as u32, height as u32, buf).ok_or(RenderError::BufferSize)?;
    atomic(path, |tmp| {
        img.save_with_format(tmp, image::ImageFormat::Png)
            .map_err(|e| file_error("write", "PNG", path, e))
    })
}
