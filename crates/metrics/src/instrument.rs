//! The reflectance and transmittance factors that paper instruments read,
//! integrated from a BSDF over the instrument's geometry, and the
//! Kubelka/Stokes stacking that turns one sheet into a pad or a sheet over a
//! backing.
//!
//! **Geometries.** ISO 2469 `d/0` (ISO 2470-1 brightness, ISO 2471 opacity,
//! ISO 9416): diffuse illumination from a sphere, viewing along the normal,
//! with a gloss trap. The reflectance factor of a BSDF `f` seen along `wo` under
//! uniform diffuse light is `int f(wi, wo) |cos wi| dwi`, which is exactly the
//! directional albedo `rho(wo)` that [`paperbsdf_core::Bsdf::sample`] estimates
//! for a given `wo` (pbrt's `rho(wo)`); no reciprocity is needed. The gloss trap
//! removes the sphere's light from directions within
//! [`GLOSS_TRAP_HALF_ANGLE_DEG`] of the specular direction (here the normal).
//! TAPPI T425 `15/d`: a beam at 15 degrees, all reflected flux collected by a
//! sphere: the directional-hemispherical reflectance, which for a reciprocal
//! slab (air on both sides) is again `rho(wo)` at `wo` 15 degrees from the normal.
//!
//! **Stacking (Stokes 1862, Kubelka 1954), of diffuse totals.** A sheet over a
//! backing or other sheets exchanges light with them through an air gap. We
//! take the light in the gap as Lambertian and stack *diffuse totals*, not full
//! BSDFs: the sheet's hemispherical-hemispherical reflectance from the front
//! and back (`R_f`, `R_b`) and transmittance `T` (the same from both sides for a
//! reciprocal sheet). The upwelling flux in the gap under the top sheet, per
//! unit flux that the top sheet lets through, is `R_n / (1 - R_b R_n)` for a
//! pad or backing of reflectance `R_n` below, and a pad grows by
//! `R_{n+1} = R_f + T^2 R_n / (1 - R_b R_n)`, whose fixed point is
//! `R_inf = 2 R_f / (B + sqrt(B^2 - 4 R_f R_b))`, `B = 1 + R_f R_b - T^2`.
//! The instrument reads the top sheet's own factor plus what the upwelling
//! diffuse flux sends through it toward the detector:
//! `R = r_dir + t_dir T R_n / (1 - R_b R_n)`, where `r_dir`, `t_dir` are the
//! instrument-geometry factors of the sheet (`d/0` or `15/d`). Tests compare
//! this with the simulator's exact pad of sheets with air gaps.

use paperbsdf_core::{Bsdf, DVec3, Rgb};

/// Rec. 709 / sRGB luminance weights `Y = 0.2126 R + 0.7152 G + 0.0722 B`:
/// linear sRGB primaries under D65. The standards ask for `Y` under CIE
/// illuminant C (ISO 2471) or A (TAPPI T425) from spectra; from RGB this is
/// the closest one can do, and is the same `Y` for both.
pub const Y_WEIGHTS: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// Half-angle of the gloss trap of the `d/0` sphere, degrees: light from
/// directions within this angle of the specular direction is excluded. Our
/// reading of ISO 2469 (a trap subtending about 15.5 degrees at the
/// specimen); the standard's text was not at hand, so it is a setting.
pub const GLOSS_TRAP_HALF_ANGLE_DEG: f64 = 7.75;

/// Luminance factor `Y` of an RGB reflectance ([`Y_WEIGHTS`]).
pub fn luminance(v: Rgb) -> f64 {
    Y_WEIGHTS[0] * v.0[0] + Y_WEIGHTS[1] * v.0[1] + Y_WEIGHTS[2] * v.0[2]
}

/// How many samples the model-side integrals take.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quality {
    /// Strata per axis (`n x n` samples) for the `d/0` and `15/d` factors.
    pub n_direct: usize,
    /// Strata per axis for each directional albedo inside a hemispherical total.
    pub n_hemi: usize,
    /// Gauss-Legendre nodes in `mu` for the hemispherical totals.
    pub mu_nodes: usize,
}

impl Default for Quality {
    fn default() -> Self {
        Quality {
            n_direct: 192,
            n_hemi: 64,
            mu_nodes: 10,
        }
    }
}

impl Quality {
    /// A cheaper setting for inner loops of fits (errors of a few 1e-4 in the factors).
    pub fn fast() -> Self {
        Quality {
            n_direct: 96,
            n_hemi: 40,
            mu_nodes: 8,
        }
    }
}

/// `(reflection, transmission)` parts of `int f(wi, wo) |cos wi| dwi` by
/// `n x n` stratified samples of `bsdf.sample(wo, ..)` (as
/// [`paperbsdf_core::bsdf::sampled_albedo`]), leaving out reflected `wi` within
/// the cone `wi . axis > trap_cos` when `trap` is `Some((axis, trap_cos))`.
pub fn albedo_with_trap(bsdf: &dyn Bsdf, wo: DVec3, n: usize, trap: Option<(DVec3, f64)>) -> (Rgb, Rgb) {
    paperbsdf_core::bsdf::stratified_albedo(bsdf, wo, n, |s| match trap {
        Some((axis, c)) if s.wi.z * wo.z > 0.0 && s.wi.dot(axis) > c => Rgb::ZERO,
        _ => s.weight(),
    })
}

/// The factors of one sheet that the measurements are built from (per channel).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SheetFactors {
    /// `d/0` reflectance factor of the sheet alone (black cavity behind), gloss trap applied.
    pub r_d0: [f64; 3],
    /// `d/0` transmittance factor: diffuse light from behind, seen along the front normal.
    pub t_d0: [f64; 3],
    /// `15/d` reflectance of the sheet alone (TAPPI T425).
    pub r_15: [f64; 3],
    /// `15/d` transmittance (flux of the 15-degree beam leaving through the back).
    pub t_15: [f64; 3],
    /// Hemispherical-hemispherical reflectance for diffuse light on the front.
    pub r_hh_front: [f64; 3],
    /// Hemispherical-hemispherical reflectance for diffuse light on the back.
    pub r_hh_back: [f64; 3],
    /// Hemispherical-hemispherical transmittance (front to back).
    pub t_hh: [f64; 3],
}

/// The unit direction at polar angle `deg` from `+z` (or from `-z` when `back`), in the x-z plane.
pub fn polar_dir(deg: f64, back: bool) -> DVec3 {
    let t = deg.to_radians();
    DVec3::new(t.sin(), 0.0, if back { -t.cos() } else { t.cos() })
}

/// The [`SheetFactors`] of a BSDF through its public interface (sampling only).
pub fn model_factors(bsdf: &dyn Bsdf, q: &Quality) -> SheetFactors {
    let trap = Some((DVec3::Z, GLOSS_TRAP_HALF_ANGLE_DEG.to_radians().cos()));
    let (r_d0, t_d0) = albedo_with_trap(bsdf, DVec3::Z, q.n_direct, trap);
    let (r_15, t_15) = albedo_with_trap(bsdf, polar_dir(15.0, false), q.n_direct, None);
    let (x, w) = paperbsdf_core::quadrature::gauss_legendre_01(q.mu_nodes);
    let (mut rf, mut rb, mut th) = (Rgb::ZERO, Rgb::ZERO, Rgb::ZERO);
    for (&mu, &wk) in x.iter().zip(&w) {
        let s = (1.0 - mu * mu).max(0.0).sqrt();
        let (r, t) = albedo_with_trap(bsdf, DVec3::new(s, 0.0, mu), q.n_hemi, None);
        rf += r * (2.0 * wk * mu);
        th += t * (2.0 * wk * mu);
        let (r, _) = albedo_with_trap(bsdf, DVec3::new(s, 0.0, -mu), q.n_hemi, None);
        rb += r * (2.0 * wk * mu);
    }
    SheetFactors {
        r_d0: r_d0.0,
        t_d0: t_d0.0,
        r_15: r_15.0,
        t_15: t_15.0,
        r_hh_front: rf.0,
        r_hh_back: rb.0,
        t_hh: th.0,
    }
}

/// Diffuse reflectance of an infinitely thick pad of sheets with front
/// reflectance `rf`, back reflectance `rb` and transmittance `t` (module doc).
pub fn pad_reflectance(rf: f64, rb: f64, t: f64) -> f64 {
    let b = 1.0 + rf * rb - t * t;
    let disc = (b * b - 4.0 * rf * rb).max(0.0);
    let den = b + disc.sqrt();
    if den <= 0.0 {
        return 0.0;
    }
    (2.0 * rf / den).clamp(0.0, 1.0)
}

/// Diffuse reflectance of a pad of `n` sheets (`n = 0`: zero), by the recursion of the module doc.
pub fn pad_reflectance_n(rf: f64, rb: f64, t: f64, n: usize) -> f64 {
    let mut r = 0.0;
    for _ in 0..n {
        r = rf + t * t * r / (1.0 - rb * r);
    }
    r
}

/// What the instrument reads for a sheet of directional factors `r_dir`,
/// `t_dir` and diffuse totals `rb`, `t` lying on a backing (or pad) of diffuse
/// reflectance `r_below`: `r_dir + t_dir t r_below / (1 - rb r_below)`.
pub fn over_backing(r_dir: f64, t_dir: f64, rb: f64, t: f64, r_below: f64) -> f64 {
    r_dir + t_dir * t * r_below / (1.0 - rb * r_below)
}

/// The reflectance quantities of the standards, per channel, from a sheet's factors.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Reflectances {
    /// `R0`: `d/0` reflectance factor of one sheet over a black cavity.
    pub r0: [f64; 3],
    /// `R_inf`: `d/0` reflectance factor of an opaque pad of the same sheets.
    pub r_inf: [f64; 3],
    /// `15/d` reflectance of one sheet over black (TAPPI T425 `R0`).
    pub r0_15: [f64; 3],
    /// `15/d` reflectance of one sheet over a white backing of 89 % (TAPPI T425 `R0.89`).
    pub r089_15: [f64; 3],
    /// `d/0` transmittance factor of one sheet (decides the opacity of a sheet that reflects nothing).
    pub t0: [f64; 3],
}

/// Reflectance of the TAPPI T425 white backing.
pub const TAPPI_BACKING: f64 = 0.89;

/// The standards' reflectances from a sheet's factors by Kubelka/Stokes stacking (module doc).
pub fn stack(f: &SheetFactors) -> Reflectances {
    let mut out = Reflectances {
        r0: f.r_d0,
        r_inf: [0.0; 3],
        r0_15: f.r_15,
        r089_15: [0.0; 3],
        t0: f.t_d0,
    };
    for c in 0..3 {
        let (rf, rb, t) = (f.r_hh_front[c], f.r_hh_back[c], f.t_hh[c]);
        let pad = pad_reflectance(rf, rb, t);
        out.r_inf[c] = over_backing(f.r_d0[c], f.t_d0[c], rb, t, pad);
        out.r089_15[c] = over_backing(f.r_15[c], f.t_15[c], rb, t, TAPPI_BACKING);
    }
    out
}

/// Kubelka-Munk light-scattering and light-absorption coefficients (ISO 9416).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct KubelkaMunk {
    /// Light-scattering coefficient `s`, m^2/kg.
    pub s_m2_per_kg: f64,
    /// Light-absorption coefficient `k`, m^2/kg.
    pub k_m2_per_kg: f64,
    /// The grammage they were computed with, g/m^2.
    pub grammage_g_m2: f64,
}

/// ISO 9416 (Kubelka-Munk) `s` and `k` from `R0` and `R_inf` (fractions in
/// (0, 1), `R0 < R_inf`) and the grammage (g/m^2):
/// `a = (1/R_inf + R_inf)/2`, `b = (1/R_inf - R_inf)/2`,
/// `s w = artanh(b R0 / (1 - a R0)) / b`, `k = s (a - 1)`; `None` outside the formulas' domain.
pub fn kubelka_munk(r0: f64, r_inf: f64, grammage: f64) -> Option<KubelkaMunk> {
    if !(r0 > 0.0 && r_inf > r0 && r_inf < 1.0 && grammage > 0.0) {
        return None;
    }
    let a = 0.5 * (1.0 / r_inf + r_inf);
    let b = 0.5 * (1.0 / r_inf - r_inf);
    let arg = b * r0 / (1.0 - a * r0);
    if !(arg > 0.0 && arg < 1.0) {
        return None;
    }
    let sw = arg.atanh() / b; // dimensionless s * w
    let w = grammage * 1e-3; // kg/m^2
    let s = sw / w;
    Some(KubelkaMunk {
        s_m2_per_kg: s,
        k_m2_per_kg: s * (a - 1.0),
        grammage_g_m2: grammage,
    })
}
