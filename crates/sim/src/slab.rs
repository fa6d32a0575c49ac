//! The physical system the simulator walks through: the sheet of
//! [`paperbsdf_core::sheet::Sheet`] (its module doc defines it; docs/design.md
//! sections 2, 4.1 and 6): a laterally infinite slab of thickness `d` (front
//! face `z = 0`, back face `z = -d`) of a homogeneous medium of index `eta_b`
//! (`sigma_a`, `sigma_s`, the two-lobe Henyey-Greenstein phase function of
//! docs/design.md 4.2) between two rough dielectric faces, the front one over a thin
//! coating of index `eta_f` when `eta_f != eta_b`, with air (index 1) outside.
//!
//! Each face is a [`FaceOptics`] in its own local frame, whose `+z` is the
//! side of the air: for the front face that is the slab frame itself, for the
//! back face the slab frame with `z` flipped ([`Side::local`]). The BSDFs are
//! isotropic, so the mirror image is as good a frame as a rotation.

use crate::faces::FaceOptics;
pub use paperbsdf_core::paper::Side;
use paperbsdf_core::phase::TwoLobeHg;
use paperbsdf_core::sheet::Sheet;
use paperbsdf_core::{PaperParams, ParamError};

/// The medium of one colour channel: extinction and single-scattering albedo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    /// Extinction coefficient `sigma_t = sigma_a + sigma_s`, 1/mm.
    pub sigma_t: f64,
    /// Single-scattering albedo `sigma_s / sigma_t` (0 when `sigma_t = 0`).
    pub albedo: f64,
}

/// The physical paper sheet of a [`PaperParams`] as the walk sees it: the
/// system the Paper BSDF approximates, built from the one description of the
/// sheet that model and simulator share ([`Sheet`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Slab {
    /// The physical sheet (thickness, medium, faces, coating, face scattering).
    pub sheet: Sheet,
    /// The front face (`z = 0`) as the walk treats it, in its local frame.
    pub front: FaceOptics,
    /// The back face (`z = -d`) as the walk treats it, in its local frame (slab `z` flipped).
    pub back: FaceOptics,
    /// Thickness, mm (`sheet.d`).
    pub d: f64,
    /// Whether the parameters were given in RGB (outputs then have three channels).
    pub rgb: bool,
}

impl Slab {
    /// The slab described by `p`, after checking every parameter's range
    /// (the error names the parameter as in parameter files, its value and the allowed range).
    pub fn from_params(p: &PaperParams) -> Result<Slab, ParamError> {
        Slab::from_sheet(Sheet::from_params(p)?)
    }

    /// The slab of a sheet.
    pub fn from_sheet(sheet: Sheet) -> Result<Slab, ParamError> {
        let fs = sheet.face_scattering;
        let front = FaceOptics::new(sheet.front, fs, sheet.coating);
        let back = FaceOptics::new(sheet.back, fs, None);
        Ok(Slab {
            front,
            back,
            d: sheet.d,
            rgb: sheet.rgb,
            sheet,
        })
    }

    /// How the walk treats a face.
    #[inline]
    pub fn face(&self, f: Side) -> &FaceOptics {
        match f {
            Side::Front => &self.front,
            Side::Back => &self.back,
        }
    }

    /// The phase function of the medium.
    #[inline]
    pub fn phase(&self) -> TwoLobeHg {
        self.sheet.phase
    }

    /// The medium of channel `c` (0, 1, 2).
    pub fn medium(&self, c: usize) -> Medium {
        let (sa, ss) = (self.sheet.sigma_a.0[c], self.sheet.sigma_s.0[c]);
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
