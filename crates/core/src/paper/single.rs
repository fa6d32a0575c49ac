//! Single scattering in a slab (Hanrahan & Krueger 1993, docs/design.md 4.4).
//!
//! A collimated beam that has entered with flux `F` per unit area (per unit
//! incident irradiance: `Att(wi)`) travels inside at cosine `mu_i`; at depth
//! `z` its scattered radiance per unit length toward the inside direction of
//! cosine `mu_o` is `sigma_s p F e^{-sigma_t z / mu_i} / (mu_i mu_o)`, which,
//! attenuated by `e^{-sigma_t z' / mu_o}` on the way to the exit face and
//! integrated over the depth, gives the radiance arriving at the exit face.
//! Crossing it multiplies radiance by `Att(wo) / eta_x^2` (transmittance times
//! the `n^2` law of radiance), hence
//!
//! reflection: `a p (1 - e^{-tau (1/mu_i + 1/mu_o)}) / (mu_i + mu_o)`,
//! transmission: `a p (e^{-tau/mu_o} - e^{-tau/mu_i}) / (mu_o - mu_i)`,
//!
//! times `Att(wi) Att(wo) / eta_x^2`. The functions here are the depth
//! integrals (the last fractions), written to be exact and finite at
//! `mu_i = mu_o` and for any `tau` (including `tau = inf`).

/// `(1 - e^{-tau (1/mu_i + 1/mu_o)}) / (mu_i + mu_o)`: the depth integral of
/// single-scattered light leaving through the face of entry. `mu_i, mu_o > 0`.
#[inline]
pub fn depth_reflection(tau: f64, mu_i: f64, mu_o: f64) -> f64 {
    let s = mu_i + mu_o;
    if s <= 0.0 {
        return 0.0;
    }
    if tau.is_infinite() {
        return 1.0 / s;
    }
    -(-tau * s / (mu_i * mu_o)).exp_m1() / s
}

/// `h(x) = (1 - e^{-x}) / x` with `h(0) = 1`, `x >= 0`.
#[inline]
fn h(x: f64) -> f64 {
    if x < 1e-8 {
        1.0 - 0.5 * x
    } else {
        -(-x).exp_m1() / x
    }
}

/// `(e^{-tau/mu_o} - e^{-tau/mu_i}) / (mu_o - mu_i)`: the depth integral of
/// single-scattered light leaving through the opposite face; its limit at
/// `mu_i = mu_o = mu` is `tau e^{-tau/mu} / mu^2`. Written as
/// `tau e^{-tau / max(mu)} h(tau |1/mu_i - 1/mu_o|) / (mu_i mu_o)`.
#[inline]
pub fn depth_transmission(tau: f64, mu_i: f64, mu_o: f64) -> f64 {
    if mu_i <= 0.0 || mu_o <= 0.0 || tau.is_infinite() {
        return 0.0;
    }
    let (a, b) = (1.0 / mu_i, 1.0 / mu_o);
    tau * (-tau * a.min(b)).exp() * h(tau * (a - b).abs()) / (mu_i * mu_o)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_integrals_against_quadrature() {
        for tau in [0.01, 0.3, 2.0, 15.0] {
            for (mi, mo) in [(0.3, 0.9), (0.9, 0.3), (0.5, 0.5), (0.5, 0.5 + 1e-9), (1.0, 0.05)] {
                let n = 200_000;
                let (mut r, mut t) = (0.0, 0.0);
                for k in 0..n {
                    let z = (k as f64 + 0.5) / n as f64 * tau;
                    let dz = tau / n as f64;
                    r += (-z / mi).exp() * (-z / mo).exp() * dz / (mi * mo);
                    t += (-z / mi).exp() * (-(tau - z) / mo).exp() * dz / (mi * mo);
                }
                let (rr, tt) = (depth_reflection(tau, mi, mo), depth_transmission(tau, mi, mo));
                assert!(
                    (rr - r).abs() < 1e-6 * r.max(1e-3),
                    "R tau={tau} {mi} {mo}: {rr} vs {r}"
                );
                assert!(
                    (tt - t).abs() < 1e-6 * t.max(1e-3),
                    "T tau={tau} {mi} {mo}: {tt} vs {t}"
                );
            }
        }
    }
}
