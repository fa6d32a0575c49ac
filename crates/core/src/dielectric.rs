//! The rough dielectric interface of Walter, Marschner, Li and Torrance (EGSR 2007).
//!
//! Reflection and refraction by a microfacet interface between the exterior
//! (index 1, `z > 0`) and the interior (relative index `eta`, `z < 0`), for light
//! arriving from either side, with exact unpolarised Fresnel and separable Smith
//! shadowing. Sampling draws visible normals (Heitz & d'Eon 2014) from the
//! viewer's side and picks reflection with probability `F`, as Mitsuba 3's
//! `roughdielectric` does.
//!
//! Values are radiance transport by default (Mitsuba's `TransportMode::Radiance`):
//! refraction into the viewer's medium scales radiance by
//! `(n_viewer / n_light)^2`. The generalised reciprocity that holds is
//! `f(wi, wo) / n_o^2 = f(wo, wi) / n_i^2` with `n` the index of each
//! direction's side.
//!
//! `m = 0` is a smooth interface: delta reflection and refraction, handled
//! explicitly; `eta = 1` is an index-matched face, i.e. no interface at all
//! (light passes straight through, whatever `m`).

use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, TransportMode};
use crate::fresnel::fresnel_dielectric;
use crate::geometry::{reflect, refract};
use crate::microfacet::{upper_unit, Distribution, Microfacet};
use crate::params::ParamError;
use crate::spectrum::Rgb;
use glam::DVec3;

/// What kind of interface a [`RoughDielectric`] is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Interface {
    /// `eta = 1`: no interface; light passes straight through.
    IndexMatched,
    /// `m = 0`: a smooth (mirror and Snell) interface.
    Smooth,
    /// `m > 0`: a microfacet interface.
    Rough(Microfacet),
}

/// A rough dielectric boundary: relative index `eta` (interior over exterior),
/// roughness `m` (microfacet alpha) and distribution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    /// Relative index of refraction, interior (`z < 0`) over exterior; in [1, 5].
    pub eta: f64,
    /// Microfacet roughness alpha; 0 is smooth; in [0, pi/2].
    pub m: f64,
    /// Microfacet distribution.
    pub dist: Distribution,
    /// The resolved interface kind.
    pub interface: Interface,
}

/// Allowed range of `eta` (docs/design.md section 3).
pub const ETA_RANGE: (f64, f64) = (1.0, 5.0);
/// Allowed range of `m` (docs/design.md section 3).
pub const M_RANGE: (f64, f64) = (0.0, std::f64::consts::FRAC_PI_2);

/// Roughness below which an interface is smooth (the limit `m -> 0`). A
/// microfacet lobe this narrow differs from the delta lobes only at order `m^2`
/// (below 1e-8 in any albedo), while its `D ~ 1 / (pi m^2)` and the slopes of
/// its visible normals lose precision and overflow for much smaller `m`
/// (`m = 1e-9` gave inf/NaN). The parameter keeps its value; only the
/// resolved [`Interface`] changes.
pub const M_SMOOTH: f64 = 1e-4;

impl RoughDielectric {
    /// A boundary with the given parameters; an error names any value outside
    /// docs/design.md's ranges (`eta` in [1, 5], `m` in [0, pi/2]).
    pub fn new(dist: Distribution, eta: f64, m: f64) -> Result<Self, ParamError> {
        ParamError::check_range("eta", eta, ETA_RANGE.0, ETA_RANGE.1)?;
        ParamError::check_range("m", m, M_RANGE.0, M_RANGE.1)?;
        let interface = if eta == 1.0 {
            Interface::IndexMatched
        } else if m < M_SMOOTH {
            Interface::Smooth
        } else {
            Interface::Rough(Microfacet::new(dist, m))
        };
        Ok(RoughDielectric {
            eta,
            m,
            dist,
            interface,
        })
    }

    /// `eta_rel` = index of the side opposite `w` over the index of `w`'s side.
    #[inline]
    fn eta_rel(&self, w: DVec3) -> f64 {
        if w.z > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        }
    }

    /// `f(wi, wo)` without cosine in the given transport mode (delta lobes excluded).
    pub fn eval_mode(&self, wi: DVec3, wo: DVec3, mode: TransportMode) -> f64 {
        self.eval_with_masking(wi, wo, mode, |mf| (mf.g1_cos(wi.z), mf.g1_cos(wo.z)))
    }

    /// The Smith masking of a direction with cosine `c` that sees the front
    /// of the micro-normal, as [`RoughDielectric::eval_mode`] has it
    /// ([`Microfacet::g1_cos`] of the face's microfacets; 0 for a face
    /// without them, whose `eval_mode` is 0).
    #[inline]
    pub fn g1_cos(&self, c: f64) -> f64 {
        match self.interface {
            Interface::Rough(mf) => mf.g1_cos(c),
            _ => 0.0,
        }
    }

    /// [`RoughDielectric::eval_mode`] with the masking of the two
    /// directions given: `g1_wi` and `g1_wo` must be
    /// [`RoughDielectric::g1_cos`] of `wi.z` and `wo.z` (it depends on the
    /// cosine alone; whether a direction sees the front of the micro-normal
    /// is checked here). For
    /// a caller that evaluates the face at many azimuths of the same two
    /// cosines (`paperbsdf_slab`'s projection of the face on its grids):
    /// the masking is then computed once per cosine instead of twice per
    /// evaluation. Equal to `eval_mode` to the bit (unit test
    /// `eval_with_given_masking_is_eval_mode`).
    #[inline]
    pub fn eval_mode_masked(&self, wi: DVec3, wo: DVec3, mode: TransportMode, g1_wi: f64, g1_wo: f64) -> f64 {
        self.eval_with_masking(wi, wo, mode, |_| (g1_wi, g1_wo))
    }

    /// The body of [`RoughDielectric::eval_mode`], the masking magnitudes of
    /// `(wi, wo)` from `masking` (called only where `D > 0`).
    #[inline(always)]
    fn eval_with_masking(
        &self,
        wi: DVec3,
        wo: DVec3,
        mode: TransportMode,
        masking: impl FnOnce(&Microfacet) -> (f64, f64),
    ) -> f64 {
        let mf = match self.interface {
            Interface::Rough(mf) => mf,
            _ => return 0.0,
        };
        let (v, l) = (wo, wi);
        let (cv, cl) = (v.z, l.z);
        if cv == 0.0 || cl == 0.0 {
            return 0.0;
        }
        let is_reflect = cv * cl > 0.0;
        let eta_rel = self.eta_rel(v);
        let Some(h) = upper_unit(if is_reflect { v + l } else { v + l * eta_rel }) else {
            return 0.0;
        };
        let d = mf.d(h);
        if d == 0.0 {
            return 0.0;
        }
        let (vh, lh) = (v.dot(h), l.dot(h));
        // Smith's G: each direction must see the front of the micro-normal
        // (`Microfacet::g1`).
        if vh * cv <= 0.0 || lh * cl <= 0.0 {
            return 0.0;
        }
        let (g_l, g_v) = masking(&mf);
        let g = g_l * g_v;
        if g == 0.0 {
            return 0.0;
        }
        let f = fresnel_dielectric(vh, self.eta);
        if is_reflect {
            f * d * g / (4.0 * (cv * cl).abs())
        } else {
            let denom = vh + eta_rel * lh;
            if denom == 0.0 {
                return 0.0;
            }
            let mut val = (1.0 - f) * d * g * (vh * lh).abs() / ((cv * cl).abs() * denom * denom);
            if mode == TransportMode::Importance {
                val *= eta_rel * eta_rel;
            }
            val
        }
    }

    /// Solid-angle density with which [`RoughDielectric::sample_mode`] draws `wi` given `wo`.
    pub fn pdf_dir(&self, wi: DVec3, wo: DVec3) -> f64 {
        let mf = match self.interface {
            Interface::Rough(mf) => mf,
            _ => return 0.0,
        };
        let (v, l) = (wo, wi);
        if v.z == 0.0 || l.z == 0.0 {
            return 0.0;
        }
        let is_reflect = v.z * l.z > 0.0;
        let eta_rel = self.eta_rel(v);
        let Some(h) = upper_unit(if is_reflect { v + l } else { v + l * eta_rel }) else {
            return 0.0;
        };
        let (vh, lh) = (v.dot(h), l.dot(h));
        // The microfacet must face both directions from their own sides.
        if vh * v.z <= 0.0 || lh * l.z <= 0.0 {
            return 0.0;
        }
        let pdf_h = mf.pdf_visible(v, h);
        if pdf_h == 0.0 {
            return 0.0;
        }
        let f = fresnel_dielectric(vh, self.eta);
        if is_reflect {
            pdf_h * f / (4.0 * lh.abs())
        } else {
            let denom = vh + eta_rel * lh;
            if denom == 0.0 {
                return 0.0;
            }
            pdf_h * (1.0 - f) * eta_rel * eta_rel * lh.abs() / (denom * denom)
        }
    }

    /// Draws `wi` for the viewer direction `wo` (either side) in the given
    /// transport mode. In [`TransportMode::Importance`], call it with `wo` = the
    /// direction the light came from (pointing away from the surface): the
    /// returned `wi` is then the direction the light leaves in, and
    /// [`BsdfSample::weight`] the fraction of flux it carries.
    pub fn sample_mode(&self, wo: DVec3, uc: f64, u: [f64; 2], mode: TransportMode) -> Option<BsdfSample> {
        let v = wo;
        if v.z == 0.0 {
            return None;
        }
        let eta_rel = self.eta_rel(v);
        // Radiance scaling for refraction into the viewer's medium.
        let t_scale = match mode {
            TransportMode::Radiance => 1.0 / (eta_rel * eta_rel),
            TransportMode::Importance => 1.0,
        };
        match self.interface {
            Interface::IndexMatched => Some(BsdfSample {
                wi: -v,
                f: Rgb::splat(1.0 / v.z.abs()),
                pdf: 1.0,
                flags: BsdfFlags::TRANSMISSION | BsdfFlags::SPECULAR,
            }),
            Interface::Smooth => {
                let f = fresnel_dielectric(v.z, self.eta);
                if uc < f {
                    let wi = DVec3::new(-v.x, -v.y, v.z);
                    Some(BsdfSample {
                        wi,
                        f: Rgb::splat(f / wi.z.abs()),
                        pdf: f,
                        flags: BsdfFlags::REFLECTION | BsdfFlags::SPECULAR,
                    })
                } else {
                    let n = DVec3::Z;
                    let wi = refract(v, n, 1.0 / eta_rel)?;
                    Some(BsdfSample {
                        wi,
                        f: Rgb::splat((1.0 - f) * t_scale / wi.z.abs()),
                        pdf: 1.0 - f,
                        flags: BsdfFlags::TRANSMISSION | BsdfFlags::SPECULAR,
                    })
                }
            }
            Interface::Rough(mf) => {
                let h = mf.sample_visible(v, u);
                let vh = v.dot(h);
                if vh * v.z <= 0.0 {
                    return None;
                }
                let f = fresnel_dielectric(vh, self.eta);
                let (wi, flags) = if uc < f {
                    let wi = reflect(v, h);
                    if wi.z * v.z <= 0.0 {
                        return None;
                    }
                    (wi, BsdfFlags::REFLECTION | BsdfFlags::GLOSSY)
                } else {
                    let wi = refract(v, h, 1.0 / eta_rel)?;
                    if wi.z * v.z >= 0.0 {
                        return None;
                    }
                    (wi, BsdfFlags::TRANSMISSION | BsdfFlags::GLOSSY)
                };
                let pdf = self.pdf_dir(wi, v);
                if pdf <= 0.0 || !pdf.is_finite() {
                    return None;
                }
                let val = self.eval_mode(wi, v, mode);
                Some(BsdfSample {
                    wi,
                    f: Rgb::splat(val),
                    pdf,
                    flags,
                })
            }
        }
    }

    /// Delta-lobe throughput factors for a smooth or index-matched interface
    /// seen from `wo`: `(reflectance, transmittance, transmitted direction)` in
    /// the given mode. `None` for a rough interface.
    pub fn specular_lobes(&self, wo: DVec3, mode: TransportMode) -> Option<(f64, f64, Option<DVec3>)> {
        let eta_rel = self.eta_rel(wo);
        match self.interface {
            Interface::IndexMatched => Some((0.0, 1.0, Some(-wo))),
            Interface::Smooth => {
                let f = fresnel_dielectric(wo.z, self.eta);
                let t_scale = match mode {
                    TransportMode::Radiance => 1.0 / (eta_rel * eta_rel),
                    TransportMode::Importance => 1.0,
                };
                Some((f, (1.0 - f) * t_scale, refract(wo, DVec3::Z, 1.0 / eta_rel)))
            }
            Interface::Rough(_) => None,
        }
    }
}

impl Bsdf for RoughDielectric {
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        Rgb::splat(self.eval_mode(wi, wo, TransportMode::Radiance))
    }
    fn sample(&self, wo: DVec3, uc: f64, u: [f64; 2]) -> Option<BsdfSample> {
        self.sample_mode(wo, uc, u, TransportMode::Radiance)
    }
    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        self.pdf_dir(wi, wo)
    }
    fn flags(&self) -> BsdfFlags {
        match self.interface {
            Interface::IndexMatched => BsdfFlags::TRANSMISSION | BsdfFlags::SPECULAR,
            Interface::Smooth => BsdfFlags::REFLECTION | BsdfFlags::TRANSMISSION | BsdfFlags::SPECULAR,
            Interface::Rough(_) => BsdfFlags::REFLECTION | BsdfFlags::TRANSMISSION | BsdfFlags::GLOSSY,
        }
    }
}

/// Parameters of the `rough-dielectric` model as written in a parameter file:
/// `eta` in [1, 5], `m` in [0, pi/2], `dist` (`"ggx"` or `"beckmann"`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoughDielectricParams {
    /// Optional label.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Relative index of refraction, interior over exterior.
    pub eta: f64,
    /// Roughness (microfacet alpha); 0 is smooth.
    pub m: f64,
    /// Microfacet distribution.
    pub dist: Distribution,
}

impl RoughDielectricParams {
    /// The boundary these parameters describe (validating them).
    pub fn build(&self) -> Result<RoughDielectric, ParamError> {
        RoughDielectric::new(self.dist, self.eta, self.m)
    }
}
