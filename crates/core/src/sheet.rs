//! The physical sheet that both the Paper BSDF (`crate::paper`) and the
//! ground-truth simulator (crate `paperbsdf-sim`) describe, decoded once from
//! [`PaperParams`] (docs/design.md sections 3, 4.1 and 6).
//!
//! **What the parameters stand for.** A laterally infinite slab of thickness
//! `d` (front face `z = 0`, back face `z = -d`) of a homogeneous medium
//! (`sigma_a`, `sigma_s`, the two-lobe Henyey-Greenstein phase function) with
//! air (index 1) on both sides. The medium (the *base*) has index `eta_b`.
//!
//! - The back face is a rough interface between the base and the air below:
//!   relative index `eta_b`, roughness `m_b`, distribution `dist_b`.
//! - The front face is a rough interface between the air above and a thin,
//!   non-scattering, non-absorbing *coating* of index `eta_f` (roughness `m_f`,
//!   distribution `dist_f`). When `eta_f != eta_b` the coating meets the base
//!   through a smooth (planar) interface of relative index `eta_b / eta_f`
//!   (seen from the coating), so light crossing the front also crosses that
//!   boundary, with its Fresnel reflection and, where `eta_b < eta_f`, total
//!   internal reflection in the coating. The coating's thickness is taken as
//!   zero (no lateral shift, no absorption). When `eta_f == eta_b` there is no
//!   coating: the front face is a rough interface between air and the base, as
//!   in the paper.
//!
//! This makes every sheet a physical object: inside the base, a direction's
//! projection on the sheet is `sin(theta) / eta_b` on both sides, so light
//! that crosses unscattered leaves parallel to the way it came in and the
//! sheet is reciprocal whatever its faces (a sheet with a different index
//! behind each rough face would act as a prism). An `eta_f = 1` front is an
//! index-matched rough interface over a smooth air/base boundary, i.e. a
//! smooth front of index `eta_b`.
//!
//! Each face is a [`RoughDielectric`] in its own local frame, whose `+z` is
//! the side of the air: the slab frame itself for the front face, the slab
//! frame with `z` flipped for the back face. The faces scatter once among
//! their microfacets (Walter et al. 2007) or any number of times (Heitz et
//! al. 2016), as [`FaceScattering`] says.

use crate::dielectric::RoughDielectric;
use crate::params::{FaceScattering, PaperParams, ParamError};
use crate::phase::TwoLobeHg;
use crate::spectrum::Rgb;

/// The physical sheet of a [`PaperParams`] (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct Sheet {
    /// Thickness, mm.
    pub d: f64,
    /// Absorption coefficient per channel, 1/mm.
    pub sigma_a: Rgb,
    /// Scattering coefficient per channel, 1/mm.
    pub sigma_s: Rgb,
    /// Phase function of the medium.
    pub phase: TwoLobeHg,
    /// The front face's rough interface (air above, coating or base below), in its local frame.
    pub front: RoughDielectric,
    /// The back face's rough interface (base above, air below), in its local frame (slab `z` flipped).
    pub back: RoughDielectric,
    /// Index of the base medium (`eta_b`).
    pub eta_medium: f64,
    /// The front coating's smooth boundary with the base, as the relative
    /// index `eta_b / eta_f` seen from the coating; `None` when `eta_f == eta_b`.
    pub coating: Option<f64>,
    /// Single- or multiple-scattering microfacet faces.
    pub face_scattering: FaceScattering,
    /// Whether the parameters were given in RGB (outputs then have three channels).
    pub rgb: bool,
}

impl Sheet {
    /// The sheet described by `p`, after checking every parameter's range
    /// (the error names the parameter as in parameter files, its value and the allowed range).
    pub fn from_params(p: &PaperParams) -> Result<Sheet, ParamError> {
        p.validate()?;
        let front = RoughDielectric::new(p.dist_f, p.eta_f, p.m_f).map_err(|e| e.with_suffix("_f"))?;
        let back = RoughDielectric::new(p.dist_b, p.eta_b, p.m_b).map_err(|e| e.with_suffix("_b"))?;
        Ok(Sheet {
            d: p.d,
            sigma_a: p.sigma_a.rgb(),
            sigma_s: p.sigma_s.rgb(),
            phase: TwoLobeHg {
                g_f: p.g_f,
                g_b: p.g_b,
                w_b: p.w_b,
            },
            front,
            back,
            eta_medium: p.eta_b,
            coating: (p.eta_f != p.eta_b).then(|| p.eta_b / p.eta_f),
            face_scattering: p.face_scattering,
            rgb: p.is_rgb(),
        })
    }

    /// The rough interface of the front (`back = false`) or back face.
    #[inline]
    pub fn face(&self, back: bool) -> &RoughDielectric {
        if back {
            &self.back
        } else {
            &self.front
        }
    }

    /// Extinction coefficient `sigma_a + sigma_s` per channel, 1/mm.
    pub fn sigma_t(&self) -> Rgb {
        self.sigma_a + self.sigma_s
    }
}
