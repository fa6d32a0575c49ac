//! Layers as reflection and transmission matrices of one Fourier order, the
//! adding equations that stack them, and the homogeneous scattering layer by
//! doubling.
//!
//! **What a matrix means.** A layer of Fourier order `m` maps the order-`m`
//! radiance arriving at its faces to the radiance leaving them, as values at
//! the grid's nodes (magnitudes `mu_j` of propagation directions; the top side
//! and the bottom side may have different grids, as an interface does). With
//! a BSDF `f` (without cosine, radiance transport, directions as propagation
//! directions so that a mirror keeps the azimuth), the entry is
//! `K[o][j] = w_j mu_j integral_0^(2 pi) f(mu_o, mu_j, phi) cos(m phi) dphi`:
//! the quadrature of the incident hemisphere is inside the matrix, so layers
//! compose by matrix products. The flux of a radiance vector `L` of order 0 is
//! `2 pi sum_j w_j mu_j L_j`, and a layer conserves energy when
//! `sum_o w_o mu_o (R[o][j] + T[o][j]) = w_j mu_j` for every `j`.
//! Reciprocity: with `W = diag(w_j mu_j / eta^2)` of each side
//! ([`crate::Grid::reciprocity_weights`]), `W_top R_top` and `W_bot R_bot`
//! are symmetric and `W_bot T_down = (W_top T_up)^T`.
//!
//! **Adding** (van de Hulst 1980, ch. 4; Grant & Hunt 1969; Jakob et al. 2014,
//! eq. 5): for layer 1 above layer 2,
//! `T_down = T2d (I - R1b R2t)^-1 T1d`,
//! `R_top = R1t + T1u R2t (I - R1b R2t)^-1 T1d`, and the same with the roles of
//! the sides exchanged.
//!
//! **The medium.** Order `m` of the radiative transfer equation in optical
//! depth, for downward radiance `u` and upward radiance `v`:
//! `du/dtau = -A u + B v`, `dv/dtau = A v - B u` with
//! `A = M^-1 (I - a F_same W)`, `B = a M^-1 F_opp W`, `M = diag(mu)`,
//! `W = diag(w)` and `F` the phase function's coefficients ([`crate::phase`]).
//! A thin starting layer of thickness `dtau = tau / 2^k` comes from the
//! diamond difference (trapezoidal) scheme on that system (Wiscombe 1976,
//! "On initialization, error and flux conservation in the doubling method",
//! JQSRT 16; with `h = dtau / 2`, `X = (I + h A)^-1`, `Y = I - h A`, `Z = h B`:
//! `R = (I - X Z X Z)^-1 X Z (I + X Y)`, `T = X Y + X Z R`), which conserves
//! the flux exactly when the phase matrix is normalised; then `k` doublings
//! `T' = T (I - R R)^-1 T`, `R' = R + T R (I - R R)^-1 T`. The unscattered
//! part of `T` becomes `((1 - x/2) / (1 + x/2))^(2^k)`, `x = dtau / mu`, for
//! `exp(-tau / mu)`, whose relative error is `(tau / mu) x^2 / 12` to leading
//! order: the default `dtau` keeps `x <= 1/64` at the smallest node, i.e. at
//! most `2e-5 tau / mu` (`exp(-tau / mu)` itself falls below `1e-12` beyond
//! `tau / mu = 28`).
//!
//! **First order.** A path scattered `k` times in the medium carries `a^k`
//! of the single-scattering albedo `a`, so the light scattered once (with
//! every face interaction around it) is `a dS/da` at `a = 0`. It is solved
//! exactly, with the unscattered sheet: the layers carry their slopes
//! ([`Slope`]), the medium's from [`medium_slope`] (the diamond start's
//! first-order terms, `R = X (h M^-1 F_opp W) (I + X Y)` and the same with
//! `F_same` for `T`, since `Z = 0` at `a = 0`; then each doubling's, where
//! the layer without scattering reflects nothing and transmits a diagonal
//! `D`: `R' = R + D R D`, `T' = T D + D T`, no inverse), the faces' zero;
//! adding takes the product rule ([`Layer::add_with_slope`]: `d(G^-1 T) =
//! G^-1 (dT + dG' G^-1 T)` with `dG' = dR_1 R_2 + R_1 dR_2`). Checked
//! against finite differences of full solves and, for an index-matched
//! sheet, against the closed form of single scattering in a slab at every
//! pair of nodes (2.4e-5; tests/first_order.rs).

use crate::error::SlabError;
use crate::linalg;
use crate::phase::PhaseFourier;
use crate::quad::Grid;
use nalgebra::DMatrix;
use paperbsdf_core::ParamError;

/// Reflection and transmission matrices of one Fourier order (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// Reflection of light arriving from above, `n_top x n_top`.
    pub r_top: DMatrix<f64>,
    /// Transmission of light arriving from above, `n_bot x n_top`.
    pub t_down: DMatrix<f64>,
    /// Reflection of light arriving from below, `n_bot x n_bot`.
    pub r_bot: DMatrix<f64>,
    /// Transmission of light arriving from below, `n_top x n_bot`.
    pub t_up: DMatrix<f64>,
}

impl Layer {
    /// A layer that lets everything through unchanged (no interface), on a grid of `n` nodes.
    pub fn identity(n: usize) -> Layer {
        Layer {
            r_top: DMatrix::zeros(n, n),
            t_down: DMatrix::identity(n, n),
            r_bot: DMatrix::zeros(n, n),
            t_up: DMatrix::identity(n, n),
        }
    }
    /// The same layer turned upside down.
    pub fn flipped(&self) -> Layer {
        Layer {
            r_top: self.r_bot.clone(),
            t_down: self.t_up.clone(),
            r_bot: self.r_top.clone(),
            t_up: self.t_down.clone(),
        }
    }
    /// Nodes on the top side.
    pub fn n_top(&self) -> usize {
        self.r_top.nrows()
    }
    /// Nodes on the bottom side.
    pub fn n_bot(&self) -> usize {
        self.r_bot.nrows()
    }
    /// This layer above `below`, by the adding equations (module doc).
    pub fn add(&self, below: &Layer) -> Result<Layer, SlabError> {
        let gap = self.gap(below)?;
        Ok(self.sum(below, &gap))
    }
    /// The interreflection between this layer and `below` (module doc):
    /// `I - R1b R2t` and `I - R2t R1b`, and the light through the gap going
    /// down, `x1 = (I - R1b R2t)^-1 T1d`, and up, `x2 = (I - R2t R1b)^-1 T2u`.
    fn gap(&self, below: &Layer) -> Result<Gap, SlabError> {
        if self.n_bot() != below.n_top() {
            return Err(SlabError::GridMismatch {
                upper: self.n_bot(),
                lower: below.n_top(),
            });
        }
        let n = self.n_bot();
        let eye = DMatrix::<f64>::identity(n, n);
        let down = &eye - &self.r_bot * &below.r_top;
        let up = &eye - &below.r_top * &self.r_bot;
        let x1 = solve_gap(down.clone(), &self.t_down)?;
        let x2 = solve_gap(up.clone(), &below.t_up)?;
        Ok(Gap { down, up, x1, x2 })
    }
    /// This layer above `below` from their [`Layer::gap`].
    fn sum(&self, below: &Layer, gap: &Gap) -> Layer {
        Layer {
            r_top: &self.r_top + &self.t_up * (&below.r_top * &gap.x1),
            t_down: &below.t_down * &gap.x1,
            r_bot: &below.r_bot + &below.t_down * (&self.r_bot * &gap.x2),
            t_up: &self.t_up * &gap.x2,
        }
    }
}

/// The slopes of a layer's four matrices: their derivatives in the medium's
/// single-scattering albedo at albedo 0 (the first-order term, module doc
/// "First order").
pub type Slope = Layer;

impl Layer {
    /// A layer of `n_top` and `n_bot` nodes whose slope is zero (a face).
    pub fn zero_slope(n_top: usize, n_bot: usize) -> Slope {
        Layer {
            r_top: DMatrix::zeros(n_top, n_top),
            t_down: DMatrix::zeros(n_bot, n_top),
            r_bot: DMatrix::zeros(n_bot, n_bot),
            t_up: DMatrix::zeros(n_top, n_bot),
        }
    }
    /// [`Layer::add`] with the layers' slopes (module doc, "First order"):
    /// returns the sum, the same as [`Layer::add`] to the last bit, and its
    /// slope, by the product rule on the adding equations.
    pub fn add_with_slope(
        &self,
        slope: &Slope,
        below: &Layer,
        below_slope: &Slope,
    ) -> Result<(Layer, Slope), SlabError> {
        let gap = self.gap(below)?;
        let (x1, x2) = (&gap.x1, &gap.x2);
        // d x1 = gap1^-1 (dT1d + (dR1b R2t + R1b dR2t) x1), and alike x2.
        let d_gap1 = &slope.r_bot * &below.r_top + &self.r_bot * &below_slope.r_top;
        let dx1 = solve_gap(gap.down.clone(), &(&slope.t_down + &d_gap1 * x1))?;
        let d_gap2 = &below_slope.r_top * &self.r_bot + &below.r_top * &slope.r_bot;
        let dx2 = solve_gap(gap.up.clone(), &(&below_slope.t_up + &d_gap2 * x2))?;
        let d_slope = Layer {
            r_top: &slope.r_top
                + &slope.t_up * (&below.r_top * x1)
                + &self.t_up * (&below_slope.r_top * x1 + &below.r_top * &dx1),
            t_down: &below_slope.t_down * x1 + &below.t_down * &dx1,
            r_bot: &below_slope.r_bot
                + &below_slope.t_down * (&self.r_bot * x2)
                + &below.t_down * (&slope.r_bot * x2 + &self.r_bot * &dx2),
            t_up: &slope.t_up * x2 + &self.t_up * &dx2,
        };
        Ok((self.sum(below, &gap), d_slope))
    }
}

/// [`Layer::gap`]: the interreflection matrices and the light through the gap.
struct Gap {
    /// `I - R1b R2t`.
    down: DMatrix<f64>,
    /// `I - R2t R1b`.
    up: DMatrix<f64>,
    /// `(I - R1b R2t)^-1 T1d`.
    x1: DMatrix<f64>,
    /// `(I - R2t R1b)^-1 T2u`.
    x2: DMatrix<f64>,
}

/// Solves `gap x = rhs` for an interreflection matrix `gap = I - R_a R_b`.
///
/// `gap` is singular only for a mode that the two layers reflect into each
/// other completely (total internal reflection between two faces with no
/// medium in between, `tau = 0`): its row and column of `gap` are zero. Such
/// a mode is decoupled, and if no light is sent into it (its rows of `rhs`
/// are zero, as for light from outside) its solution is zero; the rest is
/// solved without it. Anything else is [`SlabError::Singular`].
fn solve_gap(gap: DMatrix<f64>, rhs: &DMatrix<f64>) -> Result<DMatrix<f64>, SlabError> {
    if let Some(x) = linalg::solve(gap.clone(), rhs) {
        if x.iter().all(|v| v.is_finite()) {
            return Ok(x);
        }
    }
    let n = gap.nrows();
    let trapped: Vec<bool> = (0..n)
        .map(|k| gap.row(k).iter().all(|v| *v == 0.0) && gap.column(k).iter().all(|v| *v == 0.0))
        .collect();
    let keep: Vec<usize> = (0..n).filter(|k| !trapped[*k]).collect();
    let lit_trapped = (0..n).any(|k| trapped[k] && rhs.row(k).iter().any(|v| *v != 0.0));
    if keep.len() == n || lit_trapped {
        return Err(SlabError::Singular { step: "adding" });
    }
    let sub = gap.select_rows(&keep).select_columns(&keep);
    let sub_rhs = rhs.select_rows(&keep);
    let xs = linalg::solve(sub, &sub_rhs).ok_or(SlabError::Singular { step: "adding" })?;
    let mut x = DMatrix::zeros(n, rhs.ncols());
    for (r, &k) in keep.iter().enumerate() {
        x.set_row(k, &xs.row(r));
    }
    Ok(x)
}

/// A homogeneous scattering layer of one order: the same `r` and `t` from both sides.
#[derive(Clone, Debug, PartialEq)]
pub struct SymmetricLayer {
    /// Reflection (either side).
    pub r: DMatrix<f64>,
    /// Transmission (either direction).
    pub t: DMatrix<f64>,
}

impl SymmetricLayer {
    /// Two copies of this layer, one above the other (one LU of `I - R R`).
    pub fn doubled(&self) -> Result<SymmetricLayer, SlabError> {
        let n = self.r.nrows();
        let gap = DMatrix::<f64>::identity(n, n) - &self.r * &self.r;
        let s = linalg::solve(gap, &self.t).ok_or(SlabError::Singular { step: "doubling" })?;
        Ok(SymmetricLayer {
            r: &self.r + &self.t * (&self.r * &s),
            t: &self.t * s,
        })
    }
    /// As a general [`Layer`].
    pub fn into_layer(self) -> Layer {
        Layer {
            r_top: self.r.clone(),
            t_down: self.t.clone(),
            r_bot: self.r,
            t_up: self.t,
        }
    }
}

/// The default starting thickness for `grid`: the largest power of two at
/// most `mu_min / 64` (module doc).
pub fn default_start_thickness(grid: &Grid) -> f64 {
    let mu_min = grid.mu.iter().copied().fold(1.0, f64::min);
    let cap = mu_min / 64.0;
    2f64.powi(cap.log2().floor() as i32)
}

/// The medium layer of order `m`: single-scattering albedo `albedo` in
/// `[0, 1]`, optical thickness `tau` in `[0, inf)`, phase coefficients
/// `phase` on `grid`; started at a thickness of at most `start` (module doc)
/// and doubled to `tau` (for `albedo = 0` the layer is the closed form: no
/// reflection, transmission `exp(-tau / mu)`). Returns the layer and the
/// number of doublings.
pub fn medium_layer(
    grid: &Grid,
    phase: &PhaseFourier,
    m: usize,
    albedo: f64,
    tau: f64,
    start: f64,
) -> Result<(SymmetricLayer, u32), SlabError> {
    ParamError::check_range("albedo", albedo, 0.0, 1.0)?;
    medium_layer_checks(phase, m, tau, start)?;
    let n = grid.len();
    if tau == 0.0 {
        return Ok((
            SymmetricLayer {
                r: DMatrix::zeros(n, n),
                t: DMatrix::identity(n, n),
            },
            0,
        ));
    }
    if albedo == 0.0 {
        // No scattering: no reflection, and each direction is attenuated by
        // exp(-tau / mu) (the limit the doubling converges to, here exact).
        let t = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
            n,
            grid.mu.iter().map(|&mu| (-tau / mu).exp()),
        ));
        return Ok((
            SymmetricLayer {
                r: DMatrix::zeros(n, n),
                t,
            },
            0,
        ));
    }
    let (dtau, k) = start_and_doublings(tau, start);
    let h = 0.5 * dtau;
    let eye = DMatrix::<f64>::identity(n, n);
    // hA and hB as in the module doc
    let mut ha = DMatrix::<f64>::zeros(n, n);
    let mut hb = DMatrix::<f64>::zeros(n, n);
    for i in 0..n {
        let f = h / grid.mu[i];
        for j in 0..n {
            let delta = if i == j { 1.0 } else { 0.0 };
            ha[(i, j)] = f * (delta - albedo * phase.same[m][(i, j)] * grid.w[j]);
            hb[(i, j)] = f * albedo * phase.opposite[m][(i, j)] * grid.w[j];
        }
    }
    let lu = linalg::Factored::new(&eye + &ha);
    let xy = lu
        .solve(&(&eye - &ha))
        .ok_or(SlabError::Singular { step: "starting layer" })?;
    let xz = lu.solve(&hb).ok_or(SlabError::Singular { step: "starting layer" })?;
    let rhs = &xz * (&eye + &xy);
    let r = linalg::solve(&eye - &xz * &xz, &rhs).ok_or(SlabError::Singular { step: "starting layer" })?;
    let t = &xy + &xz * &r;
    let mut layer = SymmetricLayer { r, t };
    for _ in 0..k {
        layer = layer.doubled()?;
    }
    Ok((layer, k))
}

/// The slope of the medium layer of order `m` in the albedo at 0 (module
/// doc, "First order"), per unit albedo, for the thickness `tau` started
/// and doubled as [`medium_layer`] does: the first-order terms of the
/// diamond starting layer, then of each doubling, where the layer without
/// scattering reflects nothing and transmits the diagonal `D` (so no
/// inverse is needed): `R' = R + D R D`, `T' = T D + D T`, `D' = D^2`.
/// Zero for `tau = 0`.
pub fn medium_slope(
    grid: &Grid,
    phase: &PhaseFourier,
    m: usize,
    tau: f64,
    start: f64,
) -> Result<SymmetricLayer, SlabError> {
    // The same checks as the layer itself (albedo 1: any in range).
    medium_layer_checks(phase, m, tau, start)?;
    let n = grid.len();
    if tau == 0.0 {
        return Ok(SymmetricLayer {
            r: DMatrix::zeros(n, n),
            t: DMatrix::zeros(n, n),
        });
    }
    let (dtau, k) = start_and_doublings(tau, start);
    let h = 0.5 * dtau;
    // x = h / mu: X = diag(1 / (1 + x)), X Y = diag((1 - x) / (1 + x)),
    // I + X Y = diag(2 / (1 + x)). The starting layer's first order:
    // R = X (h M^-1 F_opp W) (I + X Y), T = X (h M^-1 F_same W) (I + X Y).
    let x: Vec<f64> = grid.mu.iter().map(|&mu| h / mu).collect();
    let left: Vec<f64> = x.iter().map(|&x| x / (1.0 + x)).collect();
    let right: Vec<f64> = x.iter().zip(&grid.w).map(|(&x, &w)| 2.0 * w / (1.0 + x)).collect();
    let mut r = DMatrix::from_fn(n, n, |i, j| left[i] * phase.opposite[m][(i, j)] * right[j]);
    let mut t = DMatrix::from_fn(n, n, |i, j| left[i] * phase.same[m][(i, j)] * right[j]);
    let mut d: Vec<f64> = x.iter().map(|&x| (1.0 - x) / (1.0 + x)).collect();
    for _ in 0..k {
        for i in 0..n {
            for j in 0..n {
                r[(i, j)] += d[i] * r[(i, j)] * d[j];
                t[(i, j)] *= d[i] + d[j];
            }
        }
        for v in &mut d {
            *v *= *v;
        }
    }
    Ok(SymmetricLayer { r, t })
}

/// The starting layer's thickness for `tau`, `tau / 2^k` with the fewest
/// halvings `k` that bring it to at most `start`, and `k`: the same for
/// [`medium_layer`] and [`medium_slope`], whose doublings must match.
fn start_and_doublings(tau: f64, start: f64) -> (f64, u32) {
    let mut k = 0u32;
    let mut dtau = tau;
    while dtau > start {
        dtau *= 0.5;
        k += 1;
    }
    (dtau, k)
}

/// The checks of [`medium_layer`] and [`medium_slope`] but the albedo's.
fn medium_layer_checks(phase: &PhaseFourier, m: usize, tau: f64, start: f64) -> Result<(), SlabError> {
    ParamError::check_range("tau", tau, 0.0, 1e12)?;
    if !(start > 0.0 && start.is_finite()) {
        return Err(SlabError::Discretisation {
            name: "start_thickness",
            value: start,
            range: "(0, inf)",
        });
    }
    if m >= phase.same.len() {
        return Err(SlabError::Discretisation {
            name: "orders",
            value: m as f64,
            range: "below the number of computed phase orders",
        });
    }
    Ok(())
}
