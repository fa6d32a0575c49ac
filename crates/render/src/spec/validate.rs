//! The TOML scene format (documented in `docs/scenes.md`) and its translation
//! into a [`Scene`].
//!
//! Every table rejects unknown keys; every error names the scene file and the
//! entry (`materials.NAME`, `shapes[i]`, `camera`, ...) and, for TOML syntax and
//! unknown keys, the line.

use crate::material::{InkMap, Material, PaperMaterial, ThicknessMap};
use crate::math::Affine;
use crate::paper_model;
use crate::scene::{Camera, Scene, SceneBuilder, Settings};
use crate::shapes::Shape;
use crate::texture::{ColourTexture, GreyTexture, Image};
use glam::{DMat3, DVec2, DVec3};
use paperbsdf_core::{Colour, Distribution, PaperParams, Rgb, RoughDielectric};
use serde::Deserialize;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// An error in a scene description: the file, the entry and what is wrong.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{file}: {entry}: {message}")]
pub struct SceneError {
    /// The scene file (or `builtin:NAME`).
    pub file: String,
    /// The entry, e.g. `materials.glass` or `shapes[2]`.
    pub entry: String,
    /// What is wrong.
    pub message: String,
}

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
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<ColourSpec, A::Error> {
                let (mut c, mut n) = ([0.0; 3], 0usize);
                while let Some(v) = seq.next_element::<f64>()? {
                    if n < 3 {
                        c[n] = v;
                    }
                    n += 1;
                }
                if n != 3 {
                    return Err(serde::de::Error::custom(format!(
                        "an array of {n} numbers; expected {EXPECTED}"
                    )));
                }
                Ok(ColourSpec::Rgb(c))
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

/// `[materials.NAME]`.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// `diffuse`, `dielectric`, `paper`, `measured` or `black`.
    #[serde(rename = "type")]
    pub kind: String,
    /// measured: an RGL `.bsdf` file (RGB variant), relative to the scene file.
    pub file: Option<String>,
    /// diffuse: reflectance in [0, 1].
    pub reflectance: Option<ColourSpec>,
    /// dielectric: relative index of refraction (inside over outside), [1, 5].
    pub eta: Option<f64>,
    /// dielectric: roughness alpha, [0, pi/2]; 0 is smooth.
    pub m: Option<f64>,
    /// dielectric: `ggx` or `beckmann`.
    pub dist: Option<Distribution>,
    /// paper: a preset name.
    pub preset: Option<String>,
    /// paper: a parameter file (JSON or TOML, the format of `paperbsdf eval --params`), relative to the scene file.
    pub params: Option<String>,
    /// paper: thickness, mm.
    pub d: Option<f64>,
    /// paper: absorption, 1/mm.
    pub sigma_a: Option<Colour>,
    /// paper: scattering, 1/mm.
    pub sigma_s: Option<Colour>,
    /// paper: forward HG lobe mean cosine.
    pub g_f: Option<f64>,
    /// paper: backward HG lobe mean cosine.
    pub g_b: Option<f64>,
    /// paper: backward lobe weight.
    pub w_b: Option<f64>,
    /// paper: front face index.
    pub eta_f: Option<f64>,
    /// paper: back face index.
    pub eta_b: Option<f64>,
    /// paper: front face roughness.
    pub m_f: Option<f64>,
    /// paper: back face roughness.
    pub m_b: Option<f64>,
    /// paper: front face distribution.
    pub dist_f: Option<Distribution>,
    /// paper: back face distribution.
    pub dist_b: Option<Distribution>,
    /// paper: the faces' microfacet scattering, `"multiple"` (default) or `"single"`.
    pub face_scattering: Option<paperbsdf_core::FaceScattering>,
    /// paper: thickness map.
    pub thickness_map: Option<ThicknessMapSpec>,
    /// paper: ink map.
    pub ink_map: Option<InkMapSpec>,
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

/// Where files named in a scene come from: a directory, and files embedded in the binary (built-in scenes).
pub struct Resources {
    /// Directory relative paths are resolved against.
    pub base_dir: PathBuf,
    /// Embedded files by relative path.
    pub embedded: HashMap<String, &'static [u8]>,
}

impl Resources {
    fn image(&self, rel: &str, grey: bool) -> Result<Arc<Image>, String> {
        if let Some(b) = self.embedded.get(rel) {
            return Image::from_bytes(b, grey).map(Arc::new);
        }
        let p = self.base_dir.join(rel);
        Image::load(&p, grey).map(Arc::new)
    }

    /// Reads a measured RGL `.bsdf` file (embedded, else relative to the base directory);
    /// the error names the file's path and what is wrong with it.
    fn measured(&self, rel: &str) -> Result<paperbsdf_io::MeasuredBsdf, String> {
        if let Some(b) = self.embedded.get(rel) {
            return paperbsdf_io::MeasuredBsdf::from_bytes(b.to_vec(), rel).map_err(|e| e.to_string());
        }
        let p = self.base_dir.join(rel);
        paperbsdf_io::MeasuredBsdf::load(&p).map_err(|e| e.to_string())
    }
}

/// Reads and builds a scene file.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| SceneError {
        file: file.clone(),
        entry: "file".into(),
        message: format!("cannot read: {e}"),
    })?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    load_scene_str(
        &text,
        &file,
        &Resources {
            base_dir: base,
            embedded: HashMap::new(),
        },
    )
}

/// Parses and builds a scene from TOML text; `file` names it in errors.
pub fn load_scene_str(text: &str, file: &str, res: &Resources) -> Result<Scene, SceneError> {
    let spec: SceneSpec = toml::from_str(text).map_err(|e| {
        let entry = match e.span() {
            Some(s) => entry_at(text, s.start.min(text.len())),
            None => "toml".to_string(),
        };
        SceneError {
            file: file.to_string(),
            entry,
            message: e.message().to_string(),
        }
    })?;
    build(&spec, file, res)
}

/// The entry that byte `offset` of a scene file lies in, and its line: the table
/// and the key the line assigns, e.g. `materials.NAME.d, line 12`,
/// `shapes[2].radius, line 40`, `camera, line 3`.
fn entry_at(text: &str, offset: usize) -> String {
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let mut table: Option<String> = None;
    let mut shapes = 0usize;
    // A header's name is a dotted key: this excludes rows of multi-line arrays such as `[1, 2],`.
    let is_key = |h: &str| {
        !h.is_empty()
            && h.chars()
                .all(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | '.' | ' ' | '"' | '\''))
    };
    for l in before.lines() {
        let t = l.trim();
        let t = t.split('#').next().unwrap_or("").trim_end();
        if !t.ends_with(']') {
            continue;
        }
        let t = &t[..t.len() - 1];
        if let Some(h) = t
            .strip_prefix("[[")
            .and_then(|r| r.strip_suffix(']'))
            .filter(|h| is_key(h))
        {
            let h = h.trim();
            if h == "shapes" {
                table = Some(format!("shapes[{shapes}]"));
                shapes += 1;
            } else {
                table = Some(h.to_string());
            }
        } else if let Some(h) = t.strip_prefix('[').filter(|h| is_key(h)) {
            table = Some(h.trim().to_string());
        }
    }
    // The key the line assigns, if it is a `key = value` line.
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let this_line = text[line_start..].lines().next().unwrap_or("");
    let key = this_line
        .split_once('=')
        .map(|(k, _)| k.trim())
        .filter(|k| is_key(k) && !k.contains(' '));
    let path = match (table, key) {
        (Some(t), Some(k)) => Some(format!("{t}.{k}")),
        (Some(t), None) => Some(t),
        (None, Some(k)) => Some(k.to_string()),
        (None, None) => None,
    };
    match path {
        Some(t) => format!("{t}, line {line}"),
        None => format!("line {line}"),
    }
}

fn err(file: &str, entry: &str, message: impl Into<String>) -> SceneError {
    SceneError {
        file: file.into(),
        entry: entry.into(),
        message: message.into(),
    }
}

fn v3(a: [f64; 3]) -> DVec3 {
    DVec3::from_array(a)
}

fn finite(entry: &str, key: &str, x: &[f64], file: &str) -> Result<(), SceneError> {
    if x.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(err(file, entry, format!("`{key}` must be finite")))
    }
}

fn colour_in(c: &Colour, key: &str, lo: f64, hi: f64, entry: &str, file: &str) -> Result<Rgb, SceneError> {
    c.check_range(key, lo, hi)
        .map_err(|e| err(file, entry, e.to_string()))?;
    Ok(c.rgb())
}

fn colour_texture(
    c: &ColourSpec,
    key: &str,
    entry: &str,
    file: &str,
    res: &Resources,
) -> Result<ColourTexture, SceneError> {
    Ok(match c {
        ColourSpec::Scalar(v) => ColourTexture::Constant(colour_in(&Colour::Scalar(*v), key, 0.0, 1.0, entry, file)?),
        ColourSpec::Rgb(v) => ColourTexture::Constant(colour_in(&Colour::Rgb(*v), key, 0.0, 1.0, entry, file)?),
        ColourSpec::Texture(t) => {
            let scale = t.scale.unwrap_or(if t.kind == "checker" { 8.0 } else { 1.0 });
            if !(scale.is_finite() && scale > 0.0) {
                return Err(err(file, entry, format!("`{key}.scale` = {scale} must be positive")));
            }
            match t.kind.as_str() {
                "checker" => {
                    if t.file.is_some() {
                        return Err(err(file, entry, format!("`{key}`: a checker texture has no `file`")));
                    }
                    let even = colour_in(
                        t.even
                            .as_ref()
                            .ok_or_else(|| err(file, entry, format!("`{key}`: checker needs `even`")))?,
                        &format!("{key}.even"),
                        0.0,
                        1.0,
                        entry,
                        file,
                    )?;
                    let odd = colour_in(
                        t.odd
                            .as_ref()
                            .ok_or_else(|| err(file, entry, format!("`{key}`: checker needs `odd`")))?,
                        &format!("{key}.odd"),
                        0.0,
                        1.0,
                        entry,
                        file,
                    )?;
                    ColourTexture::Checker { even, odd, scale }
                }
                "image" => {
                    if t.even.is_some() || t.odd.is_some() {
                        return Err(err(
                            file,
                            entry,
                            format!("`{key}`: an image texture has no `even`/`odd`"),
                        ));
                    }
                    let f = t
                        .file
                        .as_ref()
                        .ok_or_else(|| err(file, entry, format!("`{key}`: image needs `file`")))?;
                    let image = res
                        .image(f, false)
                        .map_err(|e| err(file, entry, format!("`{key}`: {e}")))?;
                    ColourTexture::Image { image, scale }
                }
                other => {
                    return Err(err(
                        file,
                        entry,
                        format!("`{key}`: unknown texture type `{other}` (allowed: checker, image)"),
                    ))
                }
            }
        }
    })
}

fn grey_image(
    rel: &str,
    scale: Option<f64>,
    key: &str,
    entry: &str,
    file: &str,
    res: &Resources,
) -> Result<GreyTexture, SceneError> {
    let scale = scale.unwrap_or(1.0);
    if !(scale.is_finite() && scale > 0.0) {
        return Err(err(file, entry, format!("`{key}.scale` = {scale} must be positive")));
    }
    let image = res
        .image(rel, true)
        .map_err(|e| err(file, entry, format!("`{key}`: {e}")))?;
    Ok(GreyTexture::Image { image, scale })
}

/// Keys set in a material table that do not belong to its type.
fn foreign_keys(m: &MaterialSpec, allowed: &[&str]) -> Vec<&'static str> {
    let present: [(&'static str, bool); 22] = [
        ("reflectance", m.reflectance.is_some()),
        ("file", m.file.is_some()),
        ("params", m.params.is_some()),
        ("eta", m.eta.is_some()),
        ("m", m.m.is_some()),
        ("dist", m.dist.is_some()),
        ("preset", m.preset.is_some()),
        ("d", m.d.is_some()),
        ("sigma_a", m.sigma_a.is_some()),
        ("sigma_s", m.sigma_s.is_some()),
        ("g_f", m.g_f.is_some()),
        ("g_b", m.g_b.is_some()),
        ("w_b", m.w_b.is_some()),
        ("eta_f", m.eta_f.is_some()),
        ("eta_b", m.eta_b.is_some()),
        ("m_f", m.m_f.is_some()),
        ("m_b", m.m_b.is_some()),
        ("dist_f", m.dist_f.is_some()),
        ("dist_b", m.dist_b.is_some()),
        ("face_scattering", m.face_scattering.is_some()),
        ("thickness_map", m.thickness_map.is_some()),
        ("ink_map", m.ink_map.is_some()),
    ];
    present
        .iter()
        .filter(|(k, p)| *p && !allowed.contains(k))
        .map(|(k, _)| *k)
        .collect()
}

/// Reads a paper parameter file (embedded for built-in scenes, else relative to the scene file).
fn params_file(rel: &str, res: &Resources) -> Result<PaperParams, String> {
    let loaded = if let Some(b) = res.embedded.get(rel) {
        let text = std::str::from_utf8(b).map_err(|e| format!("parameter file '{rel}': {e}"))?;
        let is_toml = rel.to_ascii_lowercase().ends_with(".toml");
        paperbsdf_io::Loaded {
            value: paperbsdf_io::params::parse_text::<PaperParams>(text, rel, is_toml).map_err(|e| e.to_string())?,
            origin: rel.to_string(),
            text: text.to_string(),
            is_toml,
        }
    } else {
        // A file relative to the scene file, else a preset name; a FIT.json is read
        // for its `params` (and must be a fit of the `paper` model).
        let path = res.base_dir.join(rel);
        let source = if path.exists() || paper_model::preset(rel).is_none() {
            path.to_string_lossy().to_string()
        } else {
            rel.to_string()
        };
        let s = paperbsdf_io::read_source_full(&source).map_err(|e| e.to_string())?;
        if let Some(model) = s.fit_model.as_deref().filter(|m| *m != "paper") {
            return Err(format!(
                "{}: a fit of the model `{model}`; a `paper` material needs a fit of the `paper` model",
                s.origin
            ));
        }
        paperbsdf_io::Loaded {
            value: paperbsdf_io::params::parse_text::<PaperParams>(&s.text, &s.origin, s.is_toml)
                .map_err(|e| e.to_string())?,
            origin: s.origin,
            text: s.text,
            is_toml: s.is_toml,
        }
    };
    loaded.value.validate().map_err(|e| loaded.param_error(e).to_string())?;
    Ok(loaded.value)
}

/// The parameters of a paper material: a preset or a parameter file with overrides, or a full set.
fn paper_params(m: &MaterialSpec, entry: &str, file: &str, res: &Resources) -> Result<PaperParams, SceneError> {
    if m.preset.is_some() && m.params.is_some() {
        return Err(err(file, entry, "give `preset` or `params`, not both"));
    }
    if let Some(rel) = &m.params {
        let base = Some(params_file(rel, res).map_err(|e| err(file, entry, format!("`params`: {e}")))?);
        return paper_params_over(m, base, entry, file);
    }
    let base = match &m.preset {
        Some(name) => Some(paper_model::preset(name).ok_or_else(|| {
            let names = paper_model::preset_names();
            err(
                file,
                entry,
                format!(
                    "unknown paper preset `{name}` (available: {})",
                    if names.is_empty() {
                        "none in this build".to_string()
                    } else {
                        names.join(", ")
                    }
                ),
            )
        })?),
        None => None,
    };
    paper_params_over(m, base, entry, file)
}

/// The material's paper keys over `base` (a preset or parameter file, if any), validated.
fn paper_params_over(
    m: &MaterialSpec,
    base: Option<PaperParams>,
    entry: &str,
    file: &str,
) -> Result<PaperParams, SceneError> {
    macro_rules! pick {
        ($f:ident) => {
            match (&m.$f, &base) {
                (Some(v), _) => v.clone(),
                (None, Some(b)) => b.$f.clone(),
                (None, None) => {
                    return Err(err(
                        file,
                        entry,
                        format!(
                            "paper needs `{}` (or a `preset` or `params` file)",
                            stringify!($f)
                        ),
                    ))
                }
            }
        };
    }
    let p = PaperParams {
        name: Some(entry.to_string()),
        d: pick!(d),
        sigma_a: pick!(sigma_a),
        sigma_s: pick!(sigma_s),
        g_f: pick!(g_f),
        g_b: pick!(g_b),
        w_b: pick!(w_b),
        eta_f: pick!(eta_f),
        eta_b: pick!(eta_b),
        m_f: pick!(m_f),
        m_b: pick!(m_b),
        dist_f: m
            .dist_f
            .or(base.as_ref().map(|b| b.dist_f))
            .unwrap_or(Distribution::Ggx),
        dist_b: m
            .dist_b
            .or(base.as_ref().map(|b| b.dist_b))
            .unwrap_or(Distribution::Ggx),
        face_scattering: m
            .face_scattering
            .or(base.as_ref().map(|b| b.face_scattering))
            .unwrap_or_default(),
    };
    p.validate().map_err(|e| err(file, entry, e.to_string()))?;
    Ok(p)
}

fn material(name: &str, m: &MaterialSpec, file: &str, res: &Resources) -> Result<Material, SceneError> {
    let entry = format!("materials.{name}");
    let entry = entry.as_str();
    let allowed: &[&str] = match m.kind.as_str() {
        "diffuse" => &["reflectance"],
        "dielectric" => &["eta", "m", "dist"],
        "paper" => &[
            "preset",
            "params",
            "d",
            "sigma_a",
            "sigma_s",
            "g_f",
            "g_b",
            "w_b",
            "eta_f",
            "eta_b",
            "m_f",
            "m_b",
            "dist_f",
            "dist_b",
            "face_scattering",
            "thickness_map",
            "ink_map",
        ],
        "measured" => &["file"],
        "black" => &[],
        other => {
            return Err(err(
                file,
                entry,
                format!("unknown material type `{other}` (allowed: diffuse, dielectric, paper, measured, black)"),
            ))
        }
    };
    let bad = foreign_keys(m, allowed);
    if !bad.is_empty() {
        return Err(err(
            file,
            entry,
            format!(
                "key `{}` does not apply to a `{}` material (allowed: {})",
                bad[0],
                m.kind,
                allowed.join(", ")
            ),
        ));
    }
    Ok(match m.kind.as_str() {
        "diffuse" => {
            let r = m
                .reflectance
                .as_ref()
                .ok_or_else(|| err(file, entry, "diffuse needs `reflectance`"))?;
            Material::Diffuse {
                reflectance: colour_texture(r, "reflectance", entry, file, res)?,
            }
        }
        "dielectric" => {
            let eta = m.eta.ok_or_else(|| err(file, entry, "dielectric needs `eta`"))?;
            let b = RoughDielectric::new(m.dist.unwrap_or(Distribution::Ggx), eta, m.m.unwrap_or(0.0))
                .map_err(|e| err(file, entry, e.to_string()))?;
            Material::Fixed(Arc::new(b))
        }
        "paper" => {
            let p = paper_params(m, entry, file, res)?;
            let thickness = match &m.thickness_map {
                None => None,
                Some(t) => {
                    if !(t.min > 0.0 && t.min <= 1.0) {
                        return Err(err(
                            file,
                            entry,
                            format!("`thickness_map.min` = {} is outside (0, 1]", t.min),
                        ));
                    }
                    Some(ThicknessMap {
                        map: grey_image(&t.file, t.scale, "thickness_map", entry, file, res)?,
                        min: t.min,
                    })
                }
            };
            let ink = match &m.ink_map {
                None => None,
                Some(k) => {
                    let s = colour_in(&k.sigma_a, "ink_map.sigma_a", 0.0, f64::INFINITY, entry, file)?;
                    if !s.is_finite() {
                        return Err(err(file, entry, "`ink_map.sigma_a` must be finite"));
                    }
                    Some(InkMap {
                        map: grey_image(&k.file, k.scale, "ink_map", entry, file, res)?,
                        sigma_a: s,
                    })
                }
            };
            let pm = PaperMaterial::new(p, thickness, ink, paper_model::paper_bsdf)
                .map_err(|e| err(file, entry, e.to_string()))?;
            Material::Paper(Box::new(pm))
        }
        "measured" => {
            let rel = m
                .file
                .as_ref()
                .ok_or_else(|| err(file, entry, "measured needs `file` (an RGL .bsdf file)"))?;
            let b = res
                .measured(rel)
                .map_err(|e| err(file, entry, format!("`file`: {e}")))?;
            Material::Fixed(Arc::new(b))
        }
        _ => Material::Black,
    })
}

fn transform(steps: &[TransformSpec], entry: &str, file: &str) -> Result<Affine, SceneError> {
    let mut a = Affine::IDENTITY;
    for (k, s) in steps.iter().enumerate() {
        let n = s.translate.is_some() as u8 + s.scale.is_some() as u8 + s.rotate.is_some() as u8;
        let e = |m: &str| err(file, entry, format!("transform[{k}]: {m}"));
        if n != 1 {
            return Err(e("each step needs exactly one of `translate`, `scale`, `rotate`"));
        }
        if s.angle.is_some() != s.rotate.is_some() {
            return Err(e("`angle` goes with `rotate` (and `rotate` needs `angle`)"));
        }
        let step = if let Some(t) = s.translate {
            finite(entry, "translate", &t, file)?;
            Affine {
                m: DMat3::IDENTITY,
                t: v3(t),
            }
        } else if let Some(sc) = &s.scale {
            let v = sc.rgb().0;
            finite(entry, "scale", &v, file)?;
            if v.contains(&0.0) {
                return Err(e("`scale` must not be zero"));
            }
            Affine {
                m: DMat3::from_diagonal(v3(v)),
                t: DVec3::ZERO,
            }
        } else {
            let axis = v3(s.rotate.unwrap_or_default()).normalize_or_zero();
            let ang = s.angle.unwrap_or(0.0);
            if axis == DVec3::ZERO || !ang.is_finite() {
                return Err(e("`rotate` needs a non-zero axis and a finite `angle`"));
            }
            Affine {
                m: DMat3::from_axis_angle(axis, ang.to_radians()),
                t: DVec3::ZERO,
            }
        };
        a = a.then(&step);
    }
    Ok(a)
}

/// A folded sheet: `panels` strips of a `w x h` sheet, alternately tilted by `angle` out of the `xz` plane
/// (a zig-zag along `x`, `z` up), front facing `-y`, centred at the origin.
pub fn folded_sheet(w: f64, h: f64, panels: u32, angle_deg: f64) -> Vec<Shape> {
    let pw = w / panels as f64;
    let a = angle_deg.to_radians();
    let (dx, dy) = (pw * a.cos(), pw * a.sin());
    let total = dx * panels as f64;
    let mut out = vec![];
    for k in 0..panels {
        let x0 = -0.5 * total + dx * k as f64;
        let y0 = if k % 2 == 0 { 0.0 } else { dy };
        let y1 = if k % 2 == 0 { dy } else { 0.0 };
        let (u0, u1) = (k as f64 / panels as f64, (k + 1) as f64 / panels as f64);
        let p00 = DVec3::new(x0, y0, -0.5 * h);
        let p10 = DVec3::new(x0 + dx, y1, -0.5 * h);
        let p01 = DVec3::new(x0, y0, 0.5 * h);
        let p11 = DVec3::new(x0 + dx, y1, 0.5 * h);
        let tri = |a: DVec3, b: DVec3, c: DVec3, ta: DVec2, tb: DVec2, tc: DVec2| Shape::Tri {
            p0: a,
            e1: b - a,
            e2: c - a,
            ns: None,
            uv: Some(Box::new([ta, tb, tc])),
        };
        out.push(tri(
            p00,
            p10,
            p11,
            DVec2::new(u0, 0.0),
            DVec2::new(u1, 0.0),
            DVec2::new(u1, 1.0),
        ));
        out.push(tri(
            p00,
            p11,
            p01,
            DVec2::new(u0, 0.0),
            DVec2::new(u1, 1.0),
            DVec2::new(u0, 1.0),
        ));
    }
    out
}

fn transform_tris(shapes: Vec<Shape>, a: &Affine) -> Vec<Shape> {
    shapes
        .into_iter()
        .map(|s| match s {
            Shape::Tri { p0, e1, e2, ns, uv } => Shape::Tri {
                p0: a.point(p0),
                e1: a.vector(e1),
                e2: a.vector(e2),
                ns: ns.map(|n| Box::new([a.normal(n[0]), a.normal(n[1]), a.normal(n[2])])),
                uv,
            },
            other => other,
        })
        .collect()
}

/// Checks that every number of the OBJ file's `v`, `vn` and `vt` lines is
/// finite (tobj reads `nan` and `inf` as numbers); the error names the line.
fn check_obj_numbers(path: &Path) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot load OBJ '{}': {e}", path.display()))?;
    let text = String::from_utf8_lossy(&bytes);
    for (i, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        let Some(kw @ ("v" | "vn" | "vt")) = it.next() else {
            continue;
        };
        for x in it {
            if let Ok(v) = x.parse::<f64>() {
                if !v.is_finite() {
                    return Err(format!(
                        "OBJ '{}' line {}: `{kw}` has the non-finite number `{x}`",
                        path.display(),
                        i + 1
                    ));
                }
            }
        }
    }
    Ok(())
}

fn load_obj(path: &Path, a: &Affine) -> Result<Vec<Shape>, String> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    check_obj_numbers(path)?;
    let (models, _) = tobj::load_obj(path, &opts).map_err(|e| format!("cannot load OBJ '{}': {e}", path.display()))?;
    let mut out = vec![];
    for m in &models {
        let mesh = &m.mesh;
        let nv = mesh.positions.len() / 3;
        let pos = |i: usize| {
            a.point(DVec3::new(
                mesh.positions[3 * i] as f64,
                mesh.positions[3 * i + 1] as f64,
                mesh.positions[3 * i + 2] as f64,
            ))
        };
        let has_n = mesh.normals.len() == mesh.positions.len();
        let has_uv = mesh.texcoords.len() / 2 == nv && nv > 0;
        for f in mesh.indices.chunks(3) {
            if f.len() < 3 {
                continue;
            }
            let idx = [f[0] as usize, f[1] as usize, f[2] as usize];
            if idx.iter().any(|&i| i >= nv) {
                return Err(format!(
                    "OBJ '{}': face index out of range in object `{}`",
                    path.display(),
                    m.name
                ));
            }
            let (p0, p1, p2) = (pos(idx[0]), pos(idx[1]), pos(idx[2]));
            let (e1, e2) = (p1 - p0, p2 - p0);
            if e1.cross(e2).length_squared() == 0.0 {
                continue; // degenerate triangle: no area, never hit
            }
            let ns = has_n.then(|| {
                Box::new(idx.map(|i| {
                    a.normal(DVec3::new(
                        mesh.normals[3 * i] as f64,
                        mesh.normals[3 * i + 1] as f64,
                        mesh.normals[3 * i + 2] as f64,
                    ))
                }))
            });
            let uv = has_uv.then(|| {
                Box::new(idx.map(|i| DVec2::new(mesh.texcoords[2 * i] as f64, mesh.texcoords[2 * i + 1] as f64)))
            });
            out.push(Shape::Tri { p0, e1, e2, ns, uv });
        }
    }
    if out.is_empty() {
        return Err(format!("OBJ '{}' has no triangles", path.display()));
    }
    Ok(out)
}

/// Builds a [`Scene`] from a parsed description.
pub fn build(spec: &SceneSpec, file: &str, res: &Resources) -> Result<Scene, SceneError> {
    let r = &spec.render;
    let d = Settings::default();
    let settings = Settings {
        width: r.width.unwrap_or(d.width),
        height: r.height.unwrap_or(d.height),
        spp: r.spp.unwrap_or(d.spp),
        max_depth: r.max_depth.unwrap_or(d.max_depth),
        rr_depth: r.rr_depth.unwrap_or(d.rr_depth),
        seed: r.seed.unwrap_or(d.seed),
        exposure: r.exposure.unwrap_or(d.exposure),
    };
    if !(1..=16384).contains(&settings.width) || !(1..=16384).contains(&settings.height) {
        return Err(err(
            file,
            "render",
            format!("image size {}x{} is outside 1..16384", settings.width, settings.height),
        ));
    }
    if settings.spp == 0 {
        return Err(err(file, "render", "`spp` must be at least 1"));
    }
    if settings.max_depth == 0 {
        return Err(err(file, "render", "`max_depth` must be at least 1"));
    }
    if !(settings.exposure.is_finite() && settings.exposure > 0.0) {
        return Err(err(
            file,
            "render",
            format!("`exposure` = {} must be positive", settings.exposure),
        ));
    }
    let c = &spec.camera;
    finite("camera", "origin", &c.origin, file)?;
    finite("camera", "target", &c.target, file)?;
    finite("camera", "up", &c.up, file)?;
    let camera = Camera::look_at(v3(c.origin), v3(c.target), v3(c.up), c.fov).map_err(|e| err(file, "camera", e))?;
    let environment = match &spec.environment {
        None => None,
        Some(e) => Some(colour_in(
            &e.radiance,
            "radiance",
            0.0,
            f64::INFINITY,
            "environment",
            file,
        )?),
    };
    if environment.is_some_and(|e| !e.is_finite()) {
        return Err(err(file, "environment", "`radiance` must be finite"));
    }
    let mut b = SceneBuilder::new();
    let mut mat_index = HashMap::new();
    for (name, m) in &spec.materials {
        let mi = b.material(material(name, m, file, res)?);
        mat_index.insert(name.clone(), mi);
    }
    let black = b.material(Material::Black);
    for (k, s) in spec.shapes.iter().enumerate() {
        let entry = match &s.name {
            Some(n) => format!("shapes[{k}] ({n})"),
            None => format!("shapes[{k}]"),
        };
        let entry = entry.as_str();
        let a = transform(&s.transform, entry, file)?;
        if !a.is_invertible() {
            return Err(err(file, entry, "the transform is singular"));
        }
        let only = |keys: &[(&str, bool)]| -> Result<(), SceneError> {
            for (k, present) in keys {
                if *present {
                    return Err(err(
                        file,
                        entry,
                        format!("key `{k}` does not apply to a `{}` shape", s.kind),
                    ));
                }
            }
            Ok(())
        };
        let shapes = match s.kind.as_str() {
            "rectangle" => {
                only(&[
                    ("center", s.center.is_some()),
                    ("radius", s.radius.is_some()),
                    ("file", s.file.is_some()),
                    ("size", s.size.is_some()),
                    ("panels", s.panels.is_some()),
                    ("fold_angle", s.fold_angle.is_some()),
                ])?;
                let p0 = a.point(DVec3::new(-1.0, -1.0, 0.0));
                let eu = a.vector(DVec3::new(2.0, 0.0, 0.0));
                let ev = a.vector(DVec3::new(0.0, 2.0, 0.0));
                let n = a.normal(DVec3::Z);
                vec![Shape::rect(p0, eu, ev, n)]
            }
            "sphere" => {
                only(&[
                    ("file", s.file.is_some()),
                    ("size", s.size.is_some()),
                    ("panels", s.panels.is_some()),
                    ("fold_angle", s.fold_angle.is_some()),
                    ("transform", !s.transform.is_empty()),
                ])?;
                let c = s.center.unwrap_or([0.0; 3]);
                finite(entry, "center", &c, file)?;
                let r = s.radius.unwrap_or(1.0);
                if !(r.is_finite() && r > 0.0) {
                    return Err(err(file, entry, format!("`radius` = {r} must be positive")));
                }
                vec![Shape::Sphere { c: v3(c), r }]
            }
            "obj" => {
                only(&[
                    ("center", s.center.is_some()),
                    ("radius", s.radius.is_some()),
                    ("size", s.size.is_some()),
                    ("panels", s.panels.is_some()),
                    ("fold_angle", s.fold_angle.is_some()),
                ])?;
                let f = s.file.as_ref().ok_or_else(|| err(file, entry, "obj needs `file`"))?;
                load_obj(&res.base_dir.join(f), &a).map_err(|e| err(file, entry, e))?
            }
            "folded" => {
                only(&[
                    ("center", s.center.is_some()),
                    ("radius", s.radius.is_some()),
                    ("file", s.file.is_some()),
                ])?;
                let [w, h] = s.size.unwrap_or([1.0, 1.0]);
                let panels = s.panels.unwrap_or(2);
                let ang = s.fold_angle.unwrap_or(30.0);
                if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
                    return Err(err(file, entry, "`size` must be two positive numbers"));
                }
                if !(1..=1000).contains(&panels) {
                    return Err(err(file, entry, format!("`panels` = {panels} is outside 1..1000")));
                }
                if !(0.0..90.0).contains(&ang) {
                    return Err(err(
                        file,
                        entry,
                        format!("`fold_angle` = {ang} is outside [0, 90) degrees"),
                    ));
                }
                transform_tris(folded_sheet(w, h, panels, ang), &a)
            }
            other => {
                return Err(err(
                    file,
                    entry,
                    format!("unknown shape type `{other}` (allowed: rectangle, sphere, obj, folded)"),
                ))
            }
        };
        let material = match &s.material {
            None => black,
            Some(m) => *mat_index.get(m).ok_or_else(|| {
                err(
                    file,
                    entry,
                    format!(
                        "unknown material `{m}` (defined: {})",
                        spec.materials.keys().cloned().collect::<Vec<_>>().join(", ")
                    ),
                )
            })?,
        };
        let emission = match &s.emission {
            None => None,
            Some(e) => {
                let v = colour_in(e, "emission", 0.0, f64::INFINITY, entry, file)?;
                if !v.is_finite() {
                    return Err(err(file, entry, "`emission` must be finite"));
                }
                Some(v)
            }
        };
        if s.two_sided && emission.is_none() {
            return Err(err(file, entry, "`two_sided` needs `emission`"));
        }
        let mask = match &s.mask {
            None => None,
            Some(f) => Some(grey_image(f, None, "mask", entry, file, res)?),
        };
        b.object(
            s.name.as_deref().unwrap_or(entry),
            shapes,
            material,
            emission,
            s.two_sided,
            mask,
        );
    }
    Ok(b.build(camera, environment, settings))
}
