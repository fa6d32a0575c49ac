//! The slab's two faces as the random walk sees them, built from the physical
//! sheet of [`paperbsdf_core::sheet::Sheet`] (its module doc defines it).
//!
//! A face is one of three kinds, by what the walk can do with it:
//! - [`FaceOptics::Walter`]: a rough interface of Walter et al. (EGSR 2007)
//!   scattering once among its microfacets, without a coating: exact sampling,
//!   evaluation and density, so next-event estimation combines two strategies by
//!   multiple importance sampling (`crate::walk`).
//! - [`FaceOptics::Delta`]: a smooth or index-matched interface, with or
//!   without a front coating under it. With a coating the face is a film of two
//!   parallel smooth interfaces (air/coating of index `eta_f`, coating/base of
//!   relative index `eta_b / eta_f`) of zero thickness, whose incoherent sum of
//!   multiple reflections is `T = T1 T2 / (1 - R1 R2)`, `R = 1 - T` (Born & Wolf
//!   section 1.6 for each interface; `R1`, `R2` the Fresnel reflectances at the
//!   angles Snell's law gives in each medium, equal from either side).
//! - [`FaceOptics::Stochastic`]: a face the walk can sample exactly and
//!   evaluate only by an unbiased estimate: a rough interface that scatters any
//!   number of times among its microfacets (the random walk on the Smith
//!   microsurface of Heitz, Hanika, d'Eon and Dachsbacher, SIGGRAPH 2016, in
//!   `paperbsdf_core::microsurface`), and any rough front over a coating (the
//!   light bounces between the rough air/coating interface and the smooth
//!   coating/base interface until it leaves the coating, into the air or into
//!   the base). Next-event estimation through such a face uses one strategy
//!   at a time (no density is known for multiple importance sampling).
//!
//! Directions are in the face's local frame (`+z` toward the air on that
//! side), as for [`RoughDielectric`]. Inside the base a direction's projection
//! on the sheet is `sin(theta) / eta_b` of the outside direction with the same
//! projection, whatever the coating: that is what makes the sheet reciprocal.

use paperbsdf_core::fresnel::fresnel_dielectric;
use paperbsdf_core::geometry::refract;
use paperbsdf_core::params::FaceScattering;
use paperbsdf_core::{DVec3, RoughDielectric, TransportMode};

/// Sub-walk events inside a coating after which the light is given up (a
/// bound that an energy-conserving coating reaches with probability far below
/// 1e-12: every bounce leaves the coating with a probability of order `1 - R`).
const MAX_COAT_BOUNCES: u32 = 512;
/// Throughput below which Russian roulette is played inside a coating (estimates only).
const COAT_RR: f64 = 0.05;

/// How the walk treats one face (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FaceOptics {
    /// A single-scattering rough interface without a coating.
    Walter(RoughDielectric),
    /// A smooth or index-matched interface, or a smooth-topped coating (a film).
    Delta(DeltaFace),
    /// A multiple-scattering rough interface, or a rough interface over a coating.
    Stochastic(StochFace),
}

/// A delta face: a smooth or index-matched `top` interface, over a smooth
/// coating/base interface of relative index `coat` (base over coating) when `Some`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeltaFace {
    /// The air-side interface (smooth or index-matched).
    pub top: RoughDielectric,
    /// Relative index of the coating/base interface (base over coating), if there is a coating.
    pub coat: Option<f64>,
}

/// A face with a sampled and estimated BSDF: a rough `top` interface
/// scattering once or any number of times, over an optional coating.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StochFace {
    /// The air-side rough interface.
    pub top: RoughDielectric,
    /// Whether the top interface scatters any number of times among its microfacets.
    pub multiple: bool,
    /// Relative index of the coating/base interface (base over coating), if there is a coating.
    pub coat: Option<f64>,
}

/// One sampled event of a face: the direction the light (or, in radiance
/// transport, the camera path) leaves in, and the throughput `f |cos| / pdf`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceSample {
    /// Direction away from the face (local frame); `z > 0` is the air side.
    pub dir: DVec3,
    /// Throughput of the event (fraction of flux carried in importance transport).
    pub weight: f64,
    /// Whether the event was a delta event (mirror reflection or refraction by
    /// smooth interfaces only, e.g. the coating/base reflection of light from the base).
    pub delta: bool,
}

impl FaceOptics {
    /// The face for a rough interface `top` with the given microfacet
    /// scattering and coating (`coat`: base over coating index, for the front face).
    pub fn new(top: RoughDielectric, face_scattering: FaceScattering, coat: Option<f64>) -> FaceOptics {
        let delta = top.specular_lobes(DVec3::Z, TransportMode::Importance).is_some();
        if delta {
            FaceOptics::Delta(DeltaFace { top, coat })
        } else if coat.is_none() && face_scattering == FaceScattering::Single {
            FaceOptics::Walter(top)
        } else {
            FaceOptics::Stochastic(StochFace {
                top,
                multiple: face_scattering == FaceScattering::Multiple,
                coat,
            })
        }
    }

    /// The fraction of flux that the face reflects as a delta (mirror) lobe
    /// for light arriving from inside the base from `w_from` (local frame,
    /// `z < 0`, pointing toward where the light came from).
    pub fn delta_reflectance_inside(&self, w_from: DVec3) -> f64 {
        match self {
            FaceOptics::Walter(_) => 0.0,
            FaceOptics::Delta(d) => d.lobes(w_from, TransportMode::Importance).0,
            FaceOptics::Stochastic(s) => match s.coat {
                None => 0.0,
                Some(c) => fresnel_dielectric(w_from.z, c),
            },
        }
    }

    /// The face's air-side interface (the coating's top for a coated front).
    pub fn top(&self) -> &RoughDielectric {
        match self {
            FaceOptics::Walter(b) => b,
            FaceOptics::Delta(d) => &d.top,
            FaceOptics::Stochastic(s) => &s.top,
        }
    }
}

/// Fresnel reflectance and transmitted direction of the smooth coating/base
/// interface (relative index `c` = base over coating, normal `+z`, coating
/// above) for `w` pointing away from the interface on the incident side.
#[inline]
fn planar(w: DVec3, c: f64) -> (f64, Option<DVec3>) {
    let f = fresnel_dielectric(w.z, c);
    let eta_ti = if w.z > 0.0 { 1.0 / c } else { c };
    (f, if f < 1.0 { refract(w, DVec3::Z, eta_ti) } else { None })
}

impl DeltaFace {
    /// Delta-lobe factors seen from `wo` (either side, local frame):
    /// `(reflectance, transmittance, transmitted direction)` in the given mode,
    /// as [`RoughDielectric::specular_lobes`] (the transmittance includes the
    /// radiance factor `1 / eta_rel^2` in [`TransportMode::Radiance`], with
    /// `eta_rel` the index of the far side over that of `wo`'s side).
    pub fn lobes(&self, wo: DVec3, mode: TransportMode) -> (f64, f64, Option<DVec3>) {
        let Some(c) = self.coat else {
            return self.top.specular_lobes(wo, mode).unwrap_or((0.0, 0.0, None));
        };
        let eta_f = self.top.eta;
        let eta_b = c * eta_f;
        // Projection of the direction on the sheet, as in the air.
        let s2_air = (wo.x * wo.x + wo.y * wo.y) * if wo.z > 0.0 { 1.0 } else { eta_b * eta_b };
        if s2_air >= 1.0 || wo.z == 0.0 {
            return (1.0, 0.0, None); // total internal reflection from the base
        }
        let cos_air = (1.0 - s2_air).sqrt();
        let cos_coat = (1.0 - s2_air / (eta_f * eta_f)).sqrt();
        let r1 = fresnel_dielectric(cos_air, eta_f);
        let r2 = fresnel_dielectric(cos_coat, c);
        let t = (1.0 - r1) * (1.0 - r2) / (1.0 - r1 * r2);
        let (scale, dir) = if wo.z > 0.0 {
            let cb = (1.0 - s2_air / (eta_b * eta_b)).sqrt();
            (1.0 / (eta_b * eta_b), DVec3::new(-wo.x / eta_b, -wo.y / eta_b, -cb))
        } else {
            (eta_b * eta_b, DVec3::new(-wo.x * eta_b, -wo.y * eta_b, cos_air))
        };
        let t_mode = match mode {
            TransportMode::Radiance => t * scale,
            TransportMode::Importance => t,
        };
        (1.0 - t, t_mode, Some(dir.normalize()))
    }
}

impl StochFace {
    /// One event of the top interface from `w` (pointing away from it on the
    /// incident side) in the given mode: the exact Walter sampler, or one
    /// draw of the multiple-scattering microsurface walk.
    fn top_sample(&self, w: DVec3, mode: TransportMode, rnd: &mut impl FnMut() -> f64) -> Option<(DVec3, f64)> {
        if self.multiple {
            multiple::sample(&self.top, w, mode, rnd)
        } else {
            let (uc, u0, u1) = (rnd(), rnd(), rnd());
            let s = self.top.sample_mode(w, uc, [u0, u1], mode)?;
            Some((s.wi, s.weight().0[0]))
        }
    }

    /// The top interface's BSDF value (no cosine) or an unbiased estimate of it.
    fn top_eval(&self, wi: DVec3, wo: DVec3, mode: TransportMode, rnd: &mut impl FnMut() -> f64) -> f64 {
        if self.multiple {
            multiple::eval(&self.top, wi, wo, mode, rnd)
        } else {
            self.top.eval_mode(wi, wo, mode)
        }
    }

    /// Samples the face from `w` (either side, pointing away from the face
    /// toward where the light, or in radiance transport the viewer, is): an
    /// exact draw of the whole face, bounces inside the coating included.
    /// `None` when the draw produced no direction (its flux is lost: a
    /// single-scattering face's shadowing, or a failed draw).
    pub fn sample(&self, w: DVec3, mode: TransportMode, rnd: &mut impl FnMut() -> f64) -> Option<FaceSample> {
        let Some(c) = self.coat else {
            let (dir, weight) = self.top_sample(w, mode, rnd)?;
            return Some(FaceSample {
                dir,
                weight,
                delta: false,
            });
        };
        let mut weight = 1.0;
        // Radiance factor of a refraction from the coating into the base and back.
        let (into_base, into_coat) = match mode {
            TransportMode::Radiance => (1.0 / (c * c), c * c),
            TransportMode::Importance => (1.0, 1.0),
        };
        // `at_top`: where light meets the top (pointing away from it), from
        // outside (`w`) or from inside the coating after the first bounce.
        let mut at_top = if w.z > 0.0 {
            w
        } else {
            let (f, t) = planar(w, c);
            if rnd() < f {
                return Some(FaceSample {
                    dir: DVec3::new(-w.x, -w.y, w.z),
                    weight,
                    delta: true,
                });
            }
            let up = t?;
            weight *= into_coat;
            -up
        };
        // Light from outside meets the top once before its MAX_COAT_BOUNCES bounces.
        for _ in 0..MAX_COAT_BOUNCES + u32::from(w.z > 0.0) {
            let (d, wt) = self.top_sample(at_top, mode, rnd)?;
            weight *= wt;
            if d.z > 0.0 {
                return Some(FaceSample {
                    dir: d,
                    weight,
                    delta: false,
                });
            }
            // Down through the coating to the coating/base interface.
            match self.at_planar_from_coat(d, into_base, &mut weight, rnd) {
                Ok(done) => return Some(done),
                Err(up) => at_top = -up,
            }
        }
        None
    }

    /// Light propagating down the coating along `d` meets the coating/base
    /// interface: `Ok` with the refracted direction into the base, or `Err`
    /// with the reflected propagation direction (heading up again).
    fn at_planar_from_coat(
        &self,
        d: DVec3,
        into_base: f64,
        weight: &mut f64,
        rnd: &mut impl FnMut() -> f64,
    ) -> Result<FaceSample, DVec3> {
        let c = self.coat.unwrap_or(1.0);
        let (f, t) = planar(-d, c);
        match t {
            Some(t) if rnd() >= f => {
                *weight *= into_base;
                Ok(FaceSample {
                    dir: t,
                    weight: *weight,
                    delta: false,
                })
            }
            _ => Err(DVec3::new(d.x, d.y, -d.z)),
        }
    }

    /// An unbiased estimate of the face's BSDF value `f(wi, wo)` without cosine
    /// (delta lobes excluded) in the given mode. Without a coating it is the top
    /// interface's value (exact for single scattering). With a coating it is a
    /// path estimate from the viewer's end: a walk from `wo` through the
    /// coating (sampled top events, the coating/base reflections carried as
    /// their Fresnel factor), connected to `wi` by the top interface's value at
    /// every top event; light from the base reaches the top along its
    /// refracted direction with the factor `T2 = 1 - F` of the coating/base
    /// interface (the radiance factors of the two refractions cancel against
    /// the change of solid angle: `n^2 cos dw` is invariant).
    pub fn eval(&self, wi: DVec3, wo: DVec3, mode: TransportMode, rnd: &mut impl FnMut() -> f64) -> f64 {
        let Some(c) = self.coat else {
            return self.top_eval(wi, wo, mode, rnd);
        };
        if mode == TransportMode::Importance {
            // The adjoint (Veach 1997, section 5.2): f_imp(a, b) = f_rad(b, a).
            return self.eval(wo, wi, TransportMode::Radiance, rnd);
        }
        let rad = TransportMode::Radiance;
        // The light's end: its direction at the top, and the factor to get there.
        let (wi_top, l_factor) = if wi.z > 0.0 {
            (wi, 1.0)
        } else {
            let (f, t) = planar(wi, c);
            match t {
                Some(t) => (-t, 1.0 - f),
                None => return 0.0,
            }
        };
        // The viewer's end: the first top event's viewer direction and throughput.
        let mut beta;
        let mut v;
        let mut total = 0.0;
        if wo.z > 0.0 {
            v = wo;
            beta = 1.0;
        } else {
            let (f, t) = planar(wo, c);
            let Some(t) = t else { return 0.0 };
            v = -t;
            beta = (1.0 - f) * c * c;
        }
        for _ in 0..MAX_COAT_BOUNCES {
            // Connect to the light at this top event (a reflection when the
            // light and the viewer are on the same side of the top, else a transmission).
            total += beta * l_factor * self.top_eval(wi_top, v, rad, rnd);
            // Continue the viewer's path down into the coating.
            let Some((d, wt)) = self.top_sample(v, rad, rnd) else {
                break;
            };
            if d.z > 0.0 {
                break; // the viewer's path left into the air
            }
            beta *= wt * fresnel_dielectric(-d.z, c);
            // Russian roulette on the throughput.
            if beta < COAT_RR {
                let q = beta / COAT_RR;
                if rnd() >= q {
                    break;
                }
                beta /= q;
            }
            if !(beta > 0.0 && beta.is_finite()) {
                break;
            }
            v = DVec3::new(-d.x, -d.y, d.z); // reflected: heading up, viewer below
        }
        total
    }
}

/// The multiple-scattering microsurface walk (`paperbsdf_core::microsurface`).
mod multiple {
    use super::*;
    use paperbsdf_core::microsurface::{eval_multiple_estimate, sample_multiple};

    /// One draw of the walk: `(direction, weight)`.
    #[inline]
    pub(super) fn sample(
        b: &RoughDielectric,
        w: DVec3,
        mode: TransportMode,
        rnd: &mut impl FnMut() -> f64,
    ) -> Option<(DVec3, f64)> {
        sample_multiple(b, w, mode, rnd).map(|s| (s.wi, s.weight))
    }

    /// Unbiased estimate of the multiple-scattering BSDF value (no cosine).
    #[inline]
    pub(super) fn eval(
        b: &RoughDielectric,
        wi: DVec3,
        wo: DVec3,
        mode: TransportMode,
        rnd: &mut impl FnMut() -> f64,
    ) -> f64 {
        eval_multiple_estimate(b, wi, wo, mode, rnd)
    }
}
