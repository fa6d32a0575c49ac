//! Quadrature in `mu = |cos theta|` for one hemisphere, and the grids the
//! layers live on.
//!
//! **Choice of nodes.** The grid outside the sheet (air, index 1) is an
//! `n`-point Gauss-Radau rule on `[0, 1]` with its fixed node at `mu = 1`
//! (exact for polynomials of degree `2n - 2`; Abramowitz & Stegun 25.4.31), so
//! that normal incidence, where every reference total is given (iadpython's
//! `UR1`, `UT1`), is a node; `mu = 0` is never a node. Inside a medium of index
//! `eta > 1` the hemisphere splits at the critical cosine
//! `mu_c = sqrt(1 - 1/eta^2)`: the cone `mu > mu_c` holds the Snell images of the
//! outside nodes, `mu_in = sqrt(1 - (1 - mu_out^2) / eta^2)`, with the weights
//! that the change of variables `mu_in dmu_in = mu_out dmu_out / eta^2` gives,
//! and the cone of total internal reflection `mu < mu_c` its own Gauss-Legendre
//! rule. So a smooth interface is diagonal (each outside node refracts onto one
//! inside node), the kink of the Fresnel factor at `mu_c` falls between two
//! panels instead of inside one, and a rough interface's matrices are sampled
//! on both sides of it. This is the split of Prahl's adding-doubling
//! (Prahl, van Gemert, Welch 1993) and of Jakob et al. 2014 (section 6.1), here
//! with Radau outside; the nodes and weights are computed here, not copied.
//!
//! **A coated sheet** (front coating of index `eta_f` over a base of index
//! `eta_b != eta_f`, `paperbsdf_core::sheet`) has three grids: the outside
//! grid, the coating's and the base's. The smooth coating/base boundary is
//! resolved as the air/medium one: the less dense of the two media gets
//! [`Grid::inside`] of the outside grid, the denser one [`Grid::denser`] of
//! that, i.e. the Snell images of all its nodes plus a Gauss-Legendre rule in
//! its cone of total internal reflection at the boundary
//! (`mu < sqrt(1 - (n_less / n_denser)^2)`). Since the Snell invariant
//! `n sin theta` is what refraction keeps, the last nodes of both inside
//! grids are the images of the outside nodes, so any smooth face between air
//! and either medium is diagonal too, and the panels of the three grids meet
//! at the two kinks (`n sin theta = 1` and `= min(eta_f, eta_b)`).

use nalgebra::{DMatrix, SymmetricEigen};
use paperbsdf_core::boundary::critical_mu;
use paperbsdf_core::fresnel::cos_transmitted;
use paperbsdf_core::quadrature::gauss_legendre_01;

/// Quadrature nodes and weights on one hemisphere, `mu` in `(0, 1]`, and the
/// refractive index of the medium the directions are in.
///
/// A function `h(mu)` integrates as `sum_j w[j] h(mu[j])` over `[0, 1]`; the
/// flux of a radiance vector `L` (Fourier order 0) is `2 pi sum_j w[j] mu[j] L[j]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Nodes `mu_j`, ascending, in `(0, 1]`.
    pub mu: Vec<f64>,
    /// Weights `w_j` (summing to 1, the length of `[0, 1]`).
    pub w: Vec<f64>,
    /// Refractive index of the medium these directions are in (1 for air).
    pub eta: f64,
}

impl Grid {
    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.mu.len()
    }
    /// Whether the grid has no nodes.
    pub fn is_empty(&self) -> bool {
        self.mu.is_empty()
    }
    /// The reciprocity weights `w_j mu_j / eta^2`: with `W` their diagonal
    /// matrix, a reciprocal layer has `W R` symmetric on each side and
    /// `W_bottom T_down = (W_top T_up)^T` (basic radiance `L / eta^2` is what
    /// reciprocity exchanges).
    pub fn reciprocity_weights(&self) -> Vec<f64> {
        let e2 = self.eta * self.eta;
        self.mu.iter().zip(&self.w).map(|(m, w)| m * w / e2).collect()
    }
    /// The `n`-point Gauss-Radau grid in air (index 1) with a node at `mu = 1`.
    pub fn outside(n: usize) -> Grid {
        let (mu, w) = gauss_radau_01(n);
        Grid { mu, w, eta: 1.0 }
    }
    /// The grid inside a medium of index `eta` seen through a face from the
    /// `outside` grid: `n_tir` Gauss-Legendre nodes on `[0, mu_c]`, then the
    /// Snell images of the outside nodes (module doc). For `eta = 1` it is the
    /// outside grid itself. `outside` must be in air (`eta = 1`).
    pub fn inside(outside: &Grid, eta: f64, n_tir: usize) -> Grid {
        debug_assert_eq!(outside.eta, 1.0);
        Grid::denser(outside, eta, n_tir)
    }
    /// The grid in a medium of (absolute) index `eta >= from.eta` beyond a
    /// smooth boundary with the medium of `from` (relative index
    /// `r = eta / from.eta`): `n_tir` Gauss-Legendre nodes on `[0, mu_c]`,
    /// `mu_c = sqrt(1 - 1/r^2)` (the directions that the boundary reflects
    /// totally back into the denser medium), then the Snell images of all of
    /// `from`'s nodes in the same order, with the weights of the change of
    /// variables `mu' dmu' = mu dmu / r^2` (module doc). So the boundary is
    /// diagonal between the two grids, and the last `from.len()` nodes are the
    /// images of `from`'s (images of images are images: the Snell invariant
    /// `n sin theta` is kept). For `eta = from.eta` it is `from` itself.
    ///
    /// The coated sheet's grids (`crate::slab`) are made with it: the
    /// coating's and the base's from the outside grid, the less dense first.
    pub fn denser(from: &Grid, eta: f64, n_tir: usize) -> Grid {
        debug_assert!(eta >= from.eta, "Grid::denser: {eta} < {}", from.eta);
        if eta == from.eta {
            return from.clone();
        }
        let r = eta / from.eta;
        let r2 = r * r;
        let mu_c = critical_mu(r);
        let (x, wx) = gauss_legendre_01(n_tir);
        let mut mu: Vec<f64> = x.iter().map(|x| x * mu_c).collect();
        let mut w: Vec<f64> = wx.iter().map(|w| w * mu_c).collect();
        for (mo, wo) in from.mu.iter().zip(&from.w) {
            // Into the denser medium there is no total internal reflection.
            let mi = cos_transmitted(*mo, r).map_or(0.0, f64::abs);
            mu.push(mi);
            w.push(wo * mo / (r2 * mi));
        }
        Grid { mu, w, eta }
    }
}

/// `n`-point Gauss-Radau rule on `[0, 1]` with the fixed node at 1: (nodes
/// ascending, weights summing to 1). Exact for polynomials of degree `2n - 2`.
///
/// On `[-1, 1]` with the fixed node at `x = -1` (mapped by `mu = (1 - x) / 2`),
/// the free nodes are the zeros of the Jacobi polynomial `P^(0,1)_(n-1)`, found
/// here as eigenvalues of its Jacobi matrix (Golub & Welsch 1969; recurrence
/// coefficients of Jacobi polynomials, Abramowitz & Stegun 22.7.1, with
/// `alpha = 0`, `beta = 1`: diagonal `1 / ((2k+1)(2k+3))`, off-diagonal
/// `sqrt(k(k+1)) / (2k+1)`), then polished by Newton's method on
/// `q = P_(n-1) + P_n`; the weights are `2 / n^2` at the fixed node and
/// `(1 - x_i) / (n^2 P_(n-1)(x_i)^2)` elsewhere (A&S 25.4.31), halved for `[0, 1]`.
pub fn gauss_radau_01(n: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(n >= 1, "a Radau rule needs at least one node");
    let nf = n as f64;
    let mut xs = Vec::with_capacity(n);
    let mut ws = Vec::with_capacity(n);
    xs.push(-1.0);
    ws.push(2.0 / (nf * nf));
    if n > 1 {
        let k = n - 1;
        let mut jm = DMatrix::<f64>::zeros(k, k);
        for i in 0..k {
            let fi = i as f64;
            jm[(i, i)] = 1.0 / ((2.0 * fi + 1.0) * (2.0 * fi + 3.0));
            if i + 1 < k {
                let f1 = fi + 1.0;
                let b = (f1 * (f1 + 1.0)).sqrt() / (2.0 * f1 + 1.0);
                jm[(i, i + 1)] = b;
                jm[(i + 1, i)] = b;
            }
        }
        let mut roots: Vec<f64> = SymmetricEigen::new(jm).eigenvalues.iter().copied().collect();
        roots.sort_by(|a, b| a.total_cmp(b));
        for x in roots {
            let mut x = x;
            for _ in 0..3 {
                let (p_nm1, p_n, dp_nm1, dp_n) = legendre_pair(n, x);
                let q = p_nm1 + p_n;
                let dq = dp_nm1 + dp_n;
                if dq == 0.0 {
                    break;
                }
                x -= q / dq;
            }
            let (p_nm1, _, _, _) = legendre_pair(n, x);
            xs.push(x);
            ws.push((1.0 - x) / (nf * nf * p_nm1 * p_nm1));
        }
    }
    // Map to [0, 1], ascending in mu (x descending).
    let mut pairs: Vec<(f64, f64)> = xs.iter().zip(&ws).map(|(x, w)| (0.5 * (1.0 - x), 0.5 * w)).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    pairs.into_iter().unzip()
}

/// `(P_(n-1)(x), P_n(x), P'_(n-1)(x), P'_n(x))` by the three-term recurrence
/// (derivatives by the recurrence of `P'`, valid also at `x = +-1`).
fn legendre_pair(n: usize, x: f64) -> (f64, f64, f64, f64) {
    // p[k], dp[k] for k = 0..=n
    let (mut p0, mut p1) = (1.0, x);
    let (mut d0, mut d1) = (0.0, 1.0);
    if n == 1 {
        return (p0, p1, d0, d1);
    }
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
        // P'_k = P'_(k-2) + (2k - 1) P_(k-1)
        let d2 = d0 + (2.0 * kf - 1.0) * p1;
        p0 = p1;
        p1 = p2;
        d0 = d1;
        d1 = d2;
    }
    (p0, p1, d0, d1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radau_integrates_polynomials_exactly() {
        for n in [1usize, 2, 3, 8, 17, 40, 64] {
            let (x, w) = gauss_radau_01(n);
            assert_eq!(x.len(), n);
            assert!((x[n - 1] - 1.0).abs() < 1e-15);
            assert!(x.windows(2).all(|p| p[0] < p[1]) && x[0] > 0.0);
            for p in 0..(2 * n - 1) {
                let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p as i32)).sum();
                assert!((s - 1.0 / (p as f64 + 1.0)).abs() < 1e-13, "n={n} p={p} {s}");
            }
        }
        // the two-point rule: nodes 1/3 and 1 on [0, 1], weights 3/4 and 1/4
        let (x, w) = gauss_radau_01(2);
        assert!((x[0] - 1.0 / 3.0).abs() < 1e-15 && (w[0] - 0.75).abs() < 1e-15);
    }

    #[test]
    fn denser_grids_pair_snell_images_and_integrate() {
        let out = Grid::outside(12);
        for (n1, n2) in [(1.3, 1.6), (1.5, 1.55), (1.45, 1.55), (1.0, 1.5)] {
            let a = Grid::inside(&out, n1, 8);
            let b = Grid::denser(&a, n2, 6);
            assert_eq!((b.len(), b.eta), (a.len() + 6, n2));
            let s1: f64 = b.mu.iter().zip(&b.w).map(|(m, w)| w * m).sum();
            let s3: f64 = b.mu.iter().zip(&b.w).map(|(m, w)| w * m.powi(3)).sum();
            assert!(
                (s1 - 0.5).abs() < 1e-13 && (s3 - 0.25).abs() < 1e-13,
                "{n1} {n2}: {s1} {s3}"
            );
            assert!(b.mu.windows(2).all(|p| p[0] < p[1]) && b.mu[0] > 0.0);
            // the images of a's nodes, and (images of images) those of the outside nodes
            let off = b.len() - a.len();
            for k in 0..a.len() {
                let img = cos_transmitted(a.mu[k], n2 / n1).unwrap().abs();
                assert!((b.mu[off + k] - img).abs() < 1e-15);
                assert!((b.w[off + k] * b.mu[off + k] - a.w[k] * a.mu[k] * (n1 * n1) / (n2 * n2)).abs() < 1e-15);
            }
            let off = b.len() - out.len();
            for k in 0..out.len() {
                let img = cos_transmitted(out.mu[k], n2).unwrap().abs();
                assert!((b.mu[off + k] - img).abs() < 1e-13, "{n1} {n2} {k}");
            }
            // the cone of total reflection at the boundary has exactly its own nodes
            let mu_c = critical_mu(n2 / n1);
            assert_eq!(b.mu.iter().filter(|m| **m < mu_c).count(), 6);
        }
    }

    #[test]
    fn inside_grid_integrates_both_cones() {
        let out = Grid::outside(16);
        for eta in [1.0, 1.33, 1.5, 2.5] {
            let g = Grid::inside(&out, eta, 12);
            let mu_c = (1.0 - 1.0 / (eta * eta)).sqrt();
            // integral of mu over [0, 1] and of mu^3
            let s1: f64 = g.mu.iter().zip(&g.w).map(|(m, w)| w * m).sum();
            let s3: f64 = g.mu.iter().zip(&g.w).map(|(m, w)| w * m.powi(3)).sum();
            assert!(
                (s1 - 0.5).abs() < 1e-13 && (s3 - 0.25).abs() < 1e-13,
                "eta={eta}: {s1} {s3}"
            );
            // the cone of total internal reflection has exactly its own nodes
            let n_tir = g.mu.iter().filter(|m| **m < mu_c).count();
            assert_eq!(n_tir, if eta == 1.0 { 0 } else { 12 });
        }
    }
}
