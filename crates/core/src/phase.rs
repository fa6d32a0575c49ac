//! Phase functions: Henyey-Greenstein and the Paper BSDF's two-lobe mixture
//! (DESIGN.md 4.2): `p(cos) = w_b HG(cos; g_b) + (1 - w_b) HG(cos; g_f)`, each
//! lobe normalised over the sphere. `cos` is the cosine between the propagation
//! directions before and after scattering (positive `g` scatters forward).
//!
//! HG: Henyey & Greenstein 1941; sampling by the closed-form inverse CDF
//! (pbrt-v4, section 11.3.1).

use crate::geometry::coordinate_system;
use glam::DVec3;
use std::f64::consts::PI;

/// Henyey-Greenstein phase function, per steradian, normalised over the sphere.
#[inline]
pub fn hg(cos: f64, g: f64) -> f64 {
    let denom = 1.0 + g * g - 2.0 * g * cos;
    (1.0 - g * g) / (4.0 * PI * denom * denom.sqrt())
}

/// Draws the cosine between old and new propagation directions from HG(g).
#[inline]
pub fn sample_hg_cos(g: f64, u: f64) -> f64 {
    if g.abs() < 1e-3 {
        return 1.0 - 2.0 * u;
    }
    let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u);
    ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
}

/// The direction at cosine `cos` from unit `dir` and azimuth `2 pi u`.
#[inline]
pub fn direction_at(dir: DVec3, cos: f64, u: f64) -> DVec3 {
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let (sp, cp) = crate::geometry::sin_cos_2pi(u);
    let (t, b) = coordinate_system(dir);
    (sin * cp * t + sin * sp * b + cos * dir).normalize()
}

/// The Paper BSDF's phase function: a backward and a forward HG lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoLobeHg {
    /// Mean cosine of the forward lobe, in [-1, 1].
    pub g_f: f64,
    /// Mean cosine of the backward lobe, in [-1, 1].
    pub g_b: f64,
    /// Weight of the backward lobe, in [0, 1]; the forward lobe has `1 - w_b`.
    pub w_b: f64,
}

impl TwoLobeHg {
    /// Phase function value (per steradian) at cosine `cos` between propagation directions.
    #[inline]
    pub fn eval(&self, cos: f64) -> f64 {
        self.w_b * hg(cos, self.g_b) + (1.0 - self.w_b) * hg(cos, self.g_f)
    }
    /// The mixture's mean cosine `w_b g_b + w_f g_f` (for the reduced scattering coefficient).
    pub fn mean_cosine(&self) -> f64 {
        self.w_b * self.g_b + (1.0 - self.w_b) * self.g_f
    }
    /// Draws a new propagation direction after scattering from propagation
    /// direction `dir`: lobe by `uc`, cosine by `u[0]`, azimuth by `u[1]`. The
    /// density of the result is [`TwoLobeHg::eval`] of its cosine with `dir`.
    pub fn sample(&self, dir: DVec3, uc: f64, u: [f64; 2]) -> DVec3 {
        let g = if uc < self.w_b { self.g_b } else { self.g_f };
        direction_at(dir, sample_hg_cos(g, u[0]), u[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hg_normalised_and_mean_cosine() {
        for g in [-0.9, -0.3, 0.0, 0.5, 0.95] {
            let n = 200_000;
            let (mut norm, mut mean) = (0.0, 0.0);
            for i in 0..n {
                let c = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                let p = hg(c, g) * 2.0 * PI * 2.0 / n as f64;
                norm += p;
                mean += p * c;
            }
            assert!((norm - 1.0).abs() < 1e-3, "g={g}: {norm}");
            assert!((mean - g).abs() < 1e-3, "g={g}: {mean}");
        }
    }

    #[test]
    fn hg_sampling_inverts_cdf() {
        // CDF of HG in cos: F(c) = (1-g^2)/(2g) [1/sqrt(1+g^2-2gc) - 1/(1+g)].
        for g in [-0.7f64, 0.3, 0.9] {
            for u in [0.05, 0.3, 0.6, 0.95] {
                let c = sample_hg_cos(g, u);
                let cdf = (1.0 - g * g) / (2.0 * g) * (1.0 / (1.0 + g * g - 2.0 * g * c).sqrt() - 1.0 / (1.0 + g));
                assert!(
                    (cdf - (1.0 - u)).abs() < 1e-9 || (cdf - u).abs() < 1e-9,
                    "g={g} u={u}: {cdf}"
                );
            }
        }
    }
}
