//! Phase functions: Henyey-Greenstein and the Paper BSDF's two-lobe mixture
//! (docs/design.md 4.2): `p(cos) = w_b HG(cos; g_b) + (1 - w_b) HG(cos; g_f)`, each
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
    /// The two lobes as `(g, weight)`, forward lobe first: `[(g_f, 1 - w_b), (g_b, w_b)]`.
    pub fn lobes(&self) -> [(f64, f64); 2] {
        [(self.g_f, 1.0 - self.w_b), (self.g_b, self.w_b)]
    }
    /// The lobes that are not deltas (`|g| < 1`), forward first, with their
    /// weights; a lobe with `|g| >= 1` (all its light in one direction) gets weight 0.
    pub fn smooth_part(&self) -> HgLobes {
        HgLobes::new(
            self.lobes()
                .map(|(g, w)| if g.abs() < 1.0 { (g, w) } else { (0.0, 0.0) }),
        )
    }
    /// Phase function value (per steradian) at cosine `cos` between
    /// propagation directions; a lobe with `|g| = 1` is a delta and adds
    /// nothing here (its weight is [`TwoLobeHg::lobes`]' for that lobe).
    #[inline]
    pub fn eval(&self, cos: f64) -> f64 {
        self.smooth_part().eval(cos)
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

/// A weighted sum of up to two Henyey-Greenstein lobes, `sum_k w_k HG(cos; g_k)`,
/// whose weights need not add up to 1 (the rest of the light may be a delta
/// part that the caller handles). This is the one evaluation of a lobe
/// mixture: the Paper BSDF and the simulator both use it.
///
/// `w HG(cos; g) = k / (q sqrt(q))` with `k = w (1 - g^2) / (4 pi)` and
/// `q = 1 + g^2 - 2 g cos`; [`HgLobes::ratio`] returns the mixture over one
/// denominator so that callers can fold the division into their own.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HgLobes {
    lobes: [(f64, f64); 2],
    coef: [(f64, f64, f64); 2],
    weight: f64,
}

impl HgLobes {
    /// The mixture of `lobes`, each `(g, weight)` with `|g| < 1` and weight
    /// `>= 0` (weight 0: an absent lobe, whatever its `g`). The order is kept:
    /// it decides which lobe [`HgLobes::pick`] returns for which number.
    pub fn new(lobes: [(f64, f64); 2]) -> Self {
        let lobes = lobes.map(|(g, w)| if w > 0.0 { (g, w) } else { (0.0, 0.0) });
        HgLobes {
            lobes,
            coef: lobes.map(|(g, w)| (w * (1.0 - g * g) / (4.0 * PI), 1.0 + g * g, 2.0 * g)),
            weight: lobes[0].1 + lobes[1].1,
        }
    }
    /// The lobes `(g, weight)` in the order given (absent ones `(0, 0)`).
    pub fn lobes(&self) -> [(f64, f64); 2] {
        self.lobes
    }
    /// Sum of the weights (the mixture's integral over the sphere).
    #[inline]
    pub fn weight(&self) -> f64 {
        self.weight
    }
    /// The mixture at cosine `cos` as `(numerator, denominator)`; an absent
    /// lobe has `k = 0`, `q = 1`.
    #[inline]
    pub fn ratio(&self, cos: f64) -> (f64, f64) {
        let [(k0, a0, b0), (k1, a1, b1)] = self.coef;
        let (q0, q1) = (a0 - b0 * cos, a1 - b1 * cos);
        let (d0, d1) = (q0 * q0.sqrt(), q1 * q1.sqrt());
        (k0 * d1 + k1 * d0, d0 * d1)
    }
    /// The mixture (per steradian) at cosine `cos`.
    #[inline]
    pub fn eval(&self, cos: f64) -> f64 {
        let (n, d) = self.ratio(cos);
        n / d
    }
    /// The `g` of the lobe chosen by `u` in [0, 1) with probability
    /// proportional to its weight (the first lobe for `u < w_0 / weight`).
    #[inline]
    pub fn pick(&self, u: f64) -> f64 {
        if u * self.weight < self.lobes[0].1 {
            self.lobes[0].0
        } else {
            self.lobes[1].0
        }
    }
    /// Draws a direction from unit `dir`: lobe by `uc` ([`HgLobes::pick`]),
    /// cosine by `u[0]`, azimuth by `u[1]`. Its density is
    /// [`HgLobes::eval`]` / `[`HgLobes::weight`] of its cosine with `dir`.
    pub fn sample(&self, dir: DVec3, uc: f64, u: [f64; 2]) -> DVec3 {
        direction_at(dir, sample_hg_cos(self.pick(uc), u[0]), u[1])
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

    #[test]
    fn mixture_matches_its_lobes() {
        let mix = HgLobes::new([(0.7, 0.25), (-0.4, 0.5)]);
        for c in [-1.0, -0.3, 0.0, 0.6, 1.0] {
            let want = 0.25 * hg(c, 0.7) + 0.5 * hg(c, -0.4);
            assert!((mix.eval(c) - want).abs() < 1e-14 * want, "{c}");
        }
        assert_eq!(mix.weight(), 0.75);
        assert_eq!(mix.pick(0.3), 0.7);
        assert_eq!(mix.pick(0.34), -0.4);
        // a delta lobe (|g| = 1) is left out of the smooth part
        let p = TwoLobeHg {
            g_f: 1.0,
            g_b: -0.3,
            w_b: 0.4,
        };
        assert_eq!(p.smooth_part().weight(), 0.4);
        assert!((p.eval(0.2) - 0.4 * hg(0.2, -0.3)).abs() < 1e-15);
        let q = TwoLobeHg {
            g_f: 0.8,
            g_b: -0.3,
            w_b: 0.4,
        };
        assert!((q.eval(0.2) - (0.4 * hg(0.2, -0.3) + 0.6 * hg(0.2, 0.8))).abs() < 1e-15);
    }
}
