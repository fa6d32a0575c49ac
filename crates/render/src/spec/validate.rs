//! Checking a parsed scene description and translating it into a [`Scene`]:
//! every value against its range (nothing is clamped), files (images, meshes,
//! parameter and measured files) read, materials and shapes built. Each error
//! names the scene file and the entry.

use super::material::{MaterialSpec, PaperSpec, SheetModel};
use super::schema::{ColourSpec, RenderSpec, SceneSpec, ShapeSpec, TransformSpec};
use super::Resources;
use crate::error::SceneError;
use crate::material::{InkMap, Material, PaperMaterial, ThicknessMap};
use crate::math::Affine;
use crate::mesh::{folded_sheet, load_obj, transform_tris};
use crate::paper_model;
use crate::scene::{Camera, Scene, SceneBuilder, Settings};
use crate::shapes::Shape;
use crate::texture::{ColourTexture, GreyTexture};
use glam::{DMat3, DVec3};
use paperbsdf_core::models::ModelKind;
use paperbsdf_core::{Colour, Distribution, FaceScattering, PaperParams, Rgb, RoughDielectric};
use serde::Deserialize;
use std::collections::HashMap;
use std::sync::Arc;

/// The scene file and the entry a check is about, for the errors it makes.
#[derive(Clone, Copy)]
struct At<'a> {
    file: &'a str,
    entry: &'a str,
}

impl At<'_> {
    /// An error of this entry.
    fn err(&self, message: impl std::fmt::Display) -> SceneError {
        SceneError {
            file: self.file.into(),
            entry: self.entry.into(),
            message: message.to_string(),
        }
    }

    /// Checks that every number of `key` is finite.
    fn finite(&self, key: &str, x: &[f64]) -> Result<(), SceneError> {
        if x.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(self.err(format!("`{key}` must be finite")))
        }
    }

    /// The colour `key`, each channel checked against `[lo, hi]`.
    fn colour_in(&self, c: &Colour, key: &str, lo: f64, hi: f64) -> Result<Rgb, SceneError> {
        c.check_range(key, lo, hi).map_err(|e| self.err(e))?;
        Ok(c.rgb())
    }
}

fn v3(a: [f64; 3]) -> DVec3 {
    DVec3::from_array(a)
}

/// A reflectance-like colour in [0, 1]: constant, checker or image.
fn colour_texture(c: &ColourSpec, key: &str, at: At, res: &Resources) -> Result<ColourTexture, SceneError> {
    let t = match c {
        ColourSpec::Scalar(v) => {
            return Ok(ColourTexture::Constant(at.colour_in(
                &Colour::Scalar(*v),
                key,
                0.0,
                1.0,
            )?))
        }
        ColourSpec::Rgb(v) => {
            return Ok(ColourTexture::Constant(at.colour_in(
                &Colour::Rgb(*v),
                key,
                0.0,
                1.0,
            )?))
        }
        ColourSpec::Texture(t) => t,
    };
    let scale = t.scale.unwrap_or(if t.kind == "checker" { 8.0 } else { 1.0 });
    if !(scale.is_finite() && scale > 0.0) {
        return Err(at.err(format!("`{key}.scale` = {scale} must be positive")));
    }
    Ok(match t.kind.as_str() {
        "checker" => {
            if t.file.is_some() {
                return Err(at.err(format!("`{key}`: a checker texture has no `file`")));
            }
            let square = |c: &Option<Colour>, which: &str| {
                let c = c
                    .as_ref()
                    .ok_or_else(|| at.err(format!("`{key}`: checker needs `{which}`")))?;
                at.colour_in(c, &format!("{key}.{which}"), 0.0, 1.0)
            };
            let even = square(&t.even, "even")?;
            let odd = square(&t.odd, "odd")?;
            ColourTexture::Checker { even, odd, scale }
        }
        "image" => {
            if t.even.is_some() || t.odd.is_some() {
                return Err(at.err(format!("`{key}`: an image texture has no `even`/`odd`")));
            }
            let f = t
                .file
                .as_ref()
                .ok_or_else(|| at.err(format!("`{key}`: image needs `file`")))?;
            let image = res.image(f, false).map_err(|e| at.err(format!("`{key}`: {e}")))?;
            ColourTexture::Image { image, scale }
        }
        other => {
            return Err(at.err(format!(
                "`{key}`: unknown texture type `{other}` (allowed: checker, image)"
            )))
        }
    })
}

/// A greyscale image map `key` (a mask, thickness or ink map) repeated `scale` (default 1) times.
fn grey_image(rel: &str, scale: Option<f64>, key: &str, at: At, res: &Resources) -> Result<GreyTexture, SceneError> {
    let scale = scale.unwrap_or(1.0);
    if !(scale.is_finite() && scale > 0.0) {
        return Err(at.err(format!("`{key}.scale` = {scale} must be positive")));
    }
    let image = res.image(rel, true).map_err(|e| at.err(format!("`{key}`: {e}")))?;
    Ok(GreyTexture::Image { image, scale })
}

/// Reads a paper parameter file (embedded for built-in scenes, else relative to
/// the scene file) for a material of `model`; errors are the material's,
/// saying `params`. With it the discretisation a FIT.json records
/// (`slab_nodes` of a `slab` fit; default otherwise).
fn params_file(
    rel: &str,
    model: SheetModel,
    at: At,
    res: &Resources,
) -> Result<(PaperParams, paperbsdf_io::models::SlabSettings), SceneError> {
    let mut recorded = paperbsdf_io::models::SlabSettings::default();
    let fail = |e: &dyn std::fmt::Display| at.err(format!("`params`: {e}"));
    let loaded = if let Some(b) = res.embedded.get(rel) {
        let text = std::str::from_utf8(b).map_err(|e| fail(&format!("parameter file '{rel}': {e}")))?;
        let is_toml = rel.to_ascii_lowercase().ends_with(".toml");
        paperbsdf_io::Loaded {
            value: paperbsdf_io::params::parse_text::<PaperParams>(text, rel, is_toml).map_err(|e| fail(&e))?,
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
        let s = paperbsdf_io::read_source_full(&source).map_err(|e| fail(&e))?;
        // A fit of `paper` for either model; a fit of `slab` (`fit --refine
        // slab`) for `model = "slab"`, solved with the nodes it records.
        match s.fit_model.as_deref() {
            None => {}
            Some(f) if f == ModelKind::Paper.name() => {}
            Some(f) if f == ModelKind::Slab.name() && model == SheetModel::Slab => {
                recorded = paperbsdf_io::models::SlabSettings::recorded(s.fit_slab_nodes.as_ref(), &s.origin)
                    .map_err(|e| fail(&e))?;
            }
            Some(f) if f == ModelKind::Slab.name() => {
                return Err(fail(&format!(
                    "{}: a fit of the model `slab`; render it with `model = \"slab\"` (a `paper` material needs a fit of the `paper` model)",
                    s.origin
                )));
            }
            Some(f) => {
                return Err(fail(&format!(
                    "{}: a fit of the model `{f}`; a paper material needs a fit of the `paper` or `slab` model",
                    s.origin
                )));
            }
        }
        paperbsdf_io::Loaded {
            value: paperbsdf_io::params::parse_text::<PaperParams>(&s.text, &s.origin, s.is_toml)
                .map_err(|e| fail(&e))?,
            origin: s.origin,
            text: s.text,
            is_toml: s.is_toml,
        }
    };
    loaded.value.validate().map_err(|e| fail(&loaded.param_error(e)))?;
    Ok((loaded.value, recorded))
}

/// The parameters of a paper material: its keys over a preset or parameter
/// file, or (without either) a full set, the distributions defaulting to GGX
/// and the face scattering to its default; validated. With it the
/// discretisation of `slab`: the material's `slab_nodes`, else what its
/// `params` FIT.json records.
fn paper_params(
    m: &PaperSpec,
    at: At,
    res: &Resources,
) -> Result<(PaperParams, paperbsdf_io::models::SlabSettings), SceneError> {
    let mut slab = paperbsdf_io::models::SlabSettings { nodes: m.slab_nodes };
    let base = match (&m.preset, &m.params) {
        (Some(_), Some(_)) => return Err(at.err("give `preset` or `params`, not both")),
        (None, Some(rel)) => {
            let (p, recorded) = params_file(rel, m.model.unwrap_or_default(), at, res)?;
            if slab.is_default() {
                slab = recorded;
            }
            Some(p)
        }
        (Some(name), None) => Some(paper_model::preset(name).ok_or_else(|| {
            let names = paper_model::preset_names();
            at.err(format!(
                "unknown paper preset `{name}` (available: {})",
                if names.is_empty() {
                    "none in this build".to_string()
                } else {
                    names.join(", ")
                }
            ))
        })?),
        (None, None) => None,
    };
    // Parameters as TOML tables: the material's keys over the base's.
    let mut t = match &base {
        Some(b) => as_table(b, at)?,
        None => {
            let mut t = toml::Table::new();
            let ggx = toml::Value::String(Distribution::Ggx.name().into());
            t.insert("dist_f".into(), ggx.clone());
            t.insert("dist_b".into(), ggx);
            let fs = FaceScattering::default().name();
            t.insert("face_scattering".into(), fs.into());
            t
        }
    };
    t.extend(as_table(m, at)?);
    t.insert("name".into(), at.entry.into());
    if let Some(k) = super::material::keys_of::<PaperParams>()
        .iter()
        .find(|k| !t.contains_key(**k))
    {
        return Err(at.err(format!("paper needs `{k}` (or a `preset` or `params` file)")));
    }
    let p = PaperParams::deserialize(t).map_err(|e| at.err(e.message()))?;
    p.validate().map_err(|e| at.err(e))?;
    Ok((p, slab))
}

/// `v` as a TOML table (a struct's `None` fields left out).
fn as_table<T: serde::Serialize>(v: &T, at: At) -> Result<toml::Table, SceneError> {
    match toml::Value::try_from(v) {
        Ok(toml::Value::Table(t)) => Ok(t),
        Ok(_) => Err(at.err("the paper parameters are not a table")),
        Err(e) => Err(at.err(e)),
    }
}

/// Builds the material `name`.
fn material(name: &str, m: &MaterialSpec, file: &str, res: &Resources) -> Result<Material, SceneError> {
    let entry = format!("materials.{name}");
    let at = At { file, entry: &entry };
    Ok(match m {
        MaterialSpec::Diffuse(m) => {
            let r = m
                .reflectance
                .as_ref()
                .ok_or_else(|| at.err("diffuse needs `reflectance`"))?;
            Material::Diffuse {
                reflectance: colour_texture(r, "reflectance", at, res)?,
            }
        }
        MaterialSpec::Dielectric(m) => {
            let eta = m.eta.ok_or_else(|| at.err("dielectric needs `eta`"))?;
            let b = RoughDielectric::new(m.dist.unwrap_or(Distribution::Ggx), eta, m.m.unwrap_or(0.0))
                .map_err(|e| at.err(e))?;
            Material::Fixed(Arc::new(b))
        }
        MaterialSpec::Paper(m) => {
            let (p, slab) = paper_params(m, at, res)?;
            let thickness = match &m.thickness_map {
                None => None,
                Some(t) => {
                    if !(t.min > 0.0 && t.min <= 1.0) {
                        return Err(at.err(format!("`thickness_map.min` = {} is outside (0, 1]", t.min)));
                    }
                    Some(ThicknessMap {
                        map: grey_image(&t.file, t.scale, "thickness_map", at, res)?,
                        min: t.min,
                    })
                }
            };
            let ink = match &m.ink_map {
                None => None,
                Some(k) => {
                    let s = at.colour_in(&k.sigma_a, "ink_map.sigma_a", 0.0, f64::INFINITY)?;
                    if !s.is_finite() {
                        return Err(at.err("`ink_map.sigma_a` must be finite"));
                    }
                    Some(InkMap {
                        map: grey_image(&k.file, k.scale, "ink_map", at, res)?,
                        sigma_a: s,
                    })
                }
            };
            let factory: crate::material::PaperFactory = match m.model.unwrap_or_default() {
                SheetModel::Paper => {
                    slab.check_model(paperbsdf_core::models::ModelKind::Paper, "paper", "slab_nodes")
                        .map_err(|e| at.err(e))?;
                    Arc::new(paper_model::paper_bsdf)
                }
                SheetModel::Slab => {
                    let options = slab.options("slab_nodes").map_err(|e| at.err(e))?;
                    Arc::new(move |p: &PaperParams| paper_model::slab_bsdf_with(p, &options))
                }
            };
            let pm = PaperMaterial::new(p, thickness, ink, factory).map_err(|e| at.err(e))?;
            Material::Paper(Box::new(pm))
        }
        MaterialSpec::Measured(m) => {
            let rel = m
                .file
                .as_ref()
                .ok_or_else(|| at.err("measured needs `file` (an RGL .bsdf file)"))?;
            let b = res.measured(rel).map_err(|e| at.err(format!("`file`: {e}")))?;
            Material::Fixed(Arc::new(b))
        }
        MaterialSpec::Black => Material::Black,
    })
}

/// The affine transform of a shape's `transform` steps, applied first to last.
fn transform(steps: &[TransformSpec], at: At) -> Result<Affine, SceneError> {
    let mut a = Affine::IDENTITY;
    for (k, s) in steps.iter().enumerate() {
        let n = s.translate.is_some() as u8 + s.scale.is_some() as u8 + s.rotate.is_some() as u8;
        let e = |m: &str| at.err(format!("transform[{k}]: {m}"));
        if n != 1 {
            return Err(e("each step needs exactly one of `translate`, `scale`, `rotate`"));
        }
        if s.angle.is_some() != s.rotate.is_some() {
            return Err(e("`angle` goes with `rotate` (and `rotate` needs `angle`)"));
        }
        let step = if let Some(t) = s.translate {
            at.finite("translate", &t)?;
            Affine {
                m: DMat3::IDENTITY,
                t: v3(t),
            }
        } else if let Some(sc) = &s.scale {
            let v = sc.rgb().0;
            at.finite("scale", &v)?;
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

/// The `[render]` settings over the defaults, checked.
fn settings(r: &RenderSpec, at: At) -> Result<Settings, SceneError> {
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
        return Err(at.err(format!(
            "image size {}x{} is outside 1..16384",
            settings.width, settings.height
        )));
    }
    if settings.spp == 0 {
        return Err(at.err("`spp` must be at least 1"));
    }
    if settings.max_depth == 0 {
        return Err(at.err("`max_depth` must be at least 1"));
    }
    if !(settings.exposure.is_finite() && settings.exposure > 0.0) {
        return Err(at.err(format!("`exposure` = {} must be positive", settings.exposure)));
    }
    Ok(settings)
}

/// The primitives of one `[[shapes]]` entry, placed by its transform.
fn shape_primitives(s: &ShapeSpec, at: At, res: &Resources) -> Result<Vec<Shape>, SceneError> {
    let a = transform(&s.transform, at)?;
    if !a.is_invertible() {
        return Err(at.err("the transform is singular"));
    }
    let only = |keys: &[(&str, bool)]| -> Result<(), SceneError> {
        match keys.iter().find(|(_, present)| *present) {
            Some((k, _)) => Err(at.err(format!("key `{k}` does not apply to a `{}` shape", s.kind))),
            None => Ok(()),
        }
    };
    Ok(match s.kind.as_str() {
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
            at.finite("center", &c)?;
            let r = s.radius.unwrap_or(1.0);
            if !(r.is_finite() && r > 0.0) {
                return Err(at.err(format!("`radius` = {r} must be positive")));
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
            let f = s.file.as_ref().ok_or_else(|| at.err("obj needs `file`"))?;
            load_obj(&res.base_dir.join(f), &a).map_err(|e| at.err(e))?
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
                return Err(at.err("`size` must be two positive numbers"));
            }
            if !(1..=1000).contains(&panels) {
                return Err(at.err(format!("`panels` = {panels} is outside 1..1000")));
            }
            if !(0.0..90.0).contains(&ang) {
                return Err(at.err(format!("`fold_angle` = {ang} is outside [0, 90) degrees")));
            }
            transform_tris(folded_sheet(w, h, panels, ang), &a)
        }
        other => {
            return Err(at.err(format!(
                "unknown shape type `{other}` (allowed: rectangle, sphere, obj, folded)"
            )))
        }
    })
}

/// Builds a [`Scene`] from a parsed description.
pub fn build(spec: &SceneSpec, file: &str, res: &Resources) -> Result<Scene, SceneError> {
    let settings = settings(&spec.render, At { file, entry: "render" })?;
    let c = &spec.camera;
    let at = At { file, entry: "camera" };
    at.finite("origin", &c.origin)?;
    at.finite("target", &c.target)?;
    at.finite("up", &c.up)?;
    let camera = Camera::look_at(v3(c.origin), v3(c.target), v3(c.up), c.fov).map_err(|e| at.err(e))?;
    let at = At {
        file,
        entry: "environment",
    };
    let environment = match &spec.environment {
        None => None,
        Some(e) => Some(at.colour_in(&e.radiance, "radiance", 0.0, f64::INFINITY)?),
    };
    if environment.is_some_and(|e| !e.is_finite()) {
        return Err(at.err("`radiance` must be finite"));
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
        let at = At { file, entry: &entry };
        let shapes = shape_primitives(s, at, res)?;
        let material = match &s.material {
            None => black,
            Some(m) => *mat_index.get(m).ok_or_else(|| {
                at.err(format!(
                    "unknown material `{m}` (defined: {})",
                    spec.materials.keys().cloned().collect::<Vec<_>>().join(", ")
                ))
            })?,
        };
        let emission = match &s.emission {
            None => None,
            Some(e) => {
                let v = at.colour_in(e, "emission", 0.0, f64::INFINITY)?;
                if !v.is_finite() {
                    return Err(at.err("`emission` must be finite"));
                }
                Some(v)
            }
        };
        if s.two_sided && emission.is_none() {
            return Err(at.err("`two_sided` needs `emission`"));
        }
        let mask = match &s.mask {
            None => None,
            Some(f) => Some(grey_image(f, None, "mask", at, res)?),
        };
        b.object(
            s.name.as_deref().unwrap_or(&entry),
            shapes,
            material,
            emission,
            s.two_sided,
            mask,
        );
    }
    Ok(b.build(camera, environment, settings))
}
