//! Parameter errors and range checks shared by every model (docs/design.md section 3).
//!
//! A value outside its range is an error that names the parameter, the value
//! and the allowed range; nothing is clamped silently.

/// An invalid model parameter.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// A number outside its allowed closed range.
    #[error(
        "parameter `{name}` = {value} is outside its allowed range [{}, {}]",
        fmt_bound(*min),
        fmt_bound(*max)
    )]
    OutOfRange {
        /// Parameter name as in parameter files.
        name: String,
        /// The offending value.
        value: f64,
        /// Lower bound (inclusive).
        min: f64,
        /// Upper bound (inclusive; may be infinite).
        max: f64,
    },
    /// A number that is NaN or infinite where a finite value is needed.
    #[error("parameter `{name}` = {value} is not a finite number")]
    NotFinite {
        /// Parameter name.
        name: String,
        /// The offending value.
        value: f64,
    },
    /// Any other invalid parameter.
    #[error("parameter `{name}`: {message}")]
    Invalid {
        /// Parameter name.
        name: String,
        /// What is wrong.
        message: String,
    },
}

/// A range bound as people write it: `pi/2` for the roughness limit, `inf`, else the number.
fn fmt_bound(x: f64) -> String {
    if (x - std::f64::consts::FRAC_PI_2).abs() < 1e-12 {
        "pi/2".to_string()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.to_string()
    } else {
        x.to_string()
    }
}

impl ParamError {
    /// Checks `min <= value <= max` (and that `value` is not NaN; an infinite
    /// value passes only if `max` is infinite).
    pub fn check_range(name: &str, value: f64, min: f64, max: f64) -> Result<(), ParamError> {
        if value.is_nan() || (value.is_infinite() && !(max.is_infinite() && value > 0.0)) {
            return Err(ParamError::NotFinite {
                name: name.to_string(),
                value,
            });
        }
        if value < min || value > max {
            return Err(ParamError::OutOfRange {
                name: name.to_string(),
                value,
                min,
                max,
            });
        }
        Ok(())
    }

    /// The same error about the parameter `name + suffix` (`eta` of the
    /// front face becomes `eta_f`).
    pub fn with_suffix(self, suffix: &str) -> ParamError {
        match self {
            ParamError::OutOfRange { name, value, min, max } => ParamError::OutOfRange {
                name: name + suffix,
                value,
                min,
                max,
            },
            ParamError::NotFinite { name, value } => ParamError::NotFinite {
                name: name + suffix,
                value,
            },
            ParamError::Invalid { name, message } => ParamError::Invalid {
                name: name + suffix,
                message,
            },
        }
    }

    /// The parameter this error is about.
    pub fn name(&self) -> &str {
        match self {
            ParamError::OutOfRange { name, .. }
            | ParamError::NotFinite { name, .. }
            | ParamError::Invalid { name, .. } => name,
        }
    }
}

use crate::microfacet::Distribution;

/// A parameter that may vary with wavelength: a number or an RGB triple
/// (docs/design.md section 2). Serialises as a number or a 3-array; anything else
/// (an array of another length, a string) is an error saying which forms are
/// accepted.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(untagged)]
pub enum Colour {
    /// The same value in every channel.
    Scalar(f64),
    /// Red, green, blue.
    Rgb([f64; 3]),
}

impl<'de> serde::Deserialize<'de> for Colour {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        const EXPECTED: &str = "a number or an RGB triple [r, g, b] of exactly 3 numbers";
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Colour;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(EXPECTED)
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Colour, E> {
                Ok(Colour::Scalar(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Colour, E> {
                Ok(Colour::Scalar(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Colour, E> {
                Ok(Colour::Scalar(v as f64))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<Colour, A::Error> {
                read_rgb_triple(seq, EXPECTED).map(Colour::Rgb)
            }
        }
        d.deserialize_any(V)
    }
}

/// Reads an RGB triple from a serde sequence: exactly three numbers, else the
/// error `an array of N numbers; expected {expected}` (`expected` lists the
/// forms the caller accepts). Shared by [`Colour`]'s reader and the colours of
/// `paperbsdf-render`'s scene files (which also accept textures).
pub fn read_rgb_triple<'de, A: serde::de::SeqAccess<'de>>(mut seq: A, expected: &str) -> Result<[f64; 3], A::Error> {
    let mut c = [0.0; 3];
    let mut n = 0usize;
    while let Some(v) = seq.next_element::<f64>()? {
        if n < 3 {
            c[n] = v;
        }
        n += 1;
    }
    if n != 3 {
        return Err(serde::de::Error::custom(format!(
            "an array of {n} numbers; expected {expected}"
        )));
    }
    Ok(c)
}

impl Colour {
    /// The three channels.
    pub fn rgb(&self) -> crate::Rgb {
        match *self {
            Colour::Scalar(v) => crate::Rgb::splat(v),
            Colour::Rgb(c) => crate::Rgb(c),
        }
    }
    /// Whether it was given as an RGB triple.
    pub fn is_rgb(&self) -> bool {
        matches!(self, Colour::Rgb(_))
    }
    /// Checks every channel against `[min, max]`; the error names `name` (and the channel).
    pub fn check_range(&self, name: &str, min: f64, max: f64) -> Result<(), ParamError> {
        match *self {
            Colour::Scalar(v) => ParamError::check_range(name, v, min, max),
            Colour::Rgb(c) => {
                for (k, v) in c.iter().enumerate() {
                    ParamError::check_range(&format!("{name}[{k}]"), *v, min, max)?;
                }
                Ok(())
            }
        }
    }
}

/// Parameters of the Paper BSDF (docs/design.md section 3, supplement Table 2).
/// Lengths in mm, coefficients in 1/mm.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaperParams {
    /// Optional label.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Thickness `d`, mm, in (0, inf).
    pub d: f64,
    /// Absorption coefficient `sigma_a`, 1/mm, in [0, inf).
    pub sigma_a: Colour,
    /// Scattering coefficient `sigma_s`, 1/mm, in [0, inf).
    pub sigma_s: Colour,
    /// Mean cosine of the forward HG lobe, in [-1, 1].
    pub g_f: f64,
    /// Mean cosine of the backward HG lobe, in [-1, 1].
    pub g_b: f64,
    /// Weight of the backward lobe, in [0, 1].
    pub w_b: f64,
    /// Relative index of the front face, in [1, 5].
    pub eta_f: f64,
    /// Relative index of the back face, in [1, 5].
    pub eta_b: f64,
    /// Roughness (microfacet alpha) of the front face, in [0, pi/2].
    pub m_f: f64,
    /// Roughness (microfacet alpha) of the back face, in [0, pi/2].
    pub m_b: f64,
    /// Microfacet distribution of the front face.
    pub dist_f: Distribution,
    /// Microfacet distribution of the back face.
    pub dist_b: Distribution,
    /// How the faces scatter among their microfacets: `multiple` (default,
    /// energy-conserving faces) or `single` (Walter's faces, as in the paper).
    #[serde(default)]
    pub face_scattering: FaceScattering,
}

/// The faces' microfacet scattering (docs/design.md 4.1, parameter `face_scattering`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FaceScattering {
    /// Energy-conserving faces: every order of scattering among the microfacets
    /// (Heitz et al. 2016 as ground truth; a reciprocal compensation in the model).
    #[default]
    Multiple,
    /// Walter et al.'s single-scattering faces (the paper, Mitsuba's `roughdielectric`).
    Single,
}

impl FaceScattering {
    /// The name used in parameter files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            FaceScattering::Multiple => "multiple",
            FaceScattering::Single => "single",
        }
    }
}

impl std::str::FromStr for FaceScattering {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, ParamError> {
        match s.to_ascii_lowercase().as_str() {
            "multiple" => Ok(FaceScattering::Multiple),
            "single" => Ok(FaceScattering::Single),
            _ => Err(ParamError::Invalid {
                name: "face_scattering".into(),
                message: format!("`{s}` is not one of `multiple`, `single`"),
            }),
        }
    }
}

/// Smallest allowed thickness, mm (the `eps` of Table 2).
pub const D_MIN: f64 = 1e-6;

impl PaperParams {
    /// Checks every parameter against docs/design.md's ranges; the first violation is returned.
    pub fn validate(&self) -> Result<(), ParamError> {
        let pi2 = std::f64::consts::FRAC_PI_2;
        ParamError::check_range("d", self.d, D_MIN, f64::INFINITY)?;
        if !self.d.is_finite() {
            return Err(ParamError::NotFinite {
                name: "d".into(),
                value: self.d,
            });
        }
        self.sigma_a.check_range("sigma_a", 0.0, f64::INFINITY)?;
        self.sigma_s.check_range("sigma_s", 0.0, f64::INFINITY)?;
        for (n, v, lo, hi) in [
            ("g_f", self.g_f, -1.0, 1.0),
            ("g_b", self.g_b, -1.0, 1.0),
            ("w_b", self.w_b, 0.0, 1.0),
            ("eta_f", self.eta_f, 1.0, 5.0),
            ("eta_b", self.eta_b, 1.0, 5.0),
            ("m_f", self.m_f, 0.0, pi2),
            ("m_b", self.m_b, 0.0, pi2),
        ] {
            ParamError::check_range(n, v, lo, hi)?;
        }
        for (n, c) in [("sigma_a", &self.sigma_a), ("sigma_s", &self.sigma_s)] {
            if !c.rgb().is_finite() {
                return Err(ParamError::NotFinite {
                    name: n.into(),
                    value: c.rgb().max_channel(),
                });
            }
        }
        Ok(())
    }
    /// Whether any wavelength-dependent parameter is an RGB triple (output has `r,g,b` columns).
    pub fn is_rgb(&self) -> bool {
        self.sigma_a.is_rgb() || self.sigma_s.is_rgb()
    }
}
