//! Materials: what a surface does with light at a hit point.
//!
//! Every material resolves, per hit, to a [`paperbsdf_core::Bsdf`] in the local
//! frame whose `+z` is the shading normal (the front of a paper sheet), so the
//! integrator sees one interface for the Lambertian, rough dielectric (Walter et
//! al. 2007, `paperbsdf_core::RoughDielectric`), Paper (Papas et al. 2014) and
//! measured (an RGL `.bsdf` file, `paperbsdf_io::MeasuredBsdf`: front-side
//! reflection only) BSDFs.
//!
//! Paper maps: a thickness map scales `d` (a watermark is thinner paper) and
//! an ink map adds absorption `sigma_a` (print). Building a Paper BSDF is not
//! free, so map values are quantised to a small number of levels whose BSDFs are
//! built once, lazily, and shared; the level is chosen stochastically between the
//! two nearest ones with the fractional part as probability, so the average over
//! samples is the linear interpolation of the two BSDFs (no banding).

use crate::texture::{ColourTexture, GreyTexture};
use paperbsdf_core::{Bsdf, BsdfFlags, BsdfSample, Colour, DVec3, PaperParams, Rgb};
use std::sync::{Arc, OnceLock};

/// A two-sided Lambertian reflector: `f = R / pi` when `wi` and `wo` are on the same side.
#[derive(Clone, Copy, Debug)]
pub struct Lambert {
    /// Reflectance `R` per channel, in [0, 1].
    pub r: Rgb,
}

impl Bsdf for Lambert {
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z * wo.z > 0.0 {
            self.r * std::f64::consts::FRAC_1_PI
        } else {
            Rgb::ZERO
        }
    }
    fn sample(&self, wo: DVec3, _uc: f64, u: [f64; 2]) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let mut wi = paperbsdf_core::geometry::sample_cosine_hemisphere(u);
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = wi.z * std::f64::consts::FRAC_1_PI;
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        Some(BsdfSample {
            wi,
            f: self.r * std::f64::consts::FRAC_1_PI,
            pdf,
            flags: BsdfFlags::REFLECTION | BsdfFlags::DIFFUSE,
        })
    }
    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z * wo.z > 0.0 {
            wi.z.abs() * std::f64::consts::FRAC_1_PI
        } else {
            0.0
        }
    }
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::REFLECTION | BsdfFlags::DIFFUSE
    }
}

/// The BSDF of one hit: a small value or a shared prebuilt model.
pub enum HitBsdf<'a> {
    /// A Lambertian reflector with the reflectance at the hit.
    Lambert(Lambert),
    /// A prebuilt BSDF.
    Shared(&'a dyn Bsdf),
}

impl HitBsdf<'_> {
    /// The BSDF behind this value.
    #[inline]
    pub fn get(&self) -> &dyn Bsdf {
        match self {
            HitBsdf::Lambert(l) => l,
            HitBsdf::Shared(b) => *b,
        }
    }
}

/// Builds a sheet's BSDF from parameters: the core model or the model
/// `slab` with its discretisation ([`crate::paper_model`]).
pub type PaperFactory = Arc<dyn Fn(&PaperParams) -> Result<Arc<dyn Bsdf>, paperbsdf_core::ParamError> + Send + Sync>;

/// A greyscale map that scales the sheet's thickness: `d(uv) = d (min + (1 - min) grey(uv))`.
#[derive(Clone, Debug)]
pub struct ThicknessMap {
    /// The map (white = full thickness).
    pub map: GreyTexture,
    /// Thickness factor where the map is black, in (0, 1].
    pub min: f64,
}

/// A greyscale map of printed ink: `sigma_a(uv) = sigma_a + ink (1 - grey(uv))` (black = full ink).
#[derive(Clone, Debug)]
pub struct InkMap {
    /// The map (black = ink).
    pub map: GreyTexture,
    /// Absorption added by full ink, 1/mm.
    pub sigma_a: Rgb,
}

/// Number of quantisation levels of a thickness or ink map.
pub const MAP_LEVELS: usize = 17;

/// A paper sheet: the Paper BSDF with optional thickness and ink maps.
pub struct PaperMaterial {
    /// Parameters where the maps are white (full thickness, no ink).
    pub base: PaperParams,
    /// Optional thickness map.
    pub thickness: Option<ThicknessMap>,
    /// Optional ink map.
    pub ink: Option<InkMap>,
    factory: PaperFactory,
    cache: Vec<OnceLock<Arc<dyn Bsdf>>>,
}

impl PaperMaterial {
    /// A paper material; builds (and so validates) the BSDFs at the extreme map values now.
    pub fn new(
        base: PaperParams,
        thickness: Option<ThicknessMap>,
        ink: Option<InkMap>,
        factory: PaperFactory,
    ) -> Result<Self, paperbsdf_core::ParamError> {
        let nt = if thickness.is_some() { MAP_LEVELS } else { 1 };
        let ni = if ink.is_some() { MAP_LEVELS } else { 1 };
        let m = PaperMaterial {
            base,
            thickness,
            ink,
            factory,
            cache: (0..nt * ni).map(|_| OnceLock::new()).collect(),
        };
        for (it, ii) in [(0, 0), (nt - 1, ni - 1), (0, ni - 1), (nt - 1, 0)] {
            let b = (m.factory)(&m.params_at(it, ii))?;
            let _ = m.cache[it * ni + ii].set(b);
        }
        Ok(m)
    }

    fn levels(&self) -> (usize, usize) {
        (
            if self.thickness.is_some() { MAP_LEVELS } else { 1 },
            if self.ink.is_some() { MAP_LEVELS } else { 1 },
        )
    }

    /// Parameters at thickness level `it` and ink level `ii` (level / (MAP_LEVELS - 1) = map grey value).
    pub fn params_at(&self, it: usize, ii: usize) -> PaperParams {
        let mut p = self.base.clone();
        let last = (MAP_LEVELS - 1) as f64;
        if let Some(t) = &self.thickness {
            let g = it as f64 / last;
            p.d = self.base.d * (t.min + (1.0 - t.min) * g);
        }
        if let Some(k) = &self.ink {
            let g = ii as f64 / last;
            let s = self.base.sigma_a.rgb() + k.sigma_a * (1.0 - g);
            p.sigma_a = Colour::Rgb(s.0);
        }
        p
    }

    /// The BSDF at `(u, v)`; `xi` in [0, 1) picks between neighbouring levels.
    pub fn bsdf_at(&self, u: f64, v: f64, xi: f64) -> &dyn Bsdf {
        let (nt, ni) = self.levels();
        let mut xi = xi;
        let mut level = |map: &GreyTexture| -> usize {
            let x = map.eval(u, v).clamp(0.0, 1.0) * (MAP_LEVELS - 1) as f64;
            let lo = x.floor();
            let frac = x - lo;
            // Reuse the random number: split [0,1) at frac.
            let up = xi < frac;
            xi = if up {
                xi / frac.max(1e-300)
            } else {
                (xi - frac) / (1.0 - frac).max(1e-300)
            };
            ((lo as usize) + up as usize).min(MAP_LEVELS - 1)
        };
        let it = self.thickness.as_ref().map_or(0, |t| level(&t.map));
        let ii = self.ink.as_ref().map_or(0, |k| level(&k.map));
        let _ = nt;
        let cell = &self.cache[it * ni + ii];
        cell.get_or_init(|| {
            // The extremes were validated in `new`; intermediate levels lie between them.
            (self.factory)(&self.params_at(it, ii)).expect("paper parameters between validated extremes")
        })
        .as_ref()
    }
}

/// What a surface does with light.
pub enum Material {
    /// Absorbs everything (e.g. a pure emitter).
    Black,
    /// Two-sided Lambertian reflection.
    Diffuse {
        /// Reflectance.
        reflectance: ColourTexture,
    },
    /// A fixed BSDF everywhere (a rough dielectric, or a measured RGL `.bsdf` BRDF, which is black from behind).
    Fixed(Arc<dyn Bsdf>),
    /// A paper sheet.
    Paper(Box<PaperMaterial>),
}

impl Material {
    /// The BSDF at texture coordinates `(u, v)`; `xi` is a random number for map level choice.
    /// `None` for a black (non-scattering) material.
    #[inline]
    pub fn bsdf_at(&self, u: f64, v: f64, xi: f64) -> Option<HitBsdf<'_>> {
        match self {
            Material::Black => None,
            Material::Diffuse { reflectance } => Some(HitBsdf::Lambert(Lambert {
                r: reflectance.eval(u, v),
            })),
            Material::Fixed(b) => Some(HitBsdf::Shared(b.as_ref())),
            Material::Paper(p) => Some(HitBsdf::Shared(p.bsdf_at(u, v, xi))),
        }
    }
}
