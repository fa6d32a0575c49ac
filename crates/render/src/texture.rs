//! Textures: colours (constant, checkerboard, image) and greyscale maps
//! (constant, checkerboard, image) looked up by surface coordinates `(u, v)`.
//!
//! Image textures are bilinearly filtered and repeat outside [0, 1]. `v = 0` is
//! the bottom row of the image, as in OBJ files, pbrt and Mitsuba. Colour images
//! are decoded from sRGB to linear; greyscale maps (masks, thickness and ink
//! maps) are used as stored, 0 = black, 1 = white, with no gamma.

use crate::error::ImageError;
use paperbsdf_core::Rgb;
use std::path::Path;
use std::sync::Arc;

/// A decoded image: `channels` floats per pixel, rows from the top.
#[derive(Debug)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// 3 (linear RGB) or 1 (grey).
    pub channels: usize,
    /// Pixel values, row-major, top row first.
    pub data: Vec<f32>,
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Largest width or height of a texture image, pixels.
pub const MAX_IMAGE_SIDE: u32 = 16384;
/// Largest decoding allocation of a texture image, bytes (256 MiB; the linear
/// float copy made from it is up to four times larger).
pub const MAX_IMAGE_BYTES: u64 = 256 << 20;

impl Image {
    /// Decodes an image file (PNG) as linear RGB (`grey = false`, sRGB decoded)
    /// or as a greyscale map (`grey = true`, values as stored).
    /// Images larger than [`MAX_IMAGE_SIDE`] on a side, or needing more than
    /// [`MAX_IMAGE_BYTES`] to decode, are refused before anything is allocated.
    pub fn load(path: &Path, grey: bool) -> Result<Image, ImageError> {
        let e = |e: image::ImageError| ImageError(format!("cannot read image '{}': {e}", path.display()));
        let mut r = image::ImageReader::open(path)
            .map_err(|x| e(x.into()))?
            .with_guessed_format()
            .map_err(|x| e(x.into()))?;
        r.limits(Self::limits());
        Ok(Self::from_dynamic(r.decode().map_err(e)?, grey))
    }
    /// Decodes an image held in memory (built-in scenes embed their masks), with the limits of [`Image::load`].
    pub fn from_bytes(bytes: &[u8], grey: bool) -> Result<Image, ImageError> {
        let e = |e: image::ImageError| ImageError(format!("cannot decode embedded image: {e}"));
        let mut r = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|x| e(x.into()))?;
        r.limits(Self::limits());
        Ok(Self::from_dynamic(r.decode().map_err(e)?, grey))
    }
    fn limits() -> image::Limits {
        let mut l = image::Limits::default();
        l.max_image_width = Some(MAX_IMAGE_SIDE);
        l.max_image_height = Some(MAX_IMAGE_SIDE);
        l.max_alloc = Some(MAX_IMAGE_BYTES);
        l
    }
    fn from_dynamic(img: image::DynamicImage, grey: bool) -> Image {
        let (width, height) = (img.width() as usize, img.height() as usize);
        if grey {
            let g = img.to_luma32f();
            Image {
                width,
                height,
                channels: 1,
                data: g.into_raw(),
            }
        } else {
            let c = img.to_rgb32f();
            let data = c.into_raw().into_iter().map(srgb_to_linear).collect();
            Image {
                width,
                height,
                channels: 3,
                data,
            }
        }
    }
    /// Bilinear lookup of channel `c` at `(u, v)`, repeating.
    fn bilinear(&self, u: f64, v: f64, c: usize) -> f64 {
        let x = u.rem_euclid(1.0) * self.width as f64 - 0.5;
        let y = (1.0 - v.rem_euclid(1.0)) * self.height as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let px = |xi: i64, yi: i64| -> f64 {
            let xi = xi.rem_euclid(self.width as i64) as usize;
            let yi = yi.rem_euclid(self.height as i64) as usize;
            self.data[(yi * self.width + xi) * self.channels + c] as f64
        };
        let (xi, yi) = (x0 as i64, y0 as i64);
        (1.0 - fy) * ((1.0 - fx) * px(xi, yi) + fx * px(xi + 1, yi))
            + fy * ((1.0 - fx) * px(xi, yi + 1) + fx * px(xi + 1, yi + 1))
    }
}

/// Whether `(u, v)` falls on an even square of a checkerboard with `scale` squares per unit of `u` and `v`.
fn checker_even(u: f64, v: f64, scale: f64) -> bool {
    let (i, j) = ((u * scale).floor() as i64, (v * scale).floor() as i64);
    (i + j).rem_euclid(2) == 0
}

/// A colour that may vary over a surface.
#[derive(Clone, Debug)]
pub enum ColourTexture {
    /// The same colour everywhere.
    Constant(Rgb),
    /// Alternating squares; `scale` squares per unit of `u` and `v`.
    Checker {
        /// Colour of squares with even `floor(u s) + floor(v s)`.
        even: Rgb,
        /// Colour of the other squares.
        odd: Rgb,
        /// Squares per unit of `u` and `v`.
        scale: f64,
    },
    /// An image (linear RGB), repeated `scale` times per unit of `u` and `v`.
    Image {
        /// The image.
        image: Arc<Image>,
        /// Repetitions per unit of `u` and `v`.
        scale: f64,
    },
}

impl ColourTexture {
    /// The colour at `(u, v)`.
    pub fn eval(&self, u: f64, v: f64) -> Rgb {
        match self {
            ColourTexture::Constant(c) => *c,
            ColourTexture::Checker { even, odd, scale } => {
                if checker_even(u, v, *scale) {
                    *even
                } else {
                    *odd
                }
            }
            ColourTexture::Image { image, scale } => {
                let (u, v) = (u * scale, v * scale);
                if image.channels == 3 {
                    Rgb::new(
                        image.bilinear(u, v, 0),
                        image.bilinear(u, v, 1),
                        image.bilinear(u, v, 2),
                    )
                } else {
                    Rgb::splat(image.bilinear(u, v, 0))
                }
            }
        }
    }
}

/// A greyscale value in [0, 1] that may vary over a surface (masks, thickness and ink maps).
#[derive(Clone, Debug)]
pub enum GreyTexture {
    /// The same value everywhere.
    Constant(f64),
    /// Alternating squares.
    Checker {
        /// Value of even squares.
        even: f64,
        /// Value of odd squares.
        odd: f64,
        /// Squares per unit of `u` and `v`.
        scale: f64,
    },
    /// An image read as grey, values as stored.
    Image {
        /// The image.
        image: Arc<Image>,
        /// Repetitions per unit of `u` and `v`.
        scale: f64,
    },
}

impl GreyTexture {
    /// The value at `(u, v)`.
    pub fn eval(&self, u: f64, v: f64) -> f64 {
        match self {
            GreyTexture::Constant(c) => *c,
            GreyTexture::Checker { even, odd, scale } => {
                if checker_even(u, v, *scale) {
                    *even
                } else {
                    *odd
                }
            }
            GreyTexture::Image { image, scale } => image.bilinear(u * scale, v * scale, 0),
        }
    }
}
