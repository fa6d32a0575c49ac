//! The physical system the simulator walks through: a laterally infinite slab
//! of thickness `d` (front face `z = 0`, back face `z = -d`, DESIGN.md section 2)
//! filled with a homogeneous medium (`sigma_a`, `sigma_s`, the two-lobe
//! Henyey-Greenstein phase function of DESIGN.md 4.2) between two Walter rough
//! dielectric faces (DESIGN.md 4.1), with air (index 1) outside both.
//!
//! Each face is a [`RoughDielectric`] in its own local frame, whose `+z` is the
//! side of the air: for the front face that is the slab frame itself, for the
//! back face the slab frame with `z` flipped ([`Face::local`]). The BSDFs are
//! isotropic, so the mirror image is as good a frame as a rotation.

use paperbsdf_core::phase::TwoLobeHg;
use paperbsdf_core::{DVec3, PaperParams, ParamError, Rgb, RoughDielectric};

/// One of the slab's two faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Face {
    /// The front face, `z = 0`, air above (`z > 0`).
    Front,
    /// The back face, `z = -d`, air below (`z < 0`).
    Back,
}

impl Face {
    /// The other face.
    #[inline]
    pub fn other(self) -> Face {
        match self {
            Face::Front => Face::Back,
            Face::Back => Face::Front,
        }
    }
    /// Depth of the face for a slab of thickness `d`: `0` or `-d`.
    #[inline]
    pub fn z(self, d: f64) -> f64 {
        match self {
            Face::Front => 0.0,
            Face::Back => -d,
        }
    }
    /// A slab-frame vector in the face's local frame (`+z` toward the air on
    /// that side) and back: the map is its own inverse.
    #[inline]
    pub fn local(self, v: DVec3) -> DVec3 {
        match self {
            Face::Front => v,
            Face::Back => DVec3::new(v.x, v.y, -v.z),
        }
    }
    /// The face a propagation direction inside the slab heads for (`z > 0`:
    /// front), which is also the face through which a viewer direction `wo`
    /// sees the slab (`wo.z > 0`: front).
    #[inline]
    pub fn toward(dir: DVec3) -> Face {
        if dir.z > 0.0 {
            Face::Front
        } else {
            Face::Back
        }
    }
    /// The face at which light from direction `wi` (pointing toward the light) arrives.
    #[inline]
    pub fn lit_by(wi: DVec3) -> Face {
        Face::toward(wi)
    }
}

/// The medium of one colour channel: extinction and single-scattering albedo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    /// Extinction coefficient `sigma_t = sigma_a + sigma_s`, 1/mm.
    pub sigma_t: f64,
    /// Single-scattering albedo `sigma_s / sigma_t` (0 when `sigma_t = 0`).
    pub albedo: f64,
}

/// The physical paper slab of a [`PaperParams`]: the system the Paper BSDF approximates.
#[derive(Clone, Debug, PartialEq)]
pub struct Slab {
    /// Thickness, mm.
    pub d: f64,
    /// The front face (`z = 0`) in its local frame.
    pub front: RoughDielectric,
    /// The back face (`z = -d`) in its local frame (slab `z` flipped).
    pub back: RoughDielectric,
    /// Phase function of the medium.
    pub phase: TwoLobeHg,
    /// Absorption coefficient per channel, 1/mm.
    pub sigma_a: Rgb,
    /// Scattering coefficient per channel, 1/mm.
    pub sigma_s: Rgb,
    /// Whether the parameters were given in RGB (outputs then have three channels).
    pub rgb: bool,
}

impl Slab {
    /// The slab described by `p`, after checking every parameter's range
    /// (the error names the parameter, its value and the allowed range).
    pub fn from_params(p: &PaperParams) -> Result<Slab, ParamError> {
        p.validate()?;
        let front = RoughDielectric::new(p.dist_f, p.eta_f, p.m_f).map_err(|e| e.with_suffix("_f"))?;
        let back = RoughDielectric::new(p.dist_b, p.eta_b, p.m_b).map_err(|e| e.with_suffix("_b"))?;
        Ok(Slab {
            d: p.d,
            front,
            back,
            phase: TwoLobeHg {
                g_f: p.g_f,
                g_b: p.g_b,
                w_b: p.w_b,
            },
            sigma_a: p.sigma_a.rgb(),
            sigma_s: p.sigma_s.rgb(),
            rgb: p.is_rgb(),
        })
    }

    /// The BSDF of a face.
    #[inline]
    pub fn face(&self, f: Face) -> &RoughDielectric {
        match f {
            Face::Front => &self.front,
            Face::Back => &self.back,
        }
    }

    /// The medium of channel `c` (0, 1, 2).
    pub fn medium(&self, c: usize) -> Medium {
        let (sa, ss) = (self.sigma_a.0[c], self.sigma_s.0[c]);
        let sigma_t = sa + ss;
        Medium {
            sigma_t,
            albedo: if sigma_t > 0.0 { ss / sigma_t } else { 0.0 },
        }
    }

    /// The channels that need their own walk: for each channel, the index of
    /// the first channel with the same medium (scalar parameters need one walk).
    pub fn distinct_channels(&self) -> [usize; 3] {
        std::array::from_fn(|c| (0..c).find(|&k| self.medium(k) == self.medium(c)).unwrap_or(c))
    }
}
