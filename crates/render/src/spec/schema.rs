//! The serde schema of a scene file: one type per table of `docs/scenes.md`
//! (the materials' tables are in [`super::material`]). Every table rejects keys
//! it does not know; values are checked against their ranges when the scene is
//! built ([`super::build`]).

use super::material::MaterialSpec;
use paperbsdf_core::Colour;
use serde::Deserialize;
use std::collections::BTreeMap;

/// `[render]`: image size and sampling.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct RenderSpec {
    /// Image width, pixels (default 320).
    pub width: Option<usize>,
    /// Image height, pixels (default 240).
    pub height: Option<usize>,
    /// Samples per pixel (default 64).
    pub spp: Option<u32>,
    /// Longest path (default 64).
    pub max_depth: Option<u32>,
    /// Russian roulette start depth (default 5).
    pub rr_depth: Option<u32>,
    /// Seed (default 0).
    pub seed: Option<u64>,
    /// PNG exposure multiplier (default 1).
    pub exposure: Option<f64>,
}

/// `[camera]`: a pinhole camera.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Eye position.
    pub origin: [f64; 3],
    /// Point looked at.
    pub target: [f64; 3],
    /// Up direction (default +z).
    #[serde(default = "default_up")]
    pub up: [f64; 3],
    /// Horizontal field of view, degrees.
    pub fov: f64,
}
fn default_up() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

/// `[environment]`: constant radiance arriving from every direction.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// Radiance (number or RGB).
    pub radiance: Colour,
}

/// A colour: a number, an RGB triple, or a texture table.
/// Deserialised by hand so that a wrong form (an array of 2, a string) is an
/// error that says which forms are accepted.
#[derive(Debug, Clone)]
pub enum ColourSpec {
    /// One value for all channels.
    Scalar(f64),
    /// RGB.
    Rgb([f64; 3]),
    /// A texture.
    Texture(TextureSpec),
}

impl<'de> Deserialize<'de> for ColourSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        const EXPECTED: &str =
            "a number, an RGB triple [r, g, b] of exactly 3 numbers, or a texture table { type = ... }";
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = ColourSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(EXPECTED)
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<ColourSpec, E> {
                Ok(ColourSpec::Scalar(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<ColourSpec, E> {
                Ok(ColourSpec::Scalar(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<ColourSpec, E> {
                Ok(ColourSpec::Scalar(v as f64))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<ColourSpec, A::Error> {
                paperbsdf_core::params::read_rgb_triple(seq, EXPECTED).map(ColourSpec::Rgb)
            }
            fn visit_map<M: serde::de::MapAccess<'de>>(self, map: M) -> Result<ColourSpec, M::Error> {
                TextureSpec::deserialize(serde::de::value::MapAccessDeserializer::new(map)).map(ColourSpec::Texture)
            }
        }
        d.deserialize_any(V)
    }
}

/// `{ type = "checker", even = .., odd = .., scale = .. }` or `{ type = "image", file = "..", scale = .. }`.
#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct TextureSpec {
    /// `checker` or `image`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Checker: colour of even squares.
    pub even: Option<Colour>,
    /// Checker: colour of odd squares.
    pub odd: Option<Colour>,
    /// Squares (checker) or repetitions (image) per unit of `u` and `v` (default 1; checker 8).
    pub scale: Option<f64>,
    /// Image: the file, relative to the scene file.
    pub file: Option<String>,
}

/// A paper thickness map: `{ file = "..", min = 0.5, scale = 1 }`.
#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct ThicknessMapSpec {
    /// Greyscale image (white = full thickness).
    pub file: String,
    /// Thickness factor where the map is black, in (0, 1].
    pub min: f64,
    /// Repetitions per unit of `u` and `v` (default 1).
    pub scale: Option<f64>,
}

/// A paper ink map: `{ file = "..", sigma_a = [..], scale = 1 }`.
#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct InkMapSpec {
    /// Greyscale image (black = full ink).
    pub file: String,
    /// Absorption added by full ink, 1/mm (>= 0).
    pub sigma_a: Colour,
    /// Repetitions per unit of `u` and `v` (default 1).
    pub scale: Option<f64>,
}

/// One transform step: exactly one of `translate`, `scale`, `rotate` (+ `angle`).
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct TransformSpec {
    /// Translation.
    pub translate: Option<[f64; 3]>,
    /// Scale: a number or per-axis.
    pub scale: Option<Colour>,
    /// Rotation axis.
    pub rotate: Option<[f64; 3]>,
    /// Rotation angle, degrees (right-handed about `rotate`).
    pub angle: Option<f64>,
}

/// `[[shapes]]`.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct ShapeSpec {
    /// `rectangle`, `sphere`, `obj` or `folded`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Optional name for messages.
    pub name: Option<String>,
    /// Material name (default: black).
    pub material: Option<String>,
    /// Emitted radiance (an area light).
    pub emission: Option<Colour>,
    /// Emit on both sides (default false: along the normal only).
    #[serde(default)]
    pub two_sided: bool,
    /// Cut-out mask image (black = hole).
    pub mask: Option<String>,
    /// Transform steps, applied first to last.
    #[serde(default)]
    pub transform: Vec<TransformSpec>,
    /// sphere: centre.
    pub center: Option<[f64; 3]>,
    /// sphere: radius.
    pub radius: Option<f64>,
    /// obj: file, relative to the scene file.
    pub file: Option<String>,
    /// folded: width and height of the unfolded sheet.
    pub size: Option<[f64; 2]>,
    /// folded: number of panels.
    pub panels: Option<u32>,
    /// folded: angle of each panel to the sheet's plane, degrees, [0, 90).
    pub fold_angle: Option<f64>,
}

/// The whole scene file.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// `[render]`.
    #[serde(default)]
    pub render: RenderSpec,
    /// `[camera]`.
    pub camera: CameraSpec,
    /// `[environment]`.
    pub environment: Option<EnvironmentSpec>,
    /// `[materials.NAME]`.
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialSpec>,
    /// `[[shapes]]`.
    #[serde(default)]
    pub shapes: Vec<ShapeSpec>,
}
