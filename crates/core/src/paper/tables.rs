//! The node tables of the Paper BSDF and of its faces: quantities tabulated
//! once per parameter set on nodes uniform in `t = sqrt(mu)` of the outside
//! cosine (dense near grazing, where Fresnel and the microfacet terms vary
//! fastest), their linear interpolation in `t`, and their hemispherical
//! integrals `2 int g(mu) mu dmu`, done exactly for what is interpolated so
//! that the energy checks integrate what `eval` returns.

use crate::quadrature::gauss_legendre_01;
use std::ops::{Add, Mul};

/// Nodes of the lobe-probability table in the outside cosine (`mu = t^2`, `t` uniform).
pub(crate) const NP: usize = 33;

/// Number of nodes of the per-face tables in the outside cosine (`mu = t^2`, `t` uniform).
pub(crate) const NS: usize = 33;

/// Nodes of the per-face tables in the outside cosine (`mu = t^2`, `t` uniform).
pub(crate) const NA: usize = 65;

/// [`lerp_nodes`] at `mu`: `st = sqrt(min(|mu|, 1))`.
#[inline(always)]
pub(crate) fn lerp_mu<T, const N: usize>(tab: &[T; N], mu: f64) -> T
where
    T: Copy + Mul<f64, Output = T> + Add<Output = T>,
{
    lerp_nodes(tab, mu.abs().min(1.0).sqrt())
}

/// The interval `i` of an `N`-node table that holds `st` (in `[0, 1]`) and
/// the fraction `f` of the way from node `i` to `i + 1`: the weights of
/// every linear interpolation of the tables.
#[inline(always)]
pub(crate) fn node_at<const N: usize>(st: f64) -> (usize, f64) {
    let x = st * (N - 1) as f64;
    // `(x as i32).max(0) as usize` is `x as usize` for every `x` once capped
    // at `N - 2` (NaN and negatives give 0, large values the cap), in fewer
    // instructions: x86-64 converts to signed integers only.
    let i = ((x as i32).max(0) as usize).min(N - 2);
    (i, x - i as f64)
}

/// A cosine's place on the [`NA`]-node tables: `st = sqrt(min(|mu|, 1))` with
/// the interval and fraction of [`node_at`], found once per direction and
/// shared by every table read there ([`TabPos::lerp`] is [`lerp_nodes`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct TabPos {
    /// `sqrt(min(|mu|, 1))`.
    pub st: f64,
    /// The interval: nodes `i` and `i + 1`.
    pub i: usize,
    /// The fraction of the way from node `i` to node `i + 1`.
    pub f: f64,
}

impl TabPos {
    /// The place of grazing (`st = 0`), for callers that read no table.
    pub const ZERO: TabPos = TabPos { st: 0.0, i: 0, f: 0.0 };

    /// The place of `st = sqrt(min(|mu|, 1))`.
    #[inline(always)]
    pub fn new(st: f64) -> Self {
        let (i, f) = node_at::<NA>(st);
        TabPos { st, i, f }
    }

    /// [`lerp_nodes`] of `tab` at this place.
    #[inline(always)]
    pub fn lerp<T>(&self, tab: &[T; NA]) -> T
    where
        T: Copy + Mul<f64, Output = T> + Add<Output = T>,
    {
        tab[self.i] * (1.0 - self.f) + tab[self.i + 1] * self.f
    }
}

/// Linear interpolation of a node table (of numbers or colours) at
/// `mu = st^2` for a precomputed `st = sqrt(min(|mu|, 1))`.
#[inline(always)]
pub(crate) fn lerp_nodes<T, const N: usize>(tab: &[T; N], st: f64) -> T
where
    T: Copy + Mul<f64, Output = T> + Add<Output = T>,
{
    let (i, f) = node_at::<N>(st);
    tab[i] * (1.0 - f) + tab[i + 1] * f
}

/// `2 int_0^1 g(mu) mu dmu` of a table interpolated by [`lerp_nodes`]: with
/// `mu = t^2` the integrand is `4 t^3 g(t)`, a polynomial of degree 4 on each
/// interval, integrated exactly by 3-point Gauss-Legendre per interval. Energy
/// checks rely on this being the integral of exactly what `eval` interpolates.
pub(crate) fn hemispherical_of_table(tab: &[f64; NA]) -> f64 {
    const X: [f64; 3] = [0.112_701_665_379_258_31, 0.5, 0.887_298_334_620_741_7];
    const W: [f64; 3] = [5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0];
    let h = 1.0 / (NA - 1) as f64;
    let mut s = 0.0;
    for i in 0..NA - 1 {
        for (x, w) in X.iter().zip(W) {
            let t = (i as f64 + x) * h;
            let g = tab[i] * (1.0 - x) + tab[i + 1] * x;
            s += w * h * 4.0 * t * t * t * g;
        }
    }
    s
}

/// `2 int_0^1 g(mu) mu dmu` of a function by Gauss-Legendre in `t = sqrt(mu)`
/// on `[0, t_c]` and `[t_c, 1]` (a kink of total internal reflection at
/// `mu = t_c^2` falls on the split).
pub(crate) fn hemispherical(g: impl Fn(f64) -> f64, mu_split: f64) -> f64 {
    hemispherical_pair(|mu| (g(mu), 0.0), mu_split).0
}

/// [`hemispherical`] of the two functions `g` returns, on the same points
/// (each sum as [`hemispherical`] would form it): for pairs of integrands
/// that share their work.
pub(crate) fn hemispherical_pair(g: impl Fn(f64) -> (f64, f64), mu_split: f64) -> (f64, f64) {
    static GL: std::sync::OnceLock<(Vec<f64>, Vec<f64>)> = std::sync::OnceLock::new();
    let (x, w) = GL.get_or_init(|| gauss_legendre_01(24));
    let tc = mu_split.clamp(0.0, 1.0).sqrt();
    let (mut s0, mut s1) = (0.0, 0.0);
    for (lo, hi) in [(0.0, tc), (tc, 1.0)] {
        let len = hi - lo;
        if len <= 0.0 {
            continue;
        }
        for (xi, wi) in x.iter().zip(w) {
            let t = lo + len * xi;
            let (a, b) = g(t * t);
            s0 += wi * len * 4.0 * t * t * t * a;
            s1 += wi * len * 4.0 * t * t * t * b;
        }
    }
    (s0, s1)
}
