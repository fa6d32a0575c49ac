//! The models of the project behind one interface (docs/design.md 4.7): the Paper
//! BSDF, the reduced multilayer model, the Lambertian + rough glass baseline
//! and the rough dielectric alone, each a [`Bsdf`] whose components can be
//! evaluated one by one ([`ComponentModel`]). Parameter files name them
//! [`ModelKind`] (the one registry of model names): `paper` and `reduced-multilayer` take
//! [`PaperParams`](crate::PaperParams), `lambert-glass` takes
//! [`LambertGlassParams`], `rough-dielectric` takes [`RoughDielectricParams`].
//!
//! **What "rough glass" means here (`lambert-glass`).** A sheet of glass in
//! air has two faces. We take both faces to be the same rough interface
//! (`eta`, `m`, `dist`), and model:
//! - reflection ([`Component::Surface`]): the Walter reflection of the face the
//!   light arrives at (first-surface reflection; light reflected inside and
//!   leaving again is neglected);
//! - transmission ([`Component::Direct`]): light crossing both faces, with
//!   weight `Att(wi) Att(wo)` and the angular spread of two rough faces of
//!   [`crate::paper::direct`] centred on the straight-through direction (a thin
//!   sheet does not bend light; a single Walter interface would refract the
//!   lobe to the inside angle, which no viewer in air sees). For a smooth sheet
//!   it is a delta lobe with the exact lossless value `(1 - F)/(1 + F)`
//!   (internal reflections summed);
//! - the Lambertian body ([`Component::Multiple`]): diffuse reflection `k_d`
//!   and transmission `k_t` of the light that crosses the first face,
//!   `k Att(mu_i) Att(mu_o) / (pi Abar)` (`Abar = 2 int Att mu dmu`): Lambertian
//!   inside the glass, seen through its faces.
//!
//! The clear transmission carries the fraction `1 - k_d - k_t` of the light
//! that the Lambertian body does not take (`k_d + k_t <= 1` is required).
//! **Bounded as a whole (our change to the supplement's baseline).** The
//! supplement adds flat `k_d / pi`, `k_t / pi` to the surface reflection, so
//! its albedo reached 1.84 (`k_d = 1`, `eta = 5`). Here the body only gets the
//! light that the face lets in: for light at `mu` the albedo is
//! `R_s(mu) + Att(mu) (k_d + k_t + (1 - k_d - k_t) X) <= R_s(mu) + Att(mu) <= 1`
//! with `X <= 1` the clear part's exit fraction.

use crate::bsdf::{select_lobe, Bsdf, BsdfFlags, BsdfSample};
use crate::dielectric::{RoughDielectric, RoughDielectricParams};
use crate::fresnel::fresnel_dielectric;
use crate::geometry::sample_cosine_hemisphere;
use crate::microfacet::Distribution;
use crate::paper::direct::SheetKernel;
use crate::paper::face::Face;
use crate::paper::grazing;
pub use crate::paper::{Component, ComponentSet, PaperBsdf, Side};
use crate::params::{Colour, ParamError};
use crate::spectrum::Rgb;
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// The models of the project, by the names that parameter files, FIT.json
/// files, scenes and the command line use: the one registry of model names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ModelKind {
    /// `paper`: the Paper BSDF ([`PaperBsdf::new`]), parameters [`PaperParams`](crate::PaperParams).
    Paper,
    /// `reduced-multilayer`: the supplement's reduced multilayer model
    /// ([`PaperBsdf::reduced_multilayer`]), parameters [`PaperParams`](crate::PaperParams).
    ReducedMultilayer,
    /// `lambert-glass`: Lambertian + rough glass ([`LambertGlass`]), parameters [`LambertGlassParams`].
    LambertGlass,
    /// `rough-dielectric`: one rough interface ([`RoughDielectric`]), parameters [`RoughDielectricParams`].
    RoughDielectric,
    /// `measured`: a measured RGL `.bsdf` file; its "parameters" are the file
    /// (read by `paperbsdf_io`, not by this crate).
    Measured,
    /// `slab`: the sheet of `paper` (same [`PaperParams`](crate::PaperParams))
    /// solved numerically by adding-doubling; built by `paperbsdf_slab`
    /// (`SlabBsdf`), not by this crate, which has no linear algebra.
    Slab,
}

impl ModelKind {
    /// Every model, in the order of the listings.
    pub const ALL: [ModelKind; 6] = [
        ModelKind::Paper,
        ModelKind::ReducedMultilayer,
        ModelKind::LambertGlass,
        ModelKind::RoughDielectric,
        ModelKind::Measured,
        ModelKind::Slab,
    ];

    /// The name in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Paper => "paper",
            ModelKind::ReducedMultilayer => "reduced-multilayer",
            ModelKind::LambertGlass => "lambert-glass",
            ModelKind::RoughDielectric => "rough-dielectric",
            ModelKind::Measured => "measured",
            ModelKind::Slab => "slab",
        }
    }

    /// Whether the model is a slab whose parameters are [`PaperParams`](crate::PaperParams)
    /// (`paper`, `reduced-multilayer`, `slab`; the paper presets are such parameters).
    pub fn is_slab(self) -> bool {
        matches!(self, ModelKind::Paper | ModelKind::ReducedMultilayer | ModelKind::Slab)
    }

    /// Whether the fitter can fit the model (`paper`, `reduced-multilayer`, `lambert-glass`).
    pub fn is_fittable(self) -> bool {
        matches!(
            self,
            ModelKind::Paper | ModelKind::ReducedMultilayer | ModelKind::LambertGlass
        )
    }

    /// The models the fitter can fit, in the order of the listings.
    pub fn fittable() -> impl Iterator<Item = ModelKind> {
        Self::ALL.into_iter().filter(|k| k.is_fittable())
    }

    /// The names of `kinds` joined by `, ` (for messages listing the allowed values).
    pub fn list(kinds: impl IntoIterator<Item = ModelKind>) -> String {
        kinds.into_iter().map(|k| k.name()).collect::<Vec<_>>().join(", ")
    }

    /// Builds the model from its typed parameters (`params` must be of this
    /// model's parameter type; `measured` is built by `paperbsdf_io`). The
    /// error names the parameter and its allowed range.
    pub fn build(self, params: &ModelParams) -> Result<Box<dyn ComponentModel>, ParamError> {
        match (self, params) {
            (ModelKind::Paper, ModelParams::Slab(p)) => Ok(Box::new(PaperBsdf::new(p)?)),
            (ModelKind::ReducedMultilayer, ModelParams::Slab(p)) => Ok(Box::new(PaperBsdf::reduced_multilayer(p)?)),
            (ModelKind::LambertGlass, ModelParams::LambertGlass(p)) => Ok(Box::new(LambertGlass::new(p)?)),
            (ModelKind::RoughDielectric, ModelParams::RoughDielectric(p)) => Ok(Box::new(p.build()?)),
            (ModelKind::Slab, _) => Err(ParamError::Invalid {
                name: "model".to_string(),
                message: "the model `slab` is built by paperbsdf_slab::SlabBsdf (or paperbsdf_io::models), \
                          not by paperbsdf-core, which has no linear algebra"
                    .to_string(),
            }),
            (k, p) => Err(ParamError::Invalid {
                name: "model".to_string(),
                message: format!("model `{}` does not take {} parameters", k.name(), p.kind_name()),
            }),
        }
    }
}

impl std::fmt::Display for ModelKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A model name that is not one of [`ModelKind::ALL`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown model `{}`; known models: {}", .0, ModelKind::list(ModelKind::ALL))]
pub struct UnknownModel(pub String);

impl std::str::FromStr for ModelKind {
    type Err = UnknownModel;
    /// Parses a name of [`ModelKind::name`] (exact, as in files).
    fn from_str(s: &str) -> Result<Self, UnknownModel> {
        ModelKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| UnknownModel(s.to_string()))
    }
}

/// The typed parameters of a model of [`ModelKind`] (`paper` and
/// `reduced-multilayer` share [`PaperParams`](crate::PaperParams)).
#[derive(Clone, Debug, PartialEq)]
pub enum ModelParams {
    /// `paper`, `reduced-multilayer`.
    Slab(crate::PaperParams),
    /// `lambert-glass`.
    LambertGlass(LambertGlassParams),
    /// `rough-dielectric`.
    RoughDielectric(RoughDielectricParams),
}

impl ModelParams {
    fn kind_name(&self) -> &'static str {
        match self {
            ModelParams::Slab(_) => "paper-slab",
            ModelParams::LambertGlass(_) => "lambert-glass",
            ModelParams::RoughDielectric(_) => "rough-dielectric",
        }
    }
}

/// A [`Bsdf`] whose components can be evaluated separately (for plots and fits).
pub trait ComponentModel: Bsdf {
    /// One component `f(wi, wo)` without cosine (zero for a component the model lacks).
    fn eval_component(&self, wi: DVec3, wo: DVec3, c: Component) -> Rgb;
    /// Whether the model's parameters were RGB (output gets `r,g,b` columns).
    fn is_rgb(&self) -> bool;
    /// The components this model has, in the order of [`Component::ALL`].
    fn components(&self) -> &'static [Component];
    /// The model's curves in plots: a legend label and the components its curve
    /// sums. By default one curve per component of [`ComponentModel::components`],
    /// labelled by [`Component::name`]; `lambert-glass` draws its glass
    /// (surface reflection and clear transmission) as one curve.
    fn legend(&self) -> Vec<(&'static str, ComponentSet)> {
        self.components()
            .iter()
            .map(|&c| (c.name(), ComponentSet::only(c)))
            .collect()
    }
    /// The sum of the components in `set` (each by [`ComponentModel::eval_component`],
    /// in the order of [`Component::ALL`]), without cosine.
    fn eval_set(&self, wi: DVec3, wo: DVec3, set: ComponentSet) -> Rgb {
        Component::ALL
            .into_iter()
            .filter(|&c| set.contains(c))
            .fold(Rgb::ZERO, |sum, c| sum + self.eval_component(wi, wo, c))
    }
}

impl ComponentModel for PaperBsdf {
    fn eval_component(&self, wi: DVec3, wo: DVec3, c: Component) -> Rgb {
        self.eval_components(wi, wo, c.into())
    }
    fn is_rgb(&self) -> bool {
        PaperBsdf::is_rgb(self)
    }
    fn components(&self) -> &'static [Component] {
        if self.options().direct {
            &Component::ALL
        } else {
            &[Component::Surface, Component::Single, Component::Multiple]
        }
    }
}

impl ComponentModel for RoughDielectric {
    fn eval_component(&self, wi: DVec3, wo: DVec3, c: Component) -> Rgb {
        match c {
            Component::Surface => self.eval(wi, wo),
            _ => Rgb::ZERO,
        }
    }
    fn is_rgb(&self) -> bool {
        false
    }
    fn components(&self) -> &'static [Component] {
        &[Component::Surface]
    }
}

impl RoughDielectricParams {
    /// Checks `eta` in [1, 5] and `m` in [0, pi/2]; the error names the parameter.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.build().map(|_| ())
    }
}

/// Parameters of the `lambert-glass` model (supplement Figure 4; module doc).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LambertGlassParams {
    /// Optional label.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Lambertian reflectance, in [0, 1] per channel.
    pub k_d: Colour,
    /// Lambertian transmittance, in [0, 1] per channel; `k_d + k_t <= 1`.
    pub k_t: Colour,
    /// Relative index of the glass faces, in [1, 5].
    pub eta: f64,
    /// Roughness (microfacet alpha) of both faces, in [0, pi/2].
    pub m: f64,
    /// Microfacet distribution of both faces.
    pub dist: Distribution,
}

impl LambertGlassParams {
    /// Checks every parameter's range and `k_d + k_t <= 1` in every channel.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.k_d.check_range("k_d", 0.0, 1.0)?;
        self.k_t.check_range("k_t", 0.0, 1.0)?;
        ParamError::check_range("eta", self.eta, 1.0, 5.0)?;
        ParamError::check_range("m", self.m, 0.0, std::f64::consts::FRAC_PI_2)?;
        let s = self.k_d.rgb() + self.k_t.rgb();
        if s.max_channel() > 1.0 {
            return Err(ParamError::Invalid {
                name: "k_t".into(),
                message: format!(
                    "k_d + k_t = {} exceeds 1 (the sheet would create light)",
                    s.max_channel()
                ),
            });
        }
        Ok(())
    }
}

/// The Lambertian + rough glass sheet (module doc).
#[derive(Clone, Debug)]
pub struct LambertGlass {
    face: Face,
    kernel: SheetKernel,
    k_d: Rgb,
    k_t: Rgb,
    clear: Rgb,
    is_rgb: bool,
}

impl LambertGlass {
    /// The model of `p` (validated).
    pub fn new(p: &LambertGlassParams) -> Result<LambertGlass, ParamError> {
        p.validate()?;
        let face = Face::walter(p.dist, p.eta, p.m, true, "")?;
        let beck = p.dist == Distribution::Beckmann;
        let kernel = SheetKernel::new([(p.eta, p.m, beck), (p.eta, p.m, beck)]);
        let (k_d, k_t) = (p.k_d.rgb(), p.k_t.rgb());
        Ok(LambertGlass {
            face,
            kernel,
            k_d,
            k_t,
            clear: (Rgb::ONE - k_d - k_t).map(|v| v.max(0.0)),
            is_rgb: p.k_d.is_rgb() || p.k_t.is_rgb(),
        })
    }

    /// Sum of the components in `set` (no cosine; delta lobes excluded).
    pub fn eval_components(&self, wi: DVec3, wo: DVec3, set: ComponentSet) -> Rgb {
        if grazing(wi) || grazing(wo) || !wi.is_finite() || !wo.is_finite() {
            return Rgb::ZERO;
        }
        let reflect = wi.z * wo.z > 0.0;
        let mut out = Rgb::ZERO;
        if reflect {
            if set.contains(Component::Surface) {
                let e = Side::of(wi);
                out += Rgb::splat(self.face.reflection(e.local(wi), e.local(wo)));
            }
            if set.contains(Component::Multiple) {
                out += self.k_d * self.body(wi, wo);
            }
        } else {
            if set.contains(Component::Multiple) {
                out += self.k_t * self.body(wi, wo);
            }
            if set.contains(Component::Direct) && !self.kernel.is_delta() {
                let k = self.kernel.eval(DVec2::new(-wi.x, -wi.y), DVec2::new(wo.x, wo.y), 1.0);
                out += self.clear * (k * self.face.att(wi.z.abs()) * self.face.att(wo.z.abs()));
            }
        }
        out
    }

    /// The Lambertian body's shape `Att(mu_i) Att(mu_o) / (pi Abar)` (module doc).
    #[inline]
    fn body(&self, wi: DVec3, wo: DVec3) -> f64 {
        self.face.att(wi.z.abs()) * self.face.att(wo.z.abs()) / (PI * self.face.abar)
    }

    fn lobe_probs(&self, wo: DVec3) -> [f64; 4] {
        let mu = wo.z.abs();
        let est = [
            self.face.r_out(mu),
            self.k_d.mean() * self.face.att(mu),
            self.k_t.mean() * self.face.att(mu),
            self.clear.mean() * self.face.att(mu) * self.face.att(mu),
        ];
        let present = [!self.face.is_index_matched(), est[1] > 0.0, est[2] > 0.0, est[3] > 0.0];
        crate::bsdf::defensive_probabilities(est, present)
    }

    fn pdf_with(&self, wi: DVec3, wo: DVec3, pr: &[f64; 4]) -> f64 {
        if grazing(wi) || grazing(wo) {
            return 0.0;
        }
        if wi.z * wo.z > 0.0 {
            let e = Side::of(wo);
            pr[0] * self.face.reflection_pdf(e.local(wi), e.local(wo)) + pr[1] * wi.z.abs() / PI
        } else {
            let mut p = pr[2] * wi.z.abs() / PI;
            if !self.kernel.is_delta() {
                p += pr[3] * self.kernel.pdf_wi(wi, wo, 1.0);
            }
            p
        }
    }
}

impl Bsdf for LambertGlass {
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.eval_components(wi, wo, ComponentSet::ALL)
    }

    fn sample(&self, wo: DVec3, uc: f64, u: [f64; 2]) -> Option<BsdfSample> {
        if grazing(wo) || !wo.is_finite() {
            return None;
        }
        let pr = self.lobe_probs(wo);
        let (k, _) = select_lobe(uc, &pr)?;
        let so = wo.z.signum();
        let x = Side::of(wo);
        let wi = match k {
            0 => {
                if self.face.is_smooth() {
                    let wi = DVec3::new(-wo.x, -wo.y, wo.z);
                    let f = fresnel_dielectric(wo.z.abs(), self.face.bd.eta);
                    return Some(BsdfSample {
                        wi,
                        f: Rgb::splat(f / wi.z.abs()),
                        pdf: pr[0],
                        flags: BsdfFlags::REFLECTION | BsdfFlags::SPECULAR,
                    });
                }
                x.local(self.face.sample_reflection(x.local(wo), u)?)
            }
            1 | 2 => {
                let w = sample_cosine_hemisphere(u);
                let s = if k == 1 { so } else { -so };
                DVec3::new(w.x, w.y, s * w.z)
            }
            _ => {
                if self.kernel.is_delta() {
                    let wi = -wo;
                    let f = fresnel_dielectric(wo.z.abs(), self.face.bd.eta);
                    let t = if self.face.is_smooth() {
                        (1.0 - f) / (1.0 + f)
                    } else {
                        1.0
                    };
                    return Some(BsdfSample {
                        wi,
                        f: self.clear * (t / wi.z.abs()),
                        pdf: pr[3],
                        flags: BsdfFlags::TRANSMISSION | BsdfFlags::SPECULAR,
                    });
                }
                self.kernel.sample_wi(wo, -so, 1.0, u)?
            }
        };
        let pdf = self.pdf_with(wi, wo, &pr);
        if !pdf.is_finite() || pdf <= 0.0 {
            return None;
        }
        let dir = if wi.z * wo.z > 0.0 {
            BsdfFlags::REFLECTION
        } else {
            BsdfFlags::TRANSMISSION
        };
        let lobe = if k == 1 || k == 2 {
            BsdfFlags::DIFFUSE
        } else {
            BsdfFlags::GLOSSY
        };
        Some(BsdfSample {
            wi,
            f: self.eval(wi, wo),
            pdf,
            flags: dir | lobe,
        })
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if grazing(wo) || !wo.is_finite() || !wi.is_finite() {
            return 0.0;
        }
        self.pdf_with(wi, wo, &self.lobe_probs(wo))
    }

    fn flags(&self) -> BsdfFlags {
        let mut f = BsdfFlags::REFLECTION | BsdfFlags::TRANSMISSION | BsdfFlags::DIFFUSE;
        if self.face.microfacet().is_some() || !self.kernel.is_delta() {
            f |= BsdfFlags::GLOSSY;
        }
        if self.face.is_smooth() || self.kernel.is_delta() {
            f |= BsdfFlags::SPECULAR;
        }
        f
    }
}

impl ComponentModel for LambertGlass {
    fn eval_component(&self, wi: DVec3, wo: DVec3, c: Component) -> Rgb {
        self.eval_components(wi, wo, ComponentSet::only(c))
    }
    fn is_rgb(&self) -> bool {
        self.is_rgb
    }
    fn components(&self) -> &'static [Component] {
        &[Component::Surface, Component::Multiple, Component::Direct]
    }
    /// `lambert` (the Lambertian body, [`Component::Multiple`]) and `rough glass`
    /// (the glass: its surface reflection and its clear transmission).
    fn legend(&self) -> Vec<(&'static str, ComponentSet)> {
        vec![
            ("lambert", ComponentSet::only(Component::Multiple)),
            (
                "rough glass",
                ComponentSet::only(Component::Surface).with(Component::Direct),
            ),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every name parses back to its model, unknown names list all six, and
    /// each model is built from its own parameter type only.
    #[test]
    fn registry_round_trips_and_builds() {
        for k in ModelKind::ALL {
            assert_eq!(k.name().parse::<ModelKind>(), Ok(k));
        }
        let e = "Paper".parse::<ModelKind>().unwrap_err().to_string();
        assert_eq!(
            e,
            "unknown model `Paper`; known models: paper, reduced-multilayer, lambert-glass, rough-dielectric, measured, slab"
        );
        assert_eq!(
            ModelKind::list(ModelKind::fittable()),
            "paper, reduced-multilayer, lambert-glass"
        );
        let p = crate::presets::preset("matte").unwrap();
        let slab = ModelParams::Slab(p.clone());
        let m = ModelKind::Paper.build(&slab).unwrap();
        let direct = PaperBsdf::new(&p).unwrap();
        let (wi, wo) = (
            DVec3::new(0.3, 0.1, 0.9).normalize(),
            DVec3::new(-0.5, 0.2, 0.7).normalize(),
        );
        assert_eq!(m.eval(wi, wo), direct.eval(wi, wo));
        assert_eq!(m.components(), &Component::ALL);
        let r = ModelKind::ReducedMultilayer.build(&slab).unwrap();
        assert_eq!(r.eval(wi, wo), PaperBsdf::reduced_multilayer(&p).unwrap().eval(wi, wo));
        let e = ModelKind::LambertGlass.build(&slab).err().unwrap().to_string();
        assert!(
            e.contains("model `lambert-glass` does not take paper-slab parameters"),
            "{e}"
        );
        assert!(ModelKind::Measured.build(&slab).is_err());
        let e = ModelKind::Slab.build(&slab).err().unwrap().to_string();
        assert!(e.contains("paperbsdf_slab::SlabBsdf"), "{e}");
        assert!(ModelKind::Slab.is_slab() && !ModelKind::Slab.is_fittable());
    }
}
