//! Multiple scattering of the Paper BSDF: the total diffuse reflectance `R_d`
//! and transmittance `T_d` of a slab in the multipole diffusion model of
//! Donner & Jensen (2005), docs/design.md 4.5.
//!
//! The supplement (equations 2 and 4) gives, for `2n + 1` dipole pairs,
//! `R_d = a'/2 sum_i [sign(z_r,i) e^{-sigma_tr |z_r,i|} - sign(z_v,i) e^{-sigma_tr |z_v,i|}]`
//! and `T_d` with `d - z` in place of `z`, where
//! `z_r,i = 2 i P + l`, `z_v,i = 2 i P - l - 2 z_b(0)` and
//! `P = d + z_b(0) + z_b(d)`. For `0 < l <= d` the signs of every term with
//! `i != 0` are known (positive for `i > 0`, negative for `i < 0`), so the sum
//! over *all* pairs (`n -> infinity`, "until more pairs change nothing") is a
//! geometric series in `q = e^{-2 sigma_tr P}` with the closed form
//!
//! `R_d = a'/2 [e^{-s l} + e^{-s (l + 2 z_b0)} - G(l) - G(l + 2 z_b0)]`,
//! `T_d = a'/2 [e^{-s (d - l)} - e^{-s (d + l + 2 z_b0)} - G(d - l) + G(d + l + 2 z_b0)]`,
//!
//! with `s = sigma_tr` and `G(x) = 2 q sinh(s x) / (1 - q)`. This is exact for
//! the infinite multipole, costs a few exponentials, and stays accurate as
//! `sigma_tr -> 0` (`G(x) -> x / P`, where the finite sum would need
//! thousands of pairs): a non-absorbing slab then gives the 1D diffusion result
//! `R_d = a' (d + z_bd - l) / P`, `T_d = a' (l + z_b0) / P`, `R_d + T_d = a'`.
//! The tests compare it with the supplement's finite sum and with numerical
//! integration of `R(r)` and `T(r)` (equations 1 and 3).
//!
//! **Source depth.** The dipole model puts the real source at `l = 1/sigma_t'`.
//! When `1/sigma_t' > d` (a thin or weakly scattering sheet) the source lies
//! outside the slab and the closed forms go negative (docs/design.md 4.5). We use
//! instead [`source_depth`]: the mean depth of the first reduced-scattering
//! event *given that it happens inside the slab*,
//! `l = (1/sigma_t') (1 - x / (e^x - 1))` with `x = sigma_t' d`. It equals
//! `1/sigma_t'` to within `x e^{-x}` for a thick slab (less than 0.5% for
//! `x > 7`, i.e. for all realistic papers), tends to `d/2` for a thin one, and
//! is always in `(0, d/2]`, so `R_d` and `T_d` are never negative. How much
//! light reaches the diffusion source at all is then bounded separately (the
//! energy bound of [`crate::paper`]).

/// Depth of the diffusion source below the face of entry (see the module doc):
/// the conditional mean depth of the first reduced-scattering event in a slab
/// of thickness `d`, `(1/sigma_t') (1 - x/(e^x - 1))` with `x = sigma_t' d`.
/// `d / 2` when `sigma_t' = 0`.
pub fn source_depth(sigma_t_prime: f64, d: f64) -> f64 {
    let x = sigma_t_prime * d;
    if x < 1e-6 {
        // Series: d (1/2 - x/12 + ...).
        return d * (0.5 - x / 12.0);
    }
    let em1 = x.exp_m1();
    if !em1.is_finite() {
        return 1.0 / sigma_t_prime;
    }
    (1.0 - x / em1) / sigma_t_prime
}

/// `G(x) = 2 q sinh(s x) / (1 - q)` with `q = e^{-2 s P}` (its `s -> 0` limit `x / P`).
#[inline]
fn g_series(s: f64, x: f64, p: f64) -> f64 {
    if s * p < 1e-10 {
        return x / p;
    }
    // 2 q sinh(s x) = e^{-s (2P - x)} - e^{-s (2P + x)} = e^{-s (2P - x)} (1 - e^{-2 s x}).
    let num = (-s * (2.0 * p - x)).exp() * (-(-2.0 * s * x).exp_m1());
    let den = -(-2.0 * s * p).exp_m1();
    num / den
}

/// The inputs of the multipole closed forms for one slab and one face of entry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Multipole {
    /// Reduced albedo `a' = sigma_s' / sigma_t'`.
    pub alpha_p: f64,
    /// Effective transport coefficient `sigma_tr = sqrt(3 sigma_a sigma_t')`, 1/mm.
    pub sigma_tr: f64,
    /// Thickness `d`, mm.
    pub d: f64,
    /// Depth of the real source below the face of entry, mm, in `(0, d]`.
    pub l: f64,
    /// Extrapolation distance `z_b = 2 A D` of the face of entry, mm.
    pub zb_entry: f64,
    /// Extrapolation distance of the opposite face, mm.
    pub zb_exit: f64,
}

impl Multipole {
    /// The slab of reduced scattering `sigma_s'`, absorption `sigma_a`,
    /// thickness `d`, entered through a face with internal diffuse reflectance
    /// `rho_entry` and left through the other with `rho_exit`; source at
    /// [`source_depth`], `D = 1/(3 sigma_t')`, `A = (1 + rho)/(1 - rho)`,
    /// `z_b = 2 A D`. `None` when `sigma_t' = 0` (nothing scatters).
    pub fn new(sigma_s_prime: f64, sigma_a: f64, d: f64, rho_entry: f64, rho_exit: f64) -> Option<Self> {
        let st = sigma_s_prime + sigma_a;
        if !st.is_finite() || st <= 0.0 {
            return None;
        }
        let diff = 1.0 / (3.0 * st);
        let zb = |rho: f64| 2.0 * (1.0 + rho) / (1.0 - rho) * diff;
        Some(Multipole {
            alpha_p: sigma_s_prime / st,
            sigma_tr: (3.0 * sigma_a * st).sqrt(),
            d,
            l: source_depth(st, d),
            zb_entry: zb(rho_entry),
            zb_exit: zb(rho_exit),
        })
    }

    /// `(R_d, T_d)`: the flux leaving through the face of entry and through the
    /// opposite face per unit flux entering, summed over every dipole pair
    /// (closed form of the module doc). Requires `0 < l <= d`.
    pub fn rd_td(&self) -> (f64, f64) {
        let Multipole {
            alpha_p,
            sigma_tr: s,
            d,
            l,
            zb_entry: zb0,
            zb_exit: zbd,
        } = *self;
        let p = d + zb0 + zbd;
        let v = l + 2.0 * zb0;
        let rd = 0.5 * alpha_p * ((-s * l).exp() + (-s * v).exp() - g_series(s, l, p) - g_series(s, v, p));
        let w = d + l + 2.0 * zb0;
        let td = 0.5 * alpha_p * ((-s * (d - l)).exp() - (-s * w).exp() - g_series(s, d - l, p) + g_series(s, w, p));
        (rd.max(0.0), td.max(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conservative_limit_is_1d_diffusion() {
        let m = Multipole {
            alpha_p: 1.0,
            sigma_tr: 0.0,
            d: 0.1,
            l: 0.02,
            zb_entry: 0.03,
            zb_exit: 0.05,
        };
        let (r, t) = m.rd_td();
        let p = 0.1 + 0.03 + 0.05;
        assert!((r - (0.1 + 0.05 - 0.02) / p).abs() < 1e-12);
        assert!((t - (0.02 + 0.03) / p).abs() < 1e-12);
        // A tiny absorption changes it continuously.
        let m2 = Multipole { sigma_tr: 1e-6, ..m };
        let (r2, t2) = m2.rd_td();
        assert!((r2 - r).abs() < 1e-6 && (t2 - t).abs() < 1e-6);
    }

    #[test]
    fn source_depth_limits() {
        assert!((source_depth(1000.0, 1.0) - 1e-3).abs() < 1e-15);
        assert!((source_depth(1e-9, 0.2) - 0.1).abs() < 1e-9);
        for x in [0.1, 1.0, 3.0, 10.0] {
            let l = source_depth(x, 1.0);
            // Conditional mean of an exponential truncated to [0, 1], by quadrature.
            let n = 100_000;
            let (mut num, mut den) = (0.0, 0.0);
            for k in 0..n {
                let z = (k as f64 + 0.5) / n as f64;
                let w = (-x * z).exp();
                num += z * w;
                den += w;
            }
            assert!((l - num / den).abs() < 1e-8, "{x}: {l} vs {}", num / den);
        }
    }
}
