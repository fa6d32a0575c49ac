//! RGB values of a BSDF.
//!
//! Every quantity that may vary with wavelength (docs/design.md section 2) is carried
//! as three channels. A scalar parameter is stored as three equal channels; the
//! parameter types remember whether they were given as a scalar so that output
//! can print one `f` column or `r,g,b` columns.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Sub};

/// Three linear channels (red, green, blue) of a BSDF value, albedo or radiance.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Rgb(pub [f64; 3]);

impl Rgb {
    /// All channels zero.
    pub const ZERO: Rgb = Rgb([0.0; 3]);
    /// All channels one.
    pub const ONE: Rgb = Rgb([1.0; 3]);

    /// The same value in every channel.
    #[inline]
    pub const fn splat(v: f64) -> Self {
        Rgb([v, v, v])
    }
    /// From three channels.
    #[inline]
    pub const fn new(r: f64, g: f64, b: f64) -> Self {
        Rgb([r, g, b])
    }
    /// Applies `f` to every channel.
    #[inline]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Rgb([f(self.0[0]), f(self.0[1]), f(self.0[2])])
    }
    /// Combines two values channel by channel.
    #[inline]
    pub fn zip(self, o: Rgb, f: impl Fn(f64, f64) -> f64) -> Self {
        Rgb([f(self.0[0], o.0[0]), f(self.0[1], o.0[1]), f(self.0[2], o.0[2])])
    }
    /// Mean of the three channels.
    #[inline]
    pub fn mean(self) -> f64 {
        (self.0[0] + self.0[1] + self.0[2]) / 3.0
    }
    /// Largest channel.
    #[inline]
    pub fn max_channel(self) -> f64 {
        self.0[0].max(self.0[1]).max(self.0[2])
    }
    /// Rec. 709 luminance.
    #[inline]
    pub fn luminance(self) -> f64 {
        0.2126 * self.0[0] + 0.7152 * self.0[1] + 0.0722 * self.0[2]
    }
    /// True when every channel is zero.
    #[inline]
    pub fn is_black(self) -> bool {
        self.0.iter().all(|&c| c == 0.0)
    }
    /// True when every channel is finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.0.iter().all(|c| c.is_finite())
    }
}

impl Add for Rgb {
    type Output = Rgb;
    #[inline]
    fn add(self, o: Rgb) -> Rgb {
        self.zip(o, |a, b| a + b)
    }
}
impl AddAssign for Rgb {
    #[inline]
    fn add_assign(&mut self, o: Rgb) {
        *self = *self + o;
    }
}
impl Sub for Rgb {
    type Output = Rgb;
    #[inline]
    fn sub(self, o: Rgb) -> Rgb {
        self.zip(o, |a, b| a - b)
    }
}
impl Mul for Rgb {
    type Output = Rgb;
    #[inline]
    fn mul(self, o: Rgb) -> Rgb {
        self.zip(o, |a, b| a * b)
    }
}
impl MulAssign for Rgb {
    #[inline]
    fn mul_assign(&mut self, o: Rgb) {
        *self = *self * o;
    }
}
impl Mul<f64> for Rgb {
    type Output = Rgb;
    #[inline]
    fn mul(self, s: f64) -> Rgb {
        self.map(|a| a * s)
    }
}
impl MulAssign<f64> for Rgb {
    #[inline]
    fn mul_assign(&mut self, s: f64) {
        *self = *self * s;
    }
}
impl Mul<Rgb> for f64 {
    type Output = Rgb;
    #[inline]
    fn mul(self, s: Rgb) -> Rgb {
        s * self
    }
}
impl Div<f64> for Rgb {
    type Output = Rgb;
    #[inline]
    fn div(self, s: f64) -> Rgb {
        self.map(|a| a / s)
    }
}
impl Div for Rgb {
    type Output = Rgb;
    #[inline]
    fn div(self, o: Rgb) -> Rgb {
        self.zip(o, |a, b| a / b)
    }
}
