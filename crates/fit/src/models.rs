//! The models the fitter knows, as [`FitModel`]s: `paper` (the Paper BSDF,
//! docs/design.md section 4), `reduced-multilayer` (the Paper BSDF without the
//! attenuation term, section 4.7) and `lambert-glass` (Lambertian reflection
//! and transmission plus a rough dielectric, section 4.7); and `slab` (the
//! same sheet as `paper` solved by adding-doubling, [`SlabFit`]), which
//! refines a `paper` fit rather than being searched.
//!
//! Search bounds (Table 2 of the supplement, made finite):
//!
//! | parameter | bounds | scale | default start |
//! |---|---|---|---|
//! | `sigma_a` (1/mm) | [1e-3, 100] | log | 0.5 |
//! | `sigma_s` (1/mm) | [1, 3000] | log | 100 |
//! | `g_f`, `g_b` | [-0.98, 0.98] | linear | 0.8, -0.3 |
//! | `w_b` | [0, 1] | linear | 0.2 |
//! | `eta_f`, `eta_b`, `eta` | [1.05, 3] | linear | 1.5 |
//! | `m_f`, `m_b`, `m` | [0.01, pi/2] | log | 0.3 |
//! | `k_d` | [0, 1] | linear | 0.5 |
//! | `k_t / (1 - k_d)` | [0, 1] | linear | 0.5 |
//!
//! The index range is narrower than Table 2's (1, 5]: paper's cellulose, fillers
//! and coatings have indices of 1.5 to 2, and a box that is mostly unphysical
//! makes the global search slower. `d` is not fitted (the paper measured it). Index-matched (`eta = 1`) and
//! smooth (`m = 0`) faces are not searched (docs/design.md section 3). Each
//! microfacet distribution choice (`ggx` or `beckmann`, per face) is a
//! separate variant; the fitter tries every variant and keeps the best.
//! With RGB data `sigma_a`, `sigma_s` (and `k_d`, `k_t`) are fitted per channel.
//! The Lambert-glass model requires `k_d + k_t <= 1`; it is searched as `k_d`
//! and the fraction `k_t / (1 - k_d)` of what is left, so that every point of
//! the box is a valid model.

use crate::error::FitError;
use crate::model::{ComponentModel, FitModel, ParamSpec, Scale};
use paperbsdf_core::models::{LambertGlass, LambertGlassParams, ModelKind, ModelParams};
use paperbsdf_core::{Colour, Distribution, FaceScattering, PaperParams};

/// The model named `name` if the fitter can fit it; else the error lists the
/// models it can fit.
fn fittable(name: &str) -> Result<ModelKind, FitError> {
    match name.parse::<ModelKind>() {
        Ok(k) if k.is_fittable() => Ok(k),
        _ => Err(FitError::UnknownModel { name: name.to_string() }),
    }
}

const DISTS: [Distribution; 2] = [Distribution::Ggx, Distribution::Beckmann];

fn colour_specs(name: &str, lo: f64, hi: f64, scale: Scale, default: f64, rgb: bool) -> Vec<ParamSpec> {
    if rgb {
        (0..3)
            .map(|c| ParamSpec::new(format!("{name}[{c}]"), lo, hi, scale, default))
            .collect()
    } else {
        vec![ParamSpec::new(name, lo, hi, scale, default)]
    }
}

fn colour_of(x: &[f64], rgb: bool) -> Colour {
    if rgb {
        Colour::Rgb([x[0], x[1], x[2]])
    } else {
        Colour::Scalar(x[0])
    }
}

fn colour_json(c: &Colour) -> serde_json::Value {
    serde_json::to_value(c).expect("colour serialises")
}

/// The Paper BSDF (or its reduced multilayer variant) with fixed thickness and distributions.
pub struct PaperFit {
    d: f64,
    dist_f: Distribution,
    dist_b: Distribution,
    rgb: bool,
    reduced: bool,
    specs: Vec<ParamSpec>,
    face_scattering: FaceScattering,
}

impl PaperFit {
    /// A variant: thickness `d` (mm), the two distributions, RGB or scalar
    /// coefficients, and whether it is the reduced multilayer model.
    pub fn new(d: f64, dist_f: Distribution, dist_b: Distribution, rgb: bool, reduced: bool) -> Self {
        let mut specs = colour_specs("sigma_a", 1e-3, 100.0, Scale::Log, 0.5, rgb);
        specs.extend(colour_specs("sigma_s", 1.0, 3000.0, Scale::Log, 100.0, rgb));
        let pi2 = std::f64::consts::FRAC_PI_2;
        specs.extend([
            ParamSpec::new("g_f", -0.98, 0.98, Scale::Linear, 0.8),
            ParamSpec::new("g_b", -0.98, 0.98, Scale::Linear, -0.3),
            ParamSpec::new("w_b", 0.0, 1.0, Scale::Linear, 0.2),
            ParamSpec::new("eta_f", 1.05, 3.0, Scale::Linear, 1.5),
            ParamSpec::new("eta_b", 1.05, 3.0, Scale::Linear, 1.5),
            ParamSpec::new("m_f", 0.01, pi2, Scale::Log, 0.3),
            ParamSpec::new("m_b", 0.01, pi2, Scale::Log, 0.3),
        ]);
        PaperFit {
            d,
            dist_f,
            dist_b,
            rgb,
            reduced,
            specs,
            face_scattering: FaceScattering::default(),
        }
    }

    /// The same variant with faces that scatter once or many times among their microfacets.
    pub fn with_face_scattering(mut self, fs: FaceScattering) -> Self {
        self.face_scattering = fs;
        self
    }

    /// The parameter set of values `x`.
    pub fn params(&self, x: &[f64]) -> PaperParams {
        let nc = if self.rgb { 3 } else { 1 };
        let r = &x[2 * nc..];
        PaperParams {
            name: None,
            d: self.d,
            sigma_a: colour_of(&x[..nc], self.rgb),
            sigma_s: colour_of(&x[nc..2 * nc], self.rgb),
            g_f: r[0],
            g_b: r[1],
            w_b: r[2],
            eta_f: r[3],
            eta_b: r[4],
            m_f: r[5],
            m_b: r[6],
            dist_f: self.dist_f,
            dist_b: self.dist_b,
            face_scattering: self.face_scattering,
        }
    }
}

impl FitModel for PaperFit {
    fn model_name(&self) -> &str {
        if self.reduced {
            ModelKind::ReducedMultilayer.name()
        } else {
            ModelKind::Paper.name()
        }
    }
    fn variant(&self) -> String {
        format!("dist_f={}, dist_b={}", self.dist_f.name(), self.dist_b.name())
    }
    fn specs(&self) -> &[ParamSpec] {
        &self.specs
    }
    fn build(&self, x: &[f64]) -> Result<Box<dyn ComponentModel>, FitError> {
        let kind = if self.reduced {
            ModelKind::ReducedMultilayer
        } else {
            ModelKind::Paper
        };
        Ok(kind.build(&ModelParams::Slab(self.params(x)))?)
    }
    /// The parameter file: every parameter; `face_scattering` only when it is
    /// not the default `multiple` (a file without it means `multiple`).
    fn params_json(&self, x: &[f64]) -> serde_json::Value {
        let p = self.params(x);
        let mut j = serde_json::json!({
            "d": p.d, "sigma_a": colour_json(&p.sigma_a), "sigma_s": colour_json(&p.sigma_s),
            "g_f": p.g_f, "g_b": p.g_b, "w_b": p.w_b, "eta_f": p.eta_f, "eta_b": p.eta_b,
            "m_f": p.m_f, "m_b": p.m_b, "dist_f": p.dist_f.name(), "dist_b": p.dist_b.name(),
        });
        if p.face_scattering != FaceScattering::default() {
            j["face_scattering"] = p.face_scattering.name().into();
        }
        j
    }
}

/// The Lambert + rough glass baseline with a fixed distribution.
pub struct LambertGlassFit {
    dist: Distribution,
    rgb: bool,
    specs: Vec<ParamSpec>,
}

impl LambertGlassFit {
    /// A variant with distribution `dist`, RGB or scalar Lambert weights.
    pub fn new(dist: Distribution, rgb: bool) -> Self {
        let mut specs = colour_specs("k_d", 0.0, 1.0, Scale::Linear, 0.5, rgb);
        specs.extend(colour_specs("k_t/(1-k_d)", 0.0, 1.0, Scale::Linear, 0.5, rgb));
        specs.push(ParamSpec::new("eta", 1.05, 3.0, Scale::Linear, 1.5));
        specs.push(ParamSpec::new("m", 0.01, std::f64::consts::FRAC_PI_2, Scale::Log, 0.3));
        LambertGlassFit { dist, rgb, specs }
    }
    /// The parameter set of values `x`.
    pub fn params(&self, x: &[f64]) -> LambertGlassParams {
        let nc = if self.rgb { 3 } else { 1 };
        let kt: Vec<f64> = (0..nc).map(|c| x[nc + c] * (1.0 - x[c])).collect();
        LambertGlassParams {
            name: None,
            k_d: colour_of(&x[..nc], self.rgb),
            k_t: colour_of(&kt, self.rgb),
            eta: x[2 * nc],
            m: x[2 * nc + 1],
            dist: self.dist,
        }
    }
}

impl FitModel for LambertGlassFit {
    fn model_name(&self) -> &str {
        ModelKind::LambertGlass.name()
    }
    fn variant(&self) -> String {
        format!("dist={}", self.dist.name())
    }
    fn specs(&self) -> &[ParamSpec] {
        &self.specs
    }
    fn build(&self, x: &[f64]) -> Result<Box<dyn ComponentModel>, FitError> {
        Ok(Box::new(LambertGlass::new(&self.params(x))?))
    }
    fn params_json(&self, x: &[f64]) -> serde_json::Value {
        let p = self.params(x);
        serde_json::json!({"k_d": colour_json(&p.k_d), "k_t": colour_json(&p.k_t), "eta": p.eta, "m": p.m, "dist": p.dist.name()})
    }
}

/// The variants of model `name` to search: for the paper models every pair of
/// distributions (thickness `d` required), for lambert-glass both distributions.
/// `dists` restricts the distributions tried (default: both).
pub fn candidates(
    name: &str,
    d: Option<f64>,
    rgb: bool,
    dists: Option<&[Distribution]>,
) -> Result<Vec<Box<dyn FitModel>>, FitError> {
    candidates_with_faces(name, d, rgb, dists, FaceScattering::default())
}

/// [`candidates`] with the faces' microfacet scattering of the Paper BSDF
/// and the reduced multilayer model (`face_scattering`; `lambert-glass` has Walter's faces).
pub fn candidates_with_faces(
    name: &str,
    d: Option<f64>,
    rgb: bool,
    dists: Option<&[Distribution]>,
    face_scattering: FaceScattering,
) -> Result<Vec<Box<dyn FitModel>>, FitError> {
    let ds: Vec<Distribution> = dists.map(|d| d.to_vec()).unwrap_or_else(|| DISTS.to_vec());
    match fittable(name)? {
        kind @ (ModelKind::Paper | ModelKind::ReducedMultilayer) => {
            let d = d.ok_or_else(|| FitError::NeedsThickness(name.to_string()))?;
            if !(d > 0.0 && d.is_finite()) {
                return Err(FitError::Thickness(d));
            }
            let mut v: Vec<Box<dyn FitModel>> = Vec::new();
            for &f in &ds {
                for &b in &ds {
                    v.push(Box::new(
                        PaperFit::new(d, f, b, rgb, kind == ModelKind::ReducedMultilayer)
                            .with_face_scattering(face_scattering),
                    ));
                }
            }
            Ok(v)
        }
        ModelKind::LambertGlass => Ok(ds
            .iter()
            .map(|&dd| Box::new(LambertGlassFit::new(dd, rgb)) as Box<dyn FitModel>)
            .collect()),
        k => unreachable!("fittable() returned {k}"),
    }
}

/// The model `slab` (the sheet solved by adding-doubling, `paperbsdf_slab`)
/// over the parameters of a `paper` or `reduced-multilayer` fit model: the
/// same free parameters, bounds, scales and held values (it reads the sheet
/// from the paper model's parameter file), each build a solve
/// ([`paperbsdf_slab::SlabBsdf::new`]). The fitter refines with it
/// ([`crate::refine`]); it is not searched globally (a solve costs about as
/// much as a thousand Paper BSDF builds).
pub struct SlabFit<'a> {
    paper: &'a dyn FitModel,
    options: paperbsdf_slab::SlabOptions,
}

/// Whether a fit of model `name` can be refined with `slab`: a fittable
/// model with the sheet's parameters (`paper`, `reduced-multilayer`); else
/// [`FitError::RefineFrom`]. The CLI and the Python package check this before
/// the fit, [`SlabFit::new`] when it is built.
pub fn refinable(name: &str) -> Result<ModelKind, FitError> {
    match name.parse::<ModelKind>() {
        Ok(k) if k.is_slab() && k.is_fittable() => Ok(k),
        _ => Err(FitError::RefineFrom {
            model: name.to_string(),
        }),
    }
}

impl<'a> SlabFit<'a> {
    /// `slab` over the parameters of `paper`; an error if `paper`'s
    /// parameters are not the sheet's (`lambert-glass`, [`refinable`]).
    pub fn new(paper: &'a dyn FitModel) -> Result<SlabFit<'a>, FitError> {
        SlabFit::with_options(paper, paperbsdf_slab::SlabOptions::default())
    }
    /// [`SlabFit::new`] solving each sheet with `options` (its nodes: the
    /// CLI's `--slab-nodes`).
    pub fn with_options(
        paper: &'a dyn FitModel,
        options: paperbsdf_slab::SlabOptions,
    ) -> Result<SlabFit<'a>, FitError> {
        refinable(paper.model_name())?;
        Ok(SlabFit { paper, options })
    }
    /// The sheet of values `x`.
    pub fn params(&self, x: &[f64]) -> Result<PaperParams, FitError> {
        serde_json::from_value(self.paper.params_json(x)).map_err(|source| FitError::ParamsJson {
            model: ModelKind::Slab.name().to_string(),
            source,
        })
    }
}

impl FitModel for SlabFit<'_> {
    fn model_name(&self) -> &str {
        ModelKind::Slab.name()
    }
    fn variant(&self) -> String {
        self.paper.variant()
    }
    fn specs(&self) -> &[ParamSpec] {
        self.paper.specs()
    }
    fn build(&self, x: &[f64]) -> Result<Box<dyn ComponentModel>, FitError> {
        Ok(Box::new(paperbsdf_slab::SlabBsdf::with_options(
            &self.params(x)?,
            &self.options,
        )?))
    }
    fn params_json(&self, x: &[f64]) -> serde_json::Value {
        self.paper.params_json(x)
    }
}

/// Builds model `name` from a parameter set (the `params` of a FIT.json):
/// the fittable models and `slab` (the result of `fit --refine slab`) with
/// the default discretisation.
pub fn build_from_params(name: &str, params: &serde_json::Value) -> Result<Box<dyn ComponentModel>, FitError> {
    build_from_params_with(name, params, &paperbsdf_slab::SlabOptions::default())
}

/// [`build_from_params`] solving `slab` with `slab_options` (a FIT.json's
/// recorded `slab_nodes`, `paperbsdf_io::models::SlabSettings::recorded`);
/// the other models ignore them.
pub fn build_from_params_with(
    name: &str,
    params: &serde_json::Value,
    slab_options: &paperbsdf_slab::SlabOptions,
) -> Result<Box<dyn ComponentModel>, FitError> {
    let json_error = |source| FitError::ParamsJson {
        model: name.to_string(),
        source,
    };
    if name.parse::<ModelKind>() == Ok(ModelKind::Slab) {
        let p: PaperParams = serde_json::from_value(params.clone()).map_err(json_error)?;
        return Ok(Box::new(paperbsdf_slab::SlabBsdf::with_options(&p, slab_options)?));
    }
    let kind = fittable(name)?;
    let typed = if kind.is_slab() {
        ModelParams::Slab(serde_json::from_value(params.clone()).map_err(json_error)?)
    } else {
        ModelParams::LambertGlass(serde_json::from_value(params.clone()).map_err(json_error)?)
    };
    Ok(kind.build(&typed)?)
}
