//! Integrals of a rough dielectric boundary that the Paper BSDF needs
//! (DESIGN.md 4.1): the directional transmittance from outside `Att(mu)` (the
//! paper's `rho_dt`), the directional reflectance from outside, the directional
//! reflectance and transmittance from inside (total internal reflection
//! included), and the hemispherical-hemispherical internal reflectance
//! `rho_in` and transmittance `Tbar_in` for diffuse light from inside.
//!
//! All are flux fractions (importance transport, no `eta^2`). They are computed
//! by quadrature in the unit square that parametrises visible normals
//! (Heitz & d'Eon 2014): with `h(u)` drawn from the visible normals seen from
//! `w`, `R(w) = E[F(w.h) G1(r)]` and `T(w) = E[(1 - F) G1(t)]`, an integrand that
//! is smooth in `u` even for a nearly smooth surface.

use crate::dielectric::{Interface, RoughDielectric};
use crate::fresnel::fresnel_dielectric;
use crate::geometry::{reflect, refract};
use crate::quadrature::gauss_legendre_01;
use glam::DVec3;

/// Points per axis of the Gauss-Legendre rule in the visible-normal square used
/// by [`directional_albedo`].
pub const DIRECT_QUADRATURE_POINTS: usize = 32;

/// `(reflectance, transmittance)` of the boundary for light arriving from
/// direction `w` (pointing toward the light, from either side), by quadrature
/// with [`DIRECT_QUADRATURE_POINTS`] points per axis.
pub fn directional_albedo(b: &RoughDielectric, w: DVec3) -> (f64, f64) {
    directional_albedo_n(b, w, DIRECT_QUADRATURE_POINTS)
}

/// As [`directional_albedo`] with `n` quadrature points per axis.
pub fn directional_albedo_n(b: &RoughDielectric, w: DVec3, n: usize) -> (f64, f64) {
    let mf = match b.interface {
        Interface::IndexMatched => return (0.0, 1.0),
        Interface::Smooth => {
            let f = fresnel_dielectric(w.z, b.eta);
            return (f, 1.0 - f);
        }
        Interface::Rough(mf) => mf,
    };
    if w.z == 0.0 {
        return (0.0, 0.0);
    }
    let eta_ti = if w.z > 0.0 { 1.0 / b.eta } else { b.eta };
    let (x, wt) = gauss_legendre_01(n);
    let (mut r, mut t) = (0.0, 0.0);
    for (i, &u0) in x.iter().enumerate() {
        for (j, &u1) in x.iter().enumerate() {
            let h = mf.sample_visible(w, [u0, u1]);
            let wh = w.dot(h);
            if wh * w.z <= 0.0 {
                continue;
            }
            let f = fresnel_dielectric(wh, b.eta);
            let ww = wt[i] * wt[j];
            let wr = reflect(w, h);
            if wr.z * w.z > 0.0 {
                r += ww * f * mf.g1(wr, h);
            }
            if f < 1.0 {
                if let Some(wt_) = refract(w, h, eta_ti) {
                    if wt_.z * w.z < 0.0 {
                        t += ww * (1.0 - f) * mf.g1(wt_, h);
                    }
                }
            }
        }
    }
    (r, t)
}

/// Number of nodes of the per-surface 1D tables in `mu`.
pub const N_MU: usize = 33;

/// `mu` of node `k` of the outside tables: `mu = t^2`, `t` uniform in [0, 1]
/// (dense near grazing, where a rough face's `Att` changes fastest).
#[inline]
pub fn outside_mu(k: usize) -> f64 {
    let t = k as f64 / (N_MU - 1) as f64;
    t * t
}

/// Cosine of the critical angle seen from inside a face of relative index `eta`
/// (0 when `eta <= 1`).
#[inline]
pub fn critical_mu(eta: f64) -> f64 {
    if eta <= 1.0 {
        0.0
    } else {
        (1.0 - 1.0 / (eta * eta)).sqrt()
    }
}

/// `mu` of node `k` of the inside tables: half of the nodes below the critical
/// cosine `mu_c` (uniform), half above it with quadratic spacing from `mu_c`,
/// so that the kink of total internal reflection lies on a node for every eta.
#[inline]
pub fn inside_mu(k: usize, mu_c: f64) -> f64 {
    let half = (N_MU - 1) / 2;
    if k <= half {
        mu_c * k as f64 / half as f64
    } else {
        let s = (k - half) as f64 / half as f64;
        mu_c + (1.0 - mu_c) * s * s
    }
}

/// Fractional node coordinate of `mu` on the inside grid (inverse of [`inside_mu`]).
#[inline]
fn inside_coord(mu: f64, mu_c: f64) -> f64 {
    let half = ((N_MU - 1) / 2) as f64;
    if mu <= mu_c {
        if mu_c > 0.0 {
            half * mu / mu_c
        } else {
            half
        }
    } else {
        half + half * ((mu - mu_c) / (1.0 - mu_c)).max(0.0).sqrt()
    }
}

#[inline]
fn lerp_table(tab: &[f64; N_MU], x: f64) -> f64 {
    let x = x.clamp(0.0, (N_MU - 1) as f64);
    let i = (x as usize).min(N_MU - 2);
    let f = x - i as f64;
    tab[i] * (1.0 - f) + tab[i + 1] * f
}

/// The integrals of one boundary that the Paper BSDF needs, tabulated in `mu`.
/// All are flux fractions (no `eta^2`).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceIntegrals {
    /// `Att` (transmittance from outside) at the outside nodes.
    pub att_nodes: [f64; N_MU],
    /// Reflectance from outside at the outside nodes.
    pub r_out_nodes: [f64; N_MU],
    /// Reflectance from inside (TIR included) at the inside nodes.
    pub r_in_nodes: [f64; N_MU],
    /// Transmittance from inside at the inside nodes.
    pub t_in_nodes: [f64; N_MU],
    /// Cosine of the critical angle from inside.
    pub mu_c: f64,
    /// `rho_in`: hemispherical-hemispherical reflectance for diffuse (cosine-weighted) light from inside.
    pub rho_in: f64,
    /// `Tbar_in`: hemispherical transmittance for diffuse light from inside.
    pub tbar_in: f64,
}

impl SurfaceIntegrals {
    /// `Att(mu)`: directional transmittance for light from outside at cosine `mu` in [0, 1].
    #[inline]
    pub fn att(&self, mu: f64) -> f64 {
        lerp_table(&self.att_nodes, mu.abs().min(1.0).sqrt() * (N_MU - 1) as f64)
    }
    /// Directional reflectance for light from outside at cosine `mu`.
    #[inline]
    pub fn r_out(&self, mu: f64) -> f64 {
        lerp_table(&self.r_out_nodes, mu.abs().min(1.0).sqrt() * (N_MU - 1) as f64)
    }
    /// Directional reflectance (TIR included) for light from inside at cosine `mu` (magnitude).
    #[inline]
    pub fn r_in(&self, mu: f64) -> f64 {
        lerp_table(&self.r_in_nodes, inside_coord(mu.abs().min(1.0), self.mu_c))
    }
    /// Directional transmittance for light from inside at cosine `mu` (magnitude).
    #[inline]
    pub fn t_in(&self, mu: f64) -> f64 {
        lerp_table(&self.t_in_nodes, inside_coord(mu.abs().min(1.0), self.mu_c))
    }

    /// Computes every integral of `b` by direct quadrature with `n` points per
    /// axis (slow: milliseconds; the tables' ground truth).
    pub fn direct(b: &RoughDielectric, n: usize) -> Self {
        let mu_c = critical_mu(b.eta);
        let mut s = SurfaceIntegrals {
            att_nodes: [0.0; N_MU],
            r_out_nodes: [0.0; N_MU],
            r_in_nodes: [0.0; N_MU],
            t_in_nodes: [0.0; N_MU],
            mu_c,
            rho_in: 0.0,
            tbar_in: 0.0,
        };
        for k in 0..N_MU {
            let (r, t) = directional_albedo_n(b, dir_at_mu(outside_mu(k), 1.0), n);
            s.r_out_nodes[k] = r;
            s.att_nodes[k] = t;
            let (r, t) = directional_albedo_n(b, dir_at_mu(inside_mu(k, mu_c), -1.0), n);
            s.r_in_nodes[k] = r;
            s.t_in_nodes[k] = t;
        }
        let (rho, tbar) = hemispherical_inside(b, n);
        s.rho_in = rho;
        s.tbar_in = tbar;
        s
    }
}

/// Direction with `|cos theta| = mu` in the x-z plane, on the side `sign` (+1 outside, -1 inside).
#[inline]
pub fn dir_at_mu(mu: f64, sign: f64) -> DVec3 {
    let mu = mu.clamp(0.0, 1.0);
    DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, sign * mu)
}

/// Points of the Gauss-Legendre rule on each side of the critical cosine used by
/// [`hemispherical_inside`].
pub const HEMI_MU_POINTS: usize = 12;

/// `(rho_in, Tbar_in)`: `2 int_0^1 R_in(mu) mu dmu` and `2 int_0^1 T_in(mu) mu dmu`
/// for diffuse light from inside, split at the critical cosine (where `R_in` has a
/// kink) with a square-root substitution above it; `n` points per axis for each
/// directional integral.
pub fn hemispherical_inside(b: &RoughDielectric, n: usize) -> (f64, f64) {
    let mu_c = critical_mu(b.eta);
    let (x, w) = gauss_legendre_01(HEMI_MU_POINTS);
    let (mut rho, mut tbar) = (0.0, 0.0);
    for (xi, wi) in x.iter().zip(&w) {
        // Below the critical cosine: mu = mu_c x.
        if mu_c > 0.0 {
            let mu = mu_c * xi;
            let (r, t) = directional_albedo_n(b, dir_at_mu(mu, -1.0), n);
            rho += 2.0 * wi * mu_c * r * mu;
            tbar += 2.0 * wi * mu_c * t * mu;
        }
        // Above it: mu = mu_c + (1 - mu_c) s^2, dmu = 2 (1 - mu_c) s ds.
        let mu = mu_c + (1.0 - mu_c) * xi * xi;
        let jac = 2.0 * (1.0 - mu_c) * xi;
        let (r, t) = directional_albedo_n(b, dir_at_mu(mu, -1.0), n);
        rho += 2.0 * wi * jac * r * mu;
        tbar += 2.0 * wi * jac * t * mu;
    }
    (rho, tbar)
}
