//! Specular gloss (TAPPI T480 / ISO 8254-1 at 75 degrees, TAPPI T653 /
//! ISO 8254-3 at 20 degrees, ASTM D523 / ISO 2813 at 20, 60 and 85 degrees)
//! integrated from a BSDF over the instrument's source and receptor apertures.
//!
//! A gloss meter sends a beam at the polar angle `theta` and reads the flux
//! reflected into a receptor window centred on the mirror direction. Gloss is
//! `100 GU` times that flux over the flux a polished black glass of the
//! standard's index reflects into the same window (Fresnel reflection only,
//! its body being black), so a perfect mirror reads `100 / F_glass(theta)`
//! (384.4 GU at 75 degrees for index 1.540).
//!
//! The flux for one source direction `wi` is
//! `int_receptor f(wi, wo) cos(theta_o) dwo` (composite Gauss-Legendre over the
//! window's angular rectangle, or polar Gauss-Legendre over a round window),
//! combined by multiple importance sampling (balance heuristic) with
//! stratified draws of [`Bsdf::sample`] from the source direction (for
//! reflection, `f(wi, wo) = f(wo, wi)`) kept when they fall in the window:
//! the quadrature resolves broad lobes, the draws narrow ones (a lobe of
//! `m = 0.002` is narrower than the quadrature's spacing at 75 degrees) and
//! the delta lobes of smooth faces, which `eval` does not include. The source directions are averaged over the
//! source aperture (Gauss-Legendre, equal power per direction), and the glass
//! reference is averaged over the same directions. Gloss of an RGB BSDF is the
//! gloss of its luminance `Y`.
//!
//! Apertures (in the plane of incidence x across it, degrees): ASTM D523
//! receptors as the standard gives them; TAPPI T653 a round receptor of 5
//! degrees diameter (as the method's published summary describes it). The
//! source apertures, and the T480 receptor, were not at hand: we use
//! ASTM D523's source `0.75 x 2.5` everywhere and a `4.0 x 10.0` receptor for
//! T480 (documented assumptions in `docs/paper_metrics.md`).

use crate::instrument::luminance;
use paperbsdf_core::fresnel::fresnel_dielectric;
use paperbsdf_core::quadrature::gauss_legendre_01;
use paperbsdf_core::{Bsdf, DVec3, Rgb};

/// The shape of a receptor window.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum Window {
    /// An angular rectangle: full widths in the plane of incidence and across it, degrees.
    Rect(f64, f64),
    /// A round window of this full angular diameter, degrees.
    Round(f64),
}

/// One standard gloss geometry.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct GlossGeometry {
    /// JSON key of the result.
    pub key: &'static str,
    /// The standard.
    pub standard: &'static str,
    /// Angle of incidence and of the receptor, degrees from the normal.
    pub angle_deg: f64,
    /// Refractive index of the reference black glass (100 GU).
    pub glass_index: f64,
    /// Source aperture (full widths in plane x across), degrees.
    pub source: (f64, f64),
    /// Receptor window.
    pub receptor: Window,
}

/// The geometries `measure` reports.
pub const GEOMETRIES: [GlossGeometry; 5] = [
    GlossGeometry {
        key: "gloss_75_tappi_t480",
        standard: "TAPPI T480 / ISO 8254-1",
        angle_deg: 75.0,
        glass_index: 1.540,
        source: (0.75, 2.5),
        receptor: Window::Rect(4.0, 10.0),
    },
    GlossGeometry {
        key: "gloss_20_tappi_t653",
        standard: "TAPPI T653 / ISO 8254-3",
        angle_deg: 20.0,
        glass_index: 1.540,
        source: (0.75, 2.5),
        receptor: Window::Round(5.0),
    },
    GlossGeometry {
        key: "gloss_20_astm_d523",
        standard: "ASTM D523 / ISO 2813",
        angle_deg: 20.0,
        glass_index: 1.567,
        source: (0.75, 2.5),
        receptor: Window::Rect(1.8, 3.6),
    },
    GlossGeometry {
        key: "gloss_60_astm_d523",
        standard: "ASTM D523 / ISO 2813",
        angle_deg: 60.0,
        glass_index: 1.567,
        source: (0.75, 2.5),
        receptor: Window::Rect(4.4, 11.7),
    },
    GlossGeometry {
        key: "gloss_85_astm_d523",
        standard: "ASTM D523 / ISO 2813",
        angle_deg: 85.0,
        glass_index: 1.567,
        source: (0.75, 2.5),
        receptor: Window::Rect(4.0, 6.0),
    },
];

/// The geometry with JSON key `key`.
pub fn geometry(key: &str) -> Option<&'static GlossGeometry> {
    GEOMETRIES.iter().find(|g| g.key == key)
}

/// Direction at in-plane offset `a` and across offset `b` (radians) from the
/// direction at polar angle `theta` on the `sign` side of `x` (+1: the light's
/// side, -1: the mirror side), above the sheet.
fn offset_dir(theta: f64, a: f64, b: f64, sign: f64) -> DVec3 {
    let (sa, ca) = (theta + a).sin_cos();
    let (sb, cb) = b.sin_cos();
    DVec3::new(sign * cb * sa, sb, cb * ca)
}

/// Quadrature points `(a, b, weight)` over a window (radians, weights in steradians).
fn window_points(w: Window, n: usize) -> Vec<(f64, f64, f64)> {
    let (x, wx) = gauss_legendre_01(n);
    let mut pts = Vec::new();
    match w {
        Window::Rect(ia, ib) => {
            let (ha, hb) = (ia.to_radians() / 2.0, ib.to_radians() / 2.0);
            // Composite rule: 6 panels in plane and 5 across of n nodes each,
            // so that a lobe of a fraction of a degree (m ~ 0.01) is resolved.
            let (pan_a, pan_b) = (6, 5);
            let node = |h: f64, panels: usize, p: usize, k: usize| -> (f64, f64) {
                let w = 2.0 * h / panels as f64;
                (-h + (p as f64 + x[k]) * w, wx[k] * w)
            };
            for pa in 0..pan_a {
                for ka in 0..n {
                    let (a, wa) = node(ha, pan_a, pa, ka);
                    for pb in 0..pan_b {
                        for kb in 0..n {
                            let (b, wb) = node(hb, pan_b, pb, kb);
                            pts.push((a, b, wa * wb * b.cos()));
                        }
                    }
                }
            }
        }
        Window::Round(diam) => {
            let r = diam.to_radians() / 2.0;
            let nphi = 4 * n;
            for k in 0..n {
                let rho = r * x[k];
                for j in 0..nphi {
                    let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / nphi as f64;
                    let (a, b) = (rho * phi.cos(), rho * phi.sin());
                    pts.push((
                        a,
                        b,
                        wx[k] * r * rho * (2.0 * std::f64::consts::PI / nphi as f64) * b.cos(),
                    ));
                }
            }
        }
    }
    pts
}

/// Whether `wo` (above the sheet) lies in the window centred on the mirror direction at `theta`.
fn in_window(w: Window, theta: f64, wo: DVec3) -> bool {
    if wo.z <= 0.0 {
        return false;
    }
    let b = wo.y.clamp(-1.0, 1.0).asin();
    let a = (-wo.x).atan2(wo.z) - theta;
    match w {
        Window::Rect(ia, ib) => a.abs() <= ia.to_radians() / 2.0 && b.abs() <= ib.to_radians() / 2.0,
        Window::Round(d) => a * a + b * b <= (d.to_radians() / 2.0).powi(2),
    }
}

/// Strata per axis of the BSDF-sampling strategy (per source direction).
const NS: usize = 64;

/// The reflected flux (per unit incident flux, per channel) into the receptor,
/// and the glass reference's, for one geometry.
pub fn receptor_flux(bsdf: &dyn Bsdf, g: &GlossGeometry) -> (Rgb, f64) {
    let theta = g.angle_deg.to_radians();
    let (ns, nr) = (3, 8);
    let (x, wx) = gauss_legendre_01(ns);
    let (sa, sb) = (g.source.0.to_radians(), g.source.1.to_radians());
    let rec = window_points(g.receptor, nr);
    let omega: f64 = rec.iter().map(|p| p.2).sum();
    let (mut flux, mut glass, mut wsum) = (Rgb::ZERO, 0.0, 0.0);
    for i in 0..ns {
        for j in 0..ns {
            let a = (x[i] - 0.5) * sa;
            let b = (x[j] - 0.5) * sb;
            let ws = wx[i] * wx[j] * b.cos();
            let wi = offset_dir(theta, a, b, 1.0);
            // Two strategies combined by the balance heuristic (Veach 1997):
            // the quadrature over the window, read as uniform sampling of its
            // solid angle (density 1 / omega), and sampling the BSDF from the
            // source (density `pdf`), which alone resolves a lobe narrower
            // than the quadrature's spacing and alone sees delta lobes.
            let n_q = rec.len() as f64;
            let n_s = (NS * NS) as f64;
            let mut f = Rgb::ZERO;
            for &(ra, rb, w) in &rec {
                let wo = offset_dir(theta, ra, rb, -1.0);
                let pq = n_q / omega;
                let ps = n_s * bsdf.pdf(wo, wi);
                let mis = if pq + ps > 0.0 { pq / (pq + ps) } else { 1.0 };
                f += bsdf.eval(wi, wo) * (w * wo.z * mis);
            }
            let mut fs = Rgb::ZERO;
            let golden = 0.618_033_988_749_894_9;
            for si in 0..NS {
                for sj in 0..NS {
                    let k = (si * NS + sj) as f64;
                    let uc = (0.5 + k * golden).fract();
                    let u = [(si as f64 + 0.5) / NS as f64, (sj as f64 + 0.5) / NS as f64];
                    let Some(s) = bsdf.sample(wi, uc, u) else { continue };
                    if s.wi.z <= 0.0 || !in_window(g.receptor, theta, s.wi) {
                        continue;
                    }
                    let w = s.weight();
                    if !w.is_finite() {
                        continue;
                    }
                    let mis = if s.flags.is_specular() {
                        1.0
                    } else {
                        let ps = n_s * s.pdf;
                        let pq = n_q / omega;
                        ps / (pq + ps)
                    };
                    fs += w * mis;
                }
            }
            f += fs * (1.0 / n_s);
            flux += f * ws;
            // The glass's mirror image of wi is inside the window whenever the
            // source is smaller than the receptor (true of every geometry here).
            let mirror = DVec3::new(-wi.x, -wi.y, wi.z);
            let fg = if in_window(g.receptor, theta, mirror) {
                fresnel_dielectric(wi.z, g.glass_index)
            } else {
                0.0
            };
            glass += fg * ws;
            wsum += ws;
        }
    }
    (flux * (1.0 / wsum), glass / wsum)
}

/// Gloss in GU of `bsdf` in geometry `g` (luminance `Y` for RGB).
pub fn gloss(bsdf: &dyn Bsdf, g: &GlossGeometry) -> f64 {
    let (f, glass) = receptor_flux(bsdf, g);
    100.0 * luminance(f) / glass
}
