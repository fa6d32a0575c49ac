//! The models of the project behind one interface (DESIGN.md 4.7): the Paper
//! BSDF, the reduced multilayer model, the Lambertian + rough glass baseline
//! and the rough dielectric alone, each a [`Bsdf`] whose components can be
//! evaluated one by one ([`ComponentModel`]). Parameter files name them
//! [`MODEL_NAMES`]: `paper` and `reduced-multilayer` take
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

use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample};
use crate::dielectric::{RoughDielectric, RoughDielectricParams};
use crate::fresnel::fresnel_dielectric;
use crate::geometry::sample_cosine_hemisphere;
use crate::microfacet::Distribution;
use crate::paper::direct::SheetKernel;
use crate::paper::face::{to_face_frame, Face};
use crate::paper::grazing;
pub use crate::paper::{Component, ComponentSet, PaperBsdf};
use crate::params::{Colour, ParamError};
use crate::spectrum::Rgb;
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// Names of the models in parameter files and on the command line.
pub const MODEL_NAMES: [&str; 4] = ["paper", "reduced-multilayer", "lambert-glass", "rough-dielectric"];

/// A [`Bsdf`] whose components can be evaluated separately (for plots and fits).
pub trait ComponentModel: Bsdf {
    /// One component `f(wi, wo)` without cosine (zero for a component the model lacks).
    fn eval_component(&self, wi: DVec3, wo: DVec3, c: Component) -> Rgb;
    /// Whether the model's parameters were RGB (output gets `r,g,b` columns).
    fn is_rgb(&self) -> bool;
    /// The components this model has, in the order of [`Component::ALL`].
    fn components(&self) -> &'static [Component];
}

impl ComponentModel for PaperBsdf {
    fn eval_component(&self, wi: DVec3, wo: DVec3, c: Component) -> Rgb {
        PaperBsdf::eval_component(self, wi, wo, c)
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
                let e = if wi.z > 0.0 { 0 } else { 1 };
                out += Rgb::splat(self.face.reflection(to_face_frame(wi, e), to_face_frame(wo, e)));
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
        let total: f64 = est.iter().zip(&present).filter(|(_, p)| **p).map(|(e, _)| *e).sum();
        let mut w = [0.0; 4];
        for k in 0..4 {
            if present[k] {
                w[k] = est[k] + 0.02 * total;
            }
        }
        let sum: f64 = w.iter().sum();
        if sum.is_nan() || sum <= 0.0 {
            return [0.0; 4];
        }
        w.map(|v| v / sum)
    }

    fn pdf_with(&self, wi: DVec3, wo: DVec3, pr: &[f64; 4]) -> f64 {
        if grazing(wi) || grazing(wo) {
            return 0.0;
        }
        if wi.z * wo.z > 0.0 {
            let e = if wo.z > 0.0 { 0 } else { 1 };
            pr[0] * self.face.reflection_pdf(to_face_frame(wi, e), to_face_frame(wo, e)) + pr[1] * wi.z.abs() / PI
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
        let mut k = 0;
        let mut acc = 0.0;
        while k < 3 && uc >= acc + pr[k] {
            acc += pr[k];
            k += 1;
        }
        if pr[k] <= 0.0 {
            return None;
        }
        let so = wo.z.signum();
        let x = if wo.z > 0.0 { 0 } else { 1 };
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
                to_face_frame(self.face.sample_reflection(to_face_frame(wo, x), u)?, x)
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
}
