//! Integrals of a rough dielectric boundary that the Paper BSDF needs
//! (docs/design.md 4.1): the directional transmittance from outside `Att(mu)` (the
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

pub mod tables;

use crate::dielectric::{Interface, RoughDielectric};
use crate::fresnel::fresnel_dielectric;
use crate::geometry::{reflect, refract};
use crate::quadrature::gauss_legendre_01;
use glam::DVec3;

/// Points per axis of the Gauss-Legendre rule in the visible-normal square used
/// by [`directional_albedo`].
pub const DIRECT_QUADRATURE_POINTS: usize = 256;

/// `(reflectance, transmittance)` of the boundary for light arriving from
/// direction `w` (pointing toward the light, from either side), by quadrature
/// with [`DIRECT_QUADRATURE_POINTS`] points per axis.
pub fn directional_albedo(b: &RoughDielectric, w: DVec3) -> (f64, f64) {
    directional_albedo_n(b, w, DIRECT_QUADRATURE_POINTS)
}

/// As [`directional_albedo`] with `n` quadrature points per axis.
pub fn directional_albedo_n(b: &RoughDielectric, w: DVec3, n: usize) -> (f64, f64) {
    directional_albedo_rule(b, w, &gauss_legendre_01(n))
}

/// As [`directional_albedo`] on the Gauss-Legendre rule `(x, wt)` on `[0, 1]`
/// ([`gauss_legendre_01`]), per axis: for callers that take many albedos on
/// one rule and compute it once (the rule's Newton iterations cost as much
/// as a 128-point albedo's quadrature).
pub fn directional_albedo_rule(b: &RoughDielectric, w: DVec3, (x, wt): &(Vec<f64>, Vec<f64>)) -> (f64, f64) {
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
    // Both visible-normal maps are separable on a tensor grid (one
    // inversion per row and per column; the samplers' values).
    let normals = mf.visible_normal_grid(w, x);
    let (mut r, mut t) = (0.0, 0.0);
    for i in 0..x.len() {
        for j in 0..x.len() {
            let h = normals[i * x.len() + j];
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
pub const N_MU: usize = 49;

/// Nodes per segment of the inside grid (three segments).
const SEG: usize = (N_MU - 1) / 3;

/// Roughness below which the grids no longer narrow with m: there the curves
/// are dominated by the m-independent Fresnel shape, which misaligned grids
/// would blur.
const M_ALIGN: f64 = 0.05;

/// Smallest clustering scale of the grids (in `mu`).
const W_MIN: f64 = 1e-4;

/// Node placement of one surface's `mu` tables. The sharp features of the
/// curves have a width proportional to the roughness: the masking fall-off at
/// grazing (`mu ~ m`) and the transition around the critical angle of total
/// internal reflection (`mu ~ m sin theta_c`). Nodes are spaced geometrically
/// away from each feature point, starting at a scale proportional to `m`, so
/// every surface's features fall on the same node indices and interpolation in
/// (eta, m) at a fixed index follows them.
///
/// Outside: `mu = w ((1 + 1/w)^x - 1)`, `x = k / (N_MU - 1)`.
/// Inside, three segments of `SEG` intervals: grazing to `mu_c / 2`
/// (clustered at grazing), `mu_c / 2` to `mu_c` (clustered at `mu_c`), `mu_c`
/// to 1 (clustered at `mu_c`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MuGrid {
    /// Cosine of the critical angle from inside.
    pub mu_c: f64,
    /// Clustering scale at grazing.
    pub w_graze: f64,
    /// Clustering scale at the critical angle.
    pub w_crit: f64,
    /// The denominators `ln(1 + span / w)` of [`MuGrid::outside_coord`] and
    /// [`MuGrid::inside_coord`] (outside, inside below `mu_c / 2`, from
    /// `mu_c / 2` to `mu_c`, above `mu_c`), which depend on the grid alone:
    /// computed once here, not at every lookup.
    ln_span: [f64; 4],
}

#[inline]
fn geo(w: f64, span: f64, x: f64) -> f64 {
    if span <= 0.0 {
        return 0.0;
    }
    w * ((1.0 + span / w).powf(x) - 1.0)
}

/// `ln(1 + span / w)`: the denominator of [`geo_inv`] (0 for an empty span, which [`geo_inv`] does not read).
#[inline]
fn geo_ln_span(w: f64, span: f64) -> f64 {
    if span <= 0.0 {
        return 0.0;
    }
    (1.0 + span / w).ln()
}

/// The inverse of [`geo`]: the node coordinate in `[0, 1]` of `d`, given
/// `ln_span = `[`geo_ln_span`]`(w, span)`.
#[inline]
fn geo_inv(w: f64, span: f64, ln_span: f64, d: f64) -> f64 {
    if span <= 0.0 {
        return 0.0;
    }
    ((1.0 + d.clamp(0.0, span) / w).ln() / ln_span).clamp(0.0, 1.0)
}

impl MuGrid {
    /// The grid of a face of relative index `eta` and roughness `m`.
    pub fn new(eta: f64, m: f64) -> Self {
        let mu_c = critical_mu(eta);
        let s_c = (1.0 - mu_c * mu_c).max(0.0).sqrt();
        let m = m.max(M_ALIGN);
        let w_graze = (0.25 * m).max(W_MIN);
        let w_crit = (0.25 * m * s_c).max(W_MIN);
        let half = 0.5 * mu_c;
        MuGrid {
            mu_c,
            w_graze,
            w_crit,
            ln_span: [
                geo_ln_span(w_graze, 1.0),
                geo_ln_span(w_graze, half),
                geo_ln_span(w_crit, half),
                geo_ln_span(w_crit, 1.0 - mu_c),
            ],
        }
    }
    /// `mu` of node `k` of the outside tables.
    pub fn outside_mu(&self, k: usize) -> f64 {
        geo(self.w_graze, 1.0, k as f64 / (N_MU - 1) as f64).min(1.0)
    }
    /// Fractional node coordinate of `mu` on the outside grid.
    #[inline]
    pub fn outside_coord(&self, mu: f64) -> f64 {
        geo_inv(self.w_graze, 1.0, self.ln_span[0], mu) * (N_MU - 1) as f64
    }
    /// `mu` of node `k` of the inside tables.
    pub fn inside_mu(&self, k: usize) -> f64 {
        let half = 0.5 * self.mu_c;
        let x = (k % SEG) as f64 / SEG as f64;
        let mu = match k / SEG {
            0 => geo(self.w_graze, half, x),
            1 => self.mu_c - geo(self.w_crit, half, 1.0 - x),
            2 => self.mu_c + geo(self.w_crit, 1.0 - self.mu_c, x),
            _ => 1.0,
        };
        mu.clamp(0.0, 1.0)
    }
    /// Fractional node coordinate of `mu` on the inside grid.
    #[inline]
    pub fn inside_coord(&self, mu: f64) -> f64 {
        let half = 0.5 * self.mu_c;
        let seg = SEG as f64;
        if mu >= self.mu_c {
            2.0 * seg + seg * geo_inv(self.w_crit, 1.0 - self.mu_c, self.ln_span[3], mu - self.mu_c)
        } else if mu >= half {
            seg + seg * (1.0 - geo_inv(self.w_crit, half, self.ln_span[2], self.mu_c - mu))
        } else {
            seg * geo_inv(self.w_graze, half, self.ln_span[1], mu)
        }
    }
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

/// Cubic Hermite (Catmull-Rom) interpolation of `tab` at fractional node
/// coordinate `x`, within the segment of nodes `[lo, hi]` that contains it (the
/// curves are smooth functions of the node coordinate inside a segment; the
/// segments meet at the kink of total internal reflection, which no
/// interpolant crosses). Slopes are central differences, second-order
/// one-sided at the segment's ends.
#[inline]
fn cubic_table(tab: &[f64; N_MU], x: f64, lo: usize, hi: usize) -> f64 {
    let x = x.clamp(lo as f64, hi as f64);
    let i = ((x as usize).max(lo)).min(hi - 1);
    let t = x - i as f64;
    let slope = |k: usize| -> f64 {
        if hi - lo < 2 {
            tab[hi] - tab[lo]
        } else if k == lo {
            0.5 * (-3.0 * tab[k] + 4.0 * tab[k + 1] - tab[k + 2])
        } else if k == hi {
            0.5 * (3.0 * tab[k] - 4.0 * tab[k - 1] + tab[k - 2])
        } else {
            0.5 * (tab[k + 1] - tab[k - 1])
        }
    };
    let (p0, p1, m0, m1) = (tab[i], tab[i + 1], slope(i), slope(i + 1));
    let (t2, t3) = (t * t, t * t * t);
    (2.0 * t3 - 3.0 * t2 + 1.0) * p0 + (t3 - 2.0 * t2 + t) * m0 + (-2.0 * t3 + 3.0 * t2) * p1 + (t3 - t2) * m1
}

#[inline]
fn outside_table(tab: &[f64; N_MU], grid: &MuGrid, mu: f64) -> f64 {
    cubic_table(tab, grid.outside_coord(mu.abs().min(1.0)), 0, N_MU - 1).max(0.0)
}

#[inline]
fn inside_table(tab: &[f64; N_MU], grid: &MuGrid, mu: f64) -> f64 {
    inside_at(tab, grid.inside_coord(mu.abs().min(1.0)))
}

/// [`inside_table`] at the node coordinate `x` of its `mu`.
#[inline]
fn inside_at(tab: &[f64; N_MU], x: f64) -> f64 {
    let seg = ((x as usize) / SEG).min(2);
    cubic_table(tab, x, seg * SEG, (seg + 1) * SEG).max(0.0)
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
    /// Where the nodes are (depends on eta and m).
    pub grid: MuGrid,
    /// `rho_in`: hemispherical-hemispherical reflectance for diffuse (cosine-weighted) light from inside.
    pub rho_in: f64,
    /// `Tbar_in`: hemispherical transmittance for diffuse light from inside.
    pub tbar_in: f64,
}

impl SurfaceIntegrals {
    /// The integrals of `b` from the precomputed tables (a few microseconds):
    /// bilinear interpolation in (eta, m) of the tabulated `mu` curves, exact
    /// Fresnel for a smooth face, the trivial values for an index-matched face.
    pub fn new(b: &RoughDielectric) -> Self {
        match b.interface {
            Interface::IndexMatched => SurfaceIntegrals {
                att_nodes: [1.0; N_MU],
                r_out_nodes: [0.0; N_MU],
                r_in_nodes: [0.0; N_MU],
                t_in_nodes: [1.0; N_MU],
                grid: MuGrid::new(1.0, 0.0),
                rho_in: 0.0,
                tbar_in: 1.0,
            },
            Interface::Smooth => Self::smooth(b.eta),
            Interface::Rough(_) => crate::boundary::tables::interpolate(b.dist, b.eta, b.m),
        }
    }

    /// All values zero, on the given grid.
    pub(crate) fn zeroed(grid: MuGrid) -> Self {
        SurfaceIntegrals {
            att_nodes: [0.0; N_MU],
            r_out_nodes: [0.0; N_MU],
            r_in_nodes: [0.0; N_MU],
            t_in_nodes: [0.0; N_MU],
            grid,
            rho_in: 0.0,
            tbar_in: 0.0,
        }
    }

    /// The integrals of a smooth face of index `eta` (exact Fresnel).
    pub fn smooth(eta: f64) -> Self {
        let grid = MuGrid::new(eta, 0.0);
        let mut s = Self::zeroed(grid);
        for k in 0..N_MU {
            let f = fresnel_dielectric(grid.outside_mu(k), eta);
            s.r_out_nodes[k] = f;
            s.att_nodes[k] = 1.0 - f;
            let f = fresnel_dielectric(-grid.inside_mu(k), eta);
            s.r_in_nodes[k] = f;
            s.t_in_nodes[k] = 1.0 - f;
        }
        let b = RoughDielectric::new(crate::Distribution::Ggx, eta, 0.0).expect("eta in range");
        let (rho, tbar) = hemispherical_inside(&b, 1);
        s.rho_in = rho;
        s.tbar_in = tbar;
        s
    }

    /// `Att(mu)`: directional transmittance for light from outside at cosine `mu` in [0, 1].
    #[inline]
    pub fn att(&self, mu: f64) -> f64 {
        outside_table(&self.att_nodes, &self.grid, mu)
    }
    /// Directional reflectance for light from outside at cosine `mu`.
    #[inline]
    pub fn r_out(&self, mu: f64) -> f64 {
        outside_table(&self.r_out_nodes, &self.grid, mu)
    }
    /// `(Att(mu), r_out(mu))` at once: [`SurfaceIntegrals::att`] and
    /// [`SurfaceIntegrals::r_out`] (the same values), locating `mu` on the grid once.
    #[inline]
    pub fn att_r_out(&self, mu: f64) -> (f64, f64) {
        let x = self.grid.outside_coord(mu.abs().min(1.0));
        (
            cubic_table(&self.att_nodes, x, 0, N_MU - 1).max(0.0),
            cubic_table(&self.r_out_nodes, x, 0, N_MU - 1).max(0.0),
        )
    }
    /// `(r_in(mu), t_in(mu))` at once: [`SurfaceIntegrals::r_in`] and
    /// [`SurfaceIntegrals::t_in`] (the same values), locating `mu` on the grid once.
    #[inline]
    pub fn r_t_in(&self, mu: f64) -> (f64, f64) {
        let x = self.grid.inside_coord(mu.abs().min(1.0));
        (inside_at(&self.r_in_nodes, x), inside_at(&self.t_in_nodes, x))
    }
    /// Directional reflectance (TIR included) for light from inside at cosine `mu` (magnitude).
    #[inline]
    pub fn r_in(&self, mu: f64) -> f64 {
        inside_table(&self.r_in_nodes, &self.grid, mu)
    }
    /// Directional transmittance for light from inside at cosine `mu` (magnitude).
    #[inline]
    pub fn t_in(&self, mu: f64) -> f64 {
        inside_table(&self.t_in_nodes, &self.grid, mu)
    }

    /// Computes every integral of `b` by direct quadrature with `n` points per
    /// axis (slow: milliseconds; the tables' ground truth).
    pub fn direct(b: &RoughDielectric, n: usize) -> Self {
        let grid = MuGrid::new(b.eta, b.m);
        let mut s = Self::zeroed(grid);
        for k in 0..N_MU {
            let (r, t) = directional_albedo_n(b, dir_at_mu(grid.outside_mu(k), 1.0), n);
            s.r_out_nodes[k] = r;
            s.att_nodes[k] = t;
            let (r, t) = directional_albedo_n(b, dir_at_mu(grid.inside_mu(k), -1.0), n);
            s.r_in_nodes[k] = r;
            s.t_in_nodes[k] = t;
        }
        let (rho, tbar) = hemispherical_inside(b, n);
        s.rho_in = rho;
        s.tbar_in = tbar;
        s
    }
}

/// Direction with `|cos theta| = mu` in the x-z plane, on the side `sign` (+1
/// outside, -1 inside). `mu` below 1e-7 is taken as 1e-7: the integrals' limit
/// at grazing (reflectance does not vanish there; the exact horizon has no side).
#[inline]
pub fn dir_at_mu(mu: f64, sign: f64) -> DVec3 {
    let mu = mu.clamp(1e-7, 1.0);
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
