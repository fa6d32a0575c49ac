//! One face of the slab as the Paper BSDF sees it (DESIGN.md 4.1): the rough
//! dielectric boundary in its own frame (its outside is `+z`), its tabulated
//! integrals (`Att`, outside reflectance, `rho_in`, `Tbar_in`), and helpers for
//! the smooth refraction through the macro normal that the single- and
//! multiple-scattering terms use (DESIGN.md 4.4).
//!
//! The back face (`z = -d`) is the same kind of object seen with `z` flipped:
//! [`to_face_frame`] maps a direction on the back side to the face's frame.

use crate::boundary::SurfaceIntegrals;
use crate::dielectric::{Interface, RoughDielectric};
use crate::fresnel::fresnel_dielectric;
use crate::microfacet::{Distribution, Microfacet};
use crate::params::ParamError;
use crate::quadrature::gauss_legendre_01;
use glam::DVec3;

/// The integrals of a boundary, in one place so that the switch to another
/// constructor (e.g. [`SurfaceIntegrals::direct`]) is one line.
fn surface_integrals(b: &RoughDielectric) -> SurfaceIntegrals {
    SurfaceIntegrals::new(b)
}

/// Mirrors `w` into the frame of the face on side `side` (0 front: identity; 1 back: `z -> -z`).
#[inline]
pub(crate) fn to_face_frame(w: DVec3, side: usize) -> DVec3 {
    if side == 0 {
        w
    } else {
        DVec3::new(w.x, w.y, -w.z)
    }
}

/// For `wi`, `wo` both above a face: `(h.z^2, wo.h)` of their unit half
/// vector `h = (wi + wo) / |wi + wo|`, without forming it: `|wi + wo|^2 =
/// 2 (1 + wi.wo)`, so `h.z^2 = (wi.z + wo.z)^2 / (2 (1 + wi.wo))` and
/// `wo.h = wi.h = sqrt((1 + wi.wo) / 2)` (both see the front of `h`). `None`
/// below the face or for opposite directions.
#[inline]
fn reflection_half(wi: DVec3, wo: DVec3) -> Option<(f64, f64)> {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return None;
    }
    let k = 1.0 + wi.dot(wo);
    if k <= 0.0 || !k.is_finite() {
        return None;
    }
    let zs = wi.z + wo.z;
    Some((zs * zs / (2.0 * k), (0.5 * k).sqrt().min(1.0)))
}

/// A face of the slab with its precomputed integrals.
#[derive(Clone, Debug)]
pub(crate) struct Face {
    /// The boundary, in the face's own frame (outside = `+z`).
    pub bd: RoughDielectric,
    /// Its integrals.
    pub si: SurfaceIntegrals,
    /// Whether `Att` is used; `false` sets every `Att` to 1 (the reduced multilayer model).
    pub use_att: bool,
    /// `Abar = 2 int_0^1 Att(mu) mu dmu` (1 when `use_att` is false).
    pub abar: f64,
    /// `Att` of a rough face at `mu = t^2`, `t` uniform on [`NA`] nodes (a
    /// cheaper copy of the boundary tables for the BSDF's inner loop).
    att_tab: [f64; NA],
    /// Outside reflectance of a rough face on the same nodes.
    r_tab: [f64; NA],
    /// `1 / eta` (the BSDF's inner loop multiplies rather than divides).
    inv_eta: f64,
    /// `1 / eta^2`.
    inv_eta2: f64,
}

/// Nodes of the per-face copies of `Att` and the outside reflectance.
const NA: usize = 65;

#[inline]
fn lerp_t(tab: &[f64; NA], mu: f64) -> f64 {
    lerp_sqrt(tab, mu.abs().min(1.0).sqrt())
}

/// [`lerp_t`] at `mu = st^2` for a precomputed `st = sqrt(min(|mu|, 1))`.
#[inline]
fn lerp_sqrt(tab: &[f64; NA], st: f64) -> f64 {
    let x = st * (NA - 1) as f64;
    let i = (x as usize).min(NA - 2);
    let f = x - i as f64;
    tab[i] * (1.0 - f) + tab[i + 1] * f
}

impl Face {
    /// The face `(dist, eta, m)`; errors name the parameters with `suffix` (`_f`, `_b`, or empty).
    pub fn new(dist: Distribution, eta: f64, m: f64, use_att: bool, suffix: &str) -> Result<Face, ParamError> {
        let bd = RoughDielectric::new(dist, eta, m).map_err(|e| e.with_suffix(suffix))?;
        let si = surface_integrals(&bd);
        let mut f = Face {
            bd,
            si,
            use_att,
            abar: 1.0,
            att_tab: [0.0; NA],
            r_tab: [0.0; NA],
            inv_eta: 1.0 / eta,
            inv_eta2: 1.0 / (eta * eta),
        };
        for k in 0..NA {
            let t = k as f64 / (NA - 1) as f64;
            f.att_tab[k] = f.si.att(t * t).clamp(0.0, 1.0);
            f.r_tab[k] = f.si.r_out(t * t).clamp(0.0, 1.0 - f.att_tab[k]);
        }
        if use_att {
            // mu = t^2 concentrates nodes near grazing where Att changes fastest.
            static GL: std::sync::OnceLock<(Vec<f64>, Vec<f64>)> = std::sync::OnceLock::new();
            let (x, w) = GL.get_or_init(|| gauss_legendre_01(24));
            f.abar = x
                .iter()
                .zip(w)
                .map(|(t, wt)| 2.0 * wt * f.att(t * t) * t * t * 2.0 * t)
                .sum();
        }
        Ok(f)
    }

    /// Relative index of the face.
    #[inline]
    pub fn eta(&self) -> f64 {
        self.bd.eta
    }

    /// `Att(mu)`: transmittance for light from outside at cosine `mu` (1 when `use_att` is false).
    #[inline]
    pub fn att(&self, mu: f64) -> f64 {
        if !self.use_att {
            return 1.0;
        }
        match self.bd.interface {
            Interface::IndexMatched => 1.0,
            Interface::Smooth => 1.0 - fresnel_dielectric(mu.abs(), self.bd.eta),
            Interface::Rough(_) => lerp_t(&self.att_tab, mu),
        }
    }

    /// [`Face::att`] at `mu` given also `st = sqrt(min(|mu|, 1))` (saves the
    /// square root when the caller has it already).
    #[inline]
    pub fn att_with_sqrt(&self, mu: f64, st: f64) -> f64 {
        if !self.use_att {
            return 1.0;
        }
        match self.bd.interface {
            Interface::IndexMatched => 1.0,
            Interface::Smooth => 1.0 - fresnel_dielectric(mu.abs(), self.bd.eta),
            Interface::Rough(_) => lerp_sqrt(&self.att_tab, st),
        }
    }

    /// [`Face::r_out`] given also `st = sqrt(min(|mu|, 1))`.
    #[inline]
    pub fn r_out_with_sqrt(&self, mu: f64, st: f64) -> f64 {
        match self.bd.interface {
            Interface::IndexMatched => 0.0,
            Interface::Smooth => fresnel_dielectric(mu.abs(), self.bd.eta),
            Interface::Rough(_) => lerp_sqrt(&self.r_tab, st),
        }
    }

    /// Directional reflectance for light from outside at cosine `mu` (the surface
    /// reflection's albedo; used as a sampling weight).
    #[inline]
    pub fn r_out(&self, mu: f64) -> f64 {
        match self.bd.interface {
            Interface::IndexMatched => 0.0,
            Interface::Smooth => fresnel_dielectric(mu.abs(), self.bd.eta),
            Interface::Rough(_) => lerp_t(&self.r_tab, mu),
        }
    }

    /// `rho_in`: hemispherical reflectance for diffuse light from inside.
    #[inline]
    pub fn rho_in(&self) -> f64 {
        self.si.rho_in
    }

    /// [`fresnel_dielectric`] for light from outside at cosine `c` in `(0, 1]`
    /// (`eta >= 1`: no total internal reflection), with the face's `1 / eta^2`
    /// in place of a division.
    #[inline]
    pub fn fresnel_outside(&self, c: f64) -> f64 {
        if self.bd.eta == 1.0 {
            return 0.0;
        }
        let cos_t = (1.0 - (1.0 - c * c) * self.inv_eta2).max(0.0).sqrt();
        crate::fresnel::fresnel_from_cosines(c, cos_t, self.bd.eta)
    }

    /// `1 / eta`.
    #[inline]
    pub fn inv_eta(&self) -> f64 {
        self.inv_eta
    }

    /// `1 / eta^2`: the change of radiance on leaving through this face.
    #[inline]
    pub fn inv_eta2(&self) -> f64 {
        self.inv_eta2
    }

    /// Cosine (magnitude) inside of the smooth refraction of an outside direction with cosine `mu`.
    #[inline]
    pub fn inside_cos(&self, mu: f64) -> f64 {
        (1.0 - (1.0 - mu * mu) * self.inv_eta2).max(0.0).sqrt()
    }

    /// The microfacet distribution, if rough.
    #[inline]
    pub fn microfacet(&self) -> Option<Microfacet> {
        match self.bd.interface {
            Interface::Rough(mf) => Some(mf),
            _ => None,
        }
    }

    /// Whether the face reflects as a delta (smooth, not index-matched).
    #[inline]
    pub fn is_smooth(&self) -> bool {
        matches!(self.bd.interface, Interface::Smooth)
    }

    /// Whether there is no interface at all.
    #[inline]
    pub fn is_index_matched(&self) -> bool {
        matches!(self.bd.interface, Interface::IndexMatched)
    }

    /// Walter reflection `f_r(wi, wo)` (no cosine) of the face, both directions in
    /// the face frame on the outside (`z > 0`); zero for a smooth or index-matched face.
    #[inline]
    pub fn reflection(&self, wi: DVec3, wo: DVec3) -> f64 {
        let Interface::Rough(mf) = self.bd.interface else {
            return 0.0;
        };
        let Some((c2, oh)) = reflection_half(wi, wo) else {
            return 0.0;
        };
        self.fresnel_outside(oh) * mf.reflection_dg_c2(c2, wi.z, wo.z)
    }

    /// Density of [`Face::sample_reflection`]: `pdf_visible(wo, h) / (4 |wo.h|)`.
    #[inline]
    pub fn reflection_pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        let Some(mf) = self.microfacet() else { return 0.0 };
        let Some((c2, _)) = reflection_half(wi, wo) else {
            return 0.0;
        };
        mf.reflection_dg_pdf_c2(c2, wi.z, wo.z).1
    }

    /// `(f_r, pdf)`: [`Face::reflection`] and [`Face::reflection_pdf`] at once,
    /// sharing `D(h)` and the masking of `wo` (for `sample`, which needs both).
    #[inline]
    pub fn reflection_and_pdf(&self, wi: DVec3, wo: DVec3) -> (f64, f64) {
        let Interface::Rough(mf) = self.bd.interface else {
            return (0.0, 0.0);
        };
        let Some((c2, oh)) = reflection_half(wi, wo) else {
            return (0.0, 0.0);
        };
        let (dg, pdf) = mf.reflection_dg_pdf_c2(c2, wi.z, wo.z);
        (self.fresnel_outside(oh) * dg, pdf)
    }

    /// Draws a reflected `wi` (face frame) from the visible normals seen from `wo`.
    #[inline]
    pub fn sample_reflection(&self, wo: DVec3, u: [f64; 2]) -> Option<DVec3> {
        let mf = self.microfacet()?;
        let h = mf.sample_visible(wo, u);
        let oh = wo.dot(h);
        if oh <= 0.0 {
            return None;
        }
        let wi = 2.0 * oh * h - wo;
        (wi.z > 0.0).then(|| wi.normalize())
    }
}
