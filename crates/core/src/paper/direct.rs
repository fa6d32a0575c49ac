//! The angular spread of light that crosses a sheet unscattered (docs/design.md
//! 4.6), shared by the Paper BSDF's direct transmission and the sheet
//! transmission of the `lambert-glass` model.
//!
//! **Approximation (ours, not the paper's).** Light that crosses two rough
//! interfaces without scattering in between is deviated twice. For small
//! slopes, a facet of slope `s` on a face of index `eta` deviates the final
//! (outside) direction by `(eta - 1) s`, whether it is met on the way in or
//! on the way out (a thin prism: deviation `(n - 1)` times the wedge angle).
//! The exit direction's projection on the sheet plane, `p_o = (wo.x, wo.y)`,
//! is therefore spread around the smooth-refraction point `c` by the
//! difference of two independent slopes scaled by `eta_k - 1`. We model that
//! spread by a 2D kernel on the projected disk of the slope family of the
//! faces (GGX slopes `beta^2 / (pi (r^2 + beta^2)^2)`, or Gaussian
//! `e^{-r^2/beta^2} / (pi beta^2)` when both rough faces are Beckmann) with
//! `beta^2 = ((eta_f - 1) m_f)^2 + ((eta_b - 1) m_b)^2` (variances of
//! independent slopes add; exact for Beckmann in the small-slope limit). An
//! index-matched face (`eta = 1`) does not deviate light, whatever its `m`;
//! two faces with `beta = 0` give a delta lobe.
//!
//! Area on the projected disk is projected solid angle (`dp = |cos| dw`), so
//! `f = W k(|p_o - c|)` has albedo `W int_disk k <= W` (mass beyond the disk
//! is light that cannot leave, and is lost): energy is bounded by the weight
//! `W` alone. With equal indices `c = -(wi.x, wi.y)` and the kernel depends on
//! `|p_o + p_i|` only, which is symmetric under `wi <-> wo`: reciprocal.

use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// The slope family of the kernel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KernelShape {
    /// No spread: a delta lobe (smooth or index-matched faces).
    Delta,
    /// GGX slopes of width `beta`.
    Ggx(f64),
    /// Gaussian (Beckmann) slopes of width `beta`.
    Gauss(f64),
}

/// The kernel of a sheet: its shape and the index ratio `eta_x / eta_e` that
/// maps the projected incident direction to the centre of the lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SheetKernel {
    /// Shape and width.
    pub shape: KernelShape,
}

impl SheetKernel {
    /// Kernel of two faces `(eta, m, is_beckmann)`; a face with `m = 0` or `eta = 1` adds no spread.
    pub fn new(faces: [(f64, f64, bool); 2]) -> Self {
        let mut beta2 = 0.0;
        let mut all_beckmann = true;
        for (eta, m, beck) in faces {
            let b = (eta - 1.0) * m;
            if b > 0.0 {
                beta2 += b * b;
                all_beckmann &= beck;
            }
        }
        let shape = if beta2 <= 0.0 {
            KernelShape::Delta
        } else if all_beckmann {
            KernelShape::Gauss(beta2.sqrt())
        } else {
            KernelShape::Ggx(beta2.sqrt())
        };
        SheetKernel { shape }
    }

    /// Kernel value (per unit area of the projected disk) at distance `r`.
    #[inline]
    pub fn k(&self, r: f64) -> f64 {
        match self.shape {
            KernelShape::Delta => 0.0,
            KernelShape::Ggx(b) => {
                let t = r * r + b * b;
                b * b / (PI * t * t)
            }
            KernelShape::Gauss(b) => (-(r * r) / (b * b)).exp() / (PI * b * b),
        }
    }

    /// Draws an offset on the plane with density [`SheetKernel::k`] of its length.
    #[inline]
    pub fn sample_offset(&self, u: [f64; 2]) -> DVec2 {
        let (s, c) = crate::geometry::sin_cos_2pi(u[1]);
        self.radius_at(u[0]) * DVec2::new(c, s)
    }

    /// The kernel's mass within radius `r` (its CDF in `r`; 1 for a delta).
    #[inline]
    pub fn cdf(&self, r: f64) -> f64 {
        let r2 = r * r;
        match self.shape {
            KernelShape::Delta => 1.0,
            KernelShape::Ggx(b) => r2 / (r2 + b * b),
            KernelShape::Gauss(b) => -(-r2 / (b * b)).exp_m1(),
        }
    }

    /// The radius at which [`SheetKernel::cdf`] reaches `u` in [0, 1) (the
    /// inverse used by [`SheetKernel::sample_offset`]).
    #[inline]
    pub fn radius_at(&self, u: f64) -> f64 {
        match self.shape {
            KernelShape::Delta => 0.0,
            KernelShape::Ggx(b) => b * (u / (1.0 - u).max(1e-300)).sqrt(),
            KernelShape::Gauss(b) => b * (-(-u).ln_1p()).max(0.0).sqrt(),
        }
    }

    /// Whether the lobe is a delta.
    pub fn is_delta(&self) -> bool {
        self.shape == KernelShape::Delta
    }

    /// Density per unit projected area of `p_o` given the incident
    /// projection `p_i = -(wi.x, wi.y)` and the ratio `r = eta_x / eta_e`.
    #[inline]
    pub fn eval(&self, p_i: DVec2, p_o: DVec2, ratio: f64) -> f64 {
        self.k((p_o - p_i * ratio).length())
    }

    /// Draws `wi` on side `sign_i` (+1 above, -1 below) for a viewer `wo` so that
    /// the density of `p_i` is `eval(p_i, p_o, ratio) ratio^2` per unit area;
    /// `None` if the point falls outside the disk.
    #[inline]
    pub fn sample_wi(&self, wo: DVec3, sign_i: f64, ratio: f64, u: [f64; 2]) -> Option<DVec3> {
        let p_o = DVec2::new(wo.x, wo.y);
        let p_i = (p_o - self.sample_offset(u)) / ratio;
        let r2 = p_i.length_squared();
        if r2 >= 1.0 {
            return None;
        }
        Some(DVec3::new(-p_i.x, -p_i.y, sign_i * (1.0 - r2).sqrt()))
    }

    /// Solid-angle density of [`SheetKernel::sample_wi`].
    #[inline]
    pub fn pdf_wi(&self, wi: DVec3, wo: DVec3, ratio: f64) -> f64 {
        let p_i = DVec2::new(-wi.x, -wi.y);
        let p_o = DVec2::new(wo.x, wo.y);
        self.eval(p_i, p_o, ratio) * ratio * ratio * wi.z.abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernels_normalised_on_the_plane() {
        for shape in [KernelShape::Ggx(0.05), KernelShape::Gauss(0.05)] {
            let k = SheetKernel { shape };
            // int_0^inf 2 pi r k(r) dr with r = t/(1-t).
            let n = 200_000;
            let mut s = 0.0;
            for i in 0..n {
                let t = (i as f64 + 0.5) / n as f64;
                let r = t / (1.0 - t);
                s += 2.0 * PI * r * k.k(r) / ((1.0 - t) * (1.0 - t)) / n as f64;
            }
            assert!((s - 1.0).abs() < 1e-4, "{shape:?}: {s}");
        }
    }
}
