//! Fourier coefficients in azimuth of the two-lobe Henyey-Greenstein phase
//! function on a quadrature grid (docs/design.md 4.2; Jakob, d'Eon, Jakob,
//! Marschner 2014, section 5, who expand the same way).
//!
//! For propagation directions at cosines `mu_i`, `mu_j` (magnitudes) in the
//! same hemisphere (`s = +1`) or in opposite ones (`s = -1`) the scattering
//! cosine is `s mu_i mu_j + sin_i sin_j cos(phi)`, `phi` the azimuth
//! difference, and the coefficient of order `m` is
//! `F_m(i, j) = integral_0^(2 pi) p(cos) cos(m phi) dphi`, so that
//! `p = sum_m F_m cos(m phi) / (pi (1 + [m = 0]))`.
//!
//! **How they are computed.** Each lobe is `k / (B - C cos phi)^(3/2)`, an
//! analytic periodic function of `phi` whose nearest singularities lie at
//! `Im phi = +- acosh(B / |C|)`, so the trapezoid rule on `N` equispaced
//! points converges like `exp(-N acosh(B / |C|))` and its aliasing error for
//! order `m` like `exp(-(N - m) acosh(B / |C|))` (Trefethen & Weideman 2014,
//! "The exponentially convergent trapezoidal rule", section 3). Each pair of
//! nodes gets `N >= m_max + 40 / acosh(B / |C|)` (capped at `2^17`; an error
//! of about `e^-40` relative), using the evenness in `phi` (half the points),
//! and all orders come from one pass with the Chebyshev recurrence for
//! `cos(m phi)`.
//!
//! **Normalisation.** On a finite grid the order-0 matrix does not integrate
//! to exactly 1 over the sphere (forward peaks are under-resolved), and a
//! conservative layer would then lose or gain energy. The coefficients are
//! therefore rescaled symmetrically, `F_m(i, j) s_i s_j` for every order,
//! with `s` chosen (by a symmetric Sinkhorn iteration) so that
//! `sum_i w_i (F_0^same(i, j) + F_0^opp(i, j)) = 1` for every node `j`. The
//! symmetric scaling keeps the phase matrix reciprocal; the factors are
//! returned ([`PhaseFourier::scale`]) so that their size can be judged.

use crate::error::{check_open, SlabError};
use crate::quad::Grid;
use nalgebra::DMatrix;
use paperbsdf_core::phase::TwoLobeHg;
use paperbsdf_core::ParamError;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Largest number of azimuth points on the full circle for one pair of nodes.
pub const MAX_AZIMUTH_POINTS: usize = 1 << 17;

/// The Fourier coefficients of a phase function on one grid.
#[derive(Clone, Debug)]
pub struct PhaseFourier {
    /// Per order `m`: `F_m` between directions in the same hemisphere, `n x n`.
    pub same: Vec<DMatrix<f64>>,
    /// Per order `m`: `F_m` between directions in opposite hemispheres.
    pub opposite: Vec<DMatrix<f64>>,
    /// The normalisation factors `s_i` (1 for a perfectly resolved phase function).
    pub scale: Vec<f64>,
}

/// Checks the phase function's parameters: `|g| < 1` for both lobes (a delta
/// lobe has no Fourier series on a grid) and `w_b` in `[0, 1]`.
pub fn validate(phase: &TwoLobeHg) -> Result<(), SlabError> {
    check_open("g_f", phase.g_f, -1.0, 1.0)?;
    check_open("g_b", phase.g_b, -1.0, 1.0)?;
    ParamError::check_range("w_b", phase.w_b, 0.0, 1.0)?;
    Ok(())
}

/// The coefficients `F_m` for orders `0..orders` on `grid`, normalised as in
/// the module doc.
pub fn phase_fourier(phase: &TwoLobeHg, grid: &Grid, orders: usize) -> Result<PhaseFourier, SlabError> {
    validate(phase)?;
    if orders == 0 {
        return Err(SlabError::Discretisation {
            name: "orders",
            value: 0.0,
            range: "[1, inf)",
        });
    }
    let n = grid.len();
    let sin: Vec<f64> = grid.mu.iter().map(|m| (1.0 - m * m).max(0.0).sqrt()).collect();
    let lobes: Vec<(f64, f64)> = phase
        .lobes()
        .into_iter()
        .filter(|(_, w)| *w > 0.0)
        .map(|(g, w)| (g, w * (1.0 - g * g) / (4.0 * PI)))
        .collect();
    // rows[i] = (same[m][j], opp[m][j]) for j >= i
    let rows: Vec<(Vec<f64>, Vec<f64>)> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut same = vec![0.0; orders * n];
            let mut opp = vec![0.0; orders * n];
            for j in i..n {
                for (s, out) in [(1.0, &mut same), (-1.0, &mut opp)] {
                    let c = azimuth_coefficients(&lobes, s * grid.mu[i] * grid.mu[j], sin[i] * sin[j], orders);
                    for (m, v) in c.into_iter().enumerate() {
                        out[m * n + j] = v;
                    }
                }
            }
            (same, opp)
        })
        .collect();
    let mut same = vec![DMatrix::<f64>::zeros(n, n); orders];
    let mut opposite = vec![DMatrix::<f64>::zeros(n, n); orders];
    for (i, (rs, ro)) in rows.iter().enumerate() {
        for m in 0..orders {
            for j in i..n {
                let (a, b) = (rs[m * n + j], ro[m * n + j]);
                same[m][(i, j)] = a;
                same[m][(j, i)] = a;
                opposite[m][(i, j)] = b;
                opposite[m][(j, i)] = b;
            }
        }
    }
    let scale = normalisation(&same[0], &opposite[0], &grid.w);
    for m in 0..orders {
        for i in 0..n {
            for j in 0..n {
                let f = scale[i] * scale[j];
                same[m][(i, j)] *= f;
                opposite[m][(i, j)] *= f;
            }
        }
    }
    Ok(PhaseFourier { same, opposite, scale })
}

/// `integral_0^(2 pi) sum_k kappa_k (1 + g_k^2 - 2 g_k cos)^(-3/2) cos(m phi) dphi`
/// for `cos = a + b cos(phi)` and `m = 0..orders`, by the trapezoid rule (module doc).
/// `lobes` holds `(g_k, kappa_k)`.
pub fn azimuth_coefficients(lobes: &[(f64, f64)], a: f64, b: f64, orders: usize) -> Vec<f64> {
    // Strip half-width of analyticity: the narrowest lobe decides.
    let mut strip = f64::INFINITY;
    for &(g, _) in lobes {
        let (bb, cc) = (1.0 + g * g - 2.0 * g * a, (2.0 * g * b).abs());
        if cc > 0.0 {
            strip = strip.min((bb / cc).max(1.0).acosh());
        }
    }
    let extra = if strip.is_finite() { (40.0 / strip).ceil() } else { 0.0 };
    let full = ((orders as f64 + 2.0 + extra) as usize).min(MAX_AZIMUTH_POINTS);
    let half = full.div_ceil(2).max(1);
    let h = PI / half as f64;
    let mut out = vec![0.0; orders];
    for k in 0..=half {
        let phi = k as f64 * h;
        let cp = phi.cos();
        let c = a + b * cp;
        let mut val = 0.0;
        for &(g, kappa) in lobes {
            let q = 1.0 + g * g - 2.0 * g * c;
            val += kappa / (q * q.sqrt());
        }
        let wt = if k == 0 || k == half { 0.5 } else { 1.0 } * 2.0 * h * val;
        // cos(m phi) by the Chebyshev recurrence
        let (mut c0, mut c1) = (1.0, cp);
        out[0] += wt;
        for o in out.iter_mut().skip(1) {
            *o += wt * c1;
            let c2 = 2.0 * cp * c1 - c0;
            c0 = c1;
            c1 = c2;
        }
    }
    out
}

/// The symmetric scaling `s` with `s_j sum_i w_i s_i G_ij = 1`, `G = same + opposite`.
fn normalisation(same: &DMatrix<f64>, opp: &DMatrix<f64>, w: &[f64]) -> Vec<f64> {
    let n = w.len();
    let g = same + opp;
    let mut s = vec![1.0; n];
    for _ in 0..500 {
        let mut worst: f64 = 0.0;
        let r: Vec<f64> = (0..n)
            .map(|j| s[j] * (0..n).map(|i| w[i] * s[i] * g[(i, j)]).sum::<f64>())
            .collect();
        for j in 0..n {
            worst = worst.max((r[j] - 1.0).abs());
            s[j] /= r[j].sqrt();
        }
        if worst < 1e-15 {
            break;
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use paperbsdf_core::phase::hg;

    #[test]
    fn coefficients_match_direct_integration() {
        // a midpoint rule with many points as the independent check
        let lobes = [
            (0.8, 0.7 * (1.0 - 0.64) / (4.0 * PI)),
            (-0.3, 0.3 * (1.0 - 0.09) / (4.0 * PI)),
        ];
        for (a, b) in [(0.3, 0.5), (0.49, 0.51), (-0.2, 0.75), (0.99, 0.01)] {
            let c = azimuth_coefficients(&lobes, a, b, 12);
            for (m, cm) in c.iter().enumerate() {
                let n = 200_000;
                let want: f64 = (0..n)
                    .map(|k| {
                        let phi = (k as f64 + 0.5) * 2.0 * PI / n as f64;
                        let cs = a + b * phi.cos();
                        (0.7 * hg(cs, 0.8) + 0.3 * hg(cs, -0.3)) * (m as f64 * phi).cos() * 2.0 * PI / n as f64
                    })
                    .sum();
                assert!(
                    (cm - want).abs() < 1e-9 * (1.0 + want.abs()),
                    "a={a} b={b} m={m}: {cm} {want}"
                );
            }
        }
    }

    #[test]
    fn rejects_delta_lobes_and_bad_weights() {
        let g = Grid::outside(4);
        let e = phase_fourier(
            &TwoLobeHg {
                g_f: 1.0,
                g_b: 0.0,
                w_b: 0.0,
            },
            &g,
            2,
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("g_f") && e.to_string().contains("(-1, 1)"),
            "{e}"
        );
        let e = phase_fourier(
            &TwoLobeHg {
                g_f: 0.5,
                g_b: 0.0,
                w_b: 1.5,
            },
            &g,
            2,
        )
        .unwrap_err();
        assert!(e.to_string().contains("w_b"), "{e}");
    }
}
