//! (d) Closed forms, computed here independently of the solver's grids and
//! phase coefficients (midpoint rules in mu and azimuth, core's `hg`):
//! - unscattered transmission `exp(-tau / mu)` (albedo 0, index-matched),
//!   within the diamond scheme's error `(tau / mu) x^2 / 12`, `x = dtau / mu`
//!   (crate::layer), and within 1e-4 relative;
//! - the single-scattering limit `tau -> 0`: collimated light at `mu0`,
//!   `R_1(mu0) = a integral_0^1 mu / (mu0 + mu) (1 - exp(-tau (1/mu0 + 1/mu))) P(-mu0, mu) dmu`,
//!   with `P(s, mu) = integral_0^(2 pi) p(s mu + sin0 sin cos phi) dphi`
//!   (Hanrahan & Krueger 1993, eq. 21, integrated over the hemisphere);
//! - semi-infinite isotropic scattering: the plane albedo
//!   `A(mu0) = 1 - H(mu0) sqrt(1 - a)` with Chandrasekhar's H-function
//!   (Radiative Transfer, 1950, ch. V, eqs. 38 and 45: `1/H(mu) = sqrt(1 - a) + (a/2) integral_0^1 mu' H(mu') / (mu + mu') dmu'`),
//!   and a conservative (`a = 1`) slab that reflects everything as `tau -> inf`.

use paperbsdf_core::phase::{hg, TwoLobeHg};
use paperbsdf_slab::{Discretisation, Face, Medium, Side, SlabSpec};
use std::f64::consts::PI;

fn matched(albedo: f64, tau: f64, phase: TwoLobeHg) -> SlabSpec {
    SlabSpec {
        medium: Medium { albedo, tau, phase },
        front: Face::Smooth { eta: 1.0 },
        back: Face::Smooth { eta: 1.0 },
    }
}

fn one_lobe(g: f64) -> TwoLobeHg {
    TwoLobeHg {
        g_f: g,
        g_b: 0.0,
        w_b: 0.0,
    }
}

#[test]
fn unscattered_light_is_exp_minus_tau_over_mu() {
    let disc = Discretisation {
        nodes: 24,
        ..Default::default()
    };
    let mut worst: f64 = 0.0;
    for tau in [0.01, 1.0, 10.0] {
        let sol = matched(0.0, tau, one_lobe(0.0)).solve(&disc).unwrap();
        let dtau = tau / 2f64.powi(sol.doublings as i32);
        let l = &sol.orders[0];
        assert!(l.r_top.amax() == 0.0);
        for j in 0..sol.outside.len() {
            let mu = sol.outside.mu[j];
            let want = (-tau / mu).exp();
            if want > 1e-12 {
                let err = (l.t_down[(j, j)] / want - 1.0).abs();
                let bound = tau / mu * (dtau / mu).powi(2) / 12.0;
                // plus the round-off of 2^k squarings
                let roundoff = 2f64.powi(sol.doublings as i32) * 4e-16;
                assert!(err <= 1.05 * bound + roundoff, "tau={tau} mu={mu}: {err} > {bound}");
                worst = worst.max(err);
            }
            assert!((0..sol.outside.len()).all(|o| o == j || l.t_down[(o, j)] == 0.0));
        }
    }
    println!("worst relative error of exp(-tau/mu): {worst:.2e}");
    assert!(worst < 1e-4, "{worst}");
}

/// `P(s, mu0, mu)`: the azimuth integral of the phase function, midpoint rule.
fn azimuth_integral(phase: &TwoLobeHg, c: f64, s: f64) -> f64 {
    let n = 1500;
    (0..n)
        .map(|k| {
            let phi = (k as f64 + 0.5) * 2.0 * PI / n as f64;
            let cos = c + s * phi.cos();
            let p: f64 = phase.lobes().iter().map(|(g, w)| w * hg(cos, *g)).sum();
            p * 2.0 * PI / n as f64
        })
        .sum()
}

/// First-order reflectance of a thin index-matched layer for collimated light at `mu0`.
fn single_scattering_reflectance(a: f64, tau: f64, phase: &TwoLobeHg, mu0: f64) -> f64 {
    let n = 1500;
    let s0 = (1.0 - mu0 * mu0).sqrt();
    (0..n)
        .map(|k| {
            let mu: f64 = (k as f64 + 0.5) / n as f64;
            let s = (1.0 - mu * mu).sqrt();
            let atten = 1.0 - (-tau * (1.0 / mu0 + 1.0 / mu)).exp();
            a * mu / (mu0 + mu) * atten * azimuth_integral(phase, -mu0 * mu, s0 * s) / n as f64
        })
        .sum()
}

#[test]
fn thin_layers_reflect_by_single_scattering() {
    let disc = Discretisation {
        nodes: 16,
        ..Default::default()
    };
    let tau = 1e-4;
    for phase in [
        one_lobe(0.0),
        one_lobe(0.6),
        TwoLobeHg {
            g_f: 0.8,
            g_b: -0.4,
            w_b: 0.2,
        },
    ] {
        let sol = matched(0.9, tau, phase).solve(&disc).unwrap();
        for j in [5, 10, 15] {
            let mu0 = sol.outside.mu[j];
            let (r, _) = sol.totals_collimated(Side::Front, j);
            let want = single_scattering_reflectance(0.9, tau, &phase, mu0);
            let rel = r / want - 1.0;
            println!("phase {phase:?} mu0 = {mu0:.3}: R = {r:.6e}, single scattering {want:.6e} ({rel:+.2e})");
            assert!(rel.abs() < 2e-3, "{rel}");
        }
    }
}

/// Chandrasekhar's H-function for isotropic scattering with albedo `a`, on a
/// 400-point midpoint grid, evaluated at `mu` by the same equation (Nystrom).
fn h_function(a: f64) -> impl Fn(f64) -> f64 {
    let n = 400;
    let x: Vec<f64> = (0..n).map(|k| (k as f64 + 0.5) / n as f64).collect();
    let mut h = vec![1.0; n];
    let root = (1.0 - a).sqrt();
    let step = move |x: &[f64], h: &[f64], mu: f64| -> f64 {
        let s: f64 = x.iter().zip(h).map(|(xk, hk)| xk * hk / (mu + xk)).sum::<f64>() / n as f64;
        1.0 / (root + 0.5 * a * s)
    };
    for _ in 0..2000 {
        let next: Vec<f64> = x.iter().map(|mu| step(&x, &h, *mu)).collect();
        let d = next.iter().zip(&h).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        h = next;
        if d < 1e-14 {
            break;
        }
    }
    move |mu| step(&x, &h, mu)
}

#[test]
fn semi_infinite_isotropic_plane_albedo() {
    let disc = Discretisation {
        nodes: 24,
        ..Default::default()
    };
    for a in [0.5, 0.9, 0.99] {
        let h = h_function(a);
        let sol = matched(a, 200.0, one_lobe(0.0)).solve(&disc).unwrap();
        let mut worst: f64 = 0.0;
        for j in 0..sol.outside.len() {
            let mu0 = sol.outside.mu[j];
            let (r, t) = sol.totals_collimated(Side::Front, j);
            assert!(t < 1e-12);
            let want = 1.0 - h(mu0) * (1.0 - a).sqrt();
            worst = worst.max((r - want).abs());
        }
        println!("a = {a}: worst |R - (1 - H sqrt(1 - a))| = {worst:.2e}");
        assert!(worst < 2e-4, "a = {a}: {worst}");
    }
}

#[test]
fn thick_conservative_layers_transmit_by_diffusion() {
    // Conservative isotropic scattering, diffuse incidence: T = 4 / (3 (tau + 2 q0)),
    // q0 = 0.710446 the extrapolation length of Milne's problem, asymptotically
    // exact for tau -> inf (van de Hulst, Multiple Light Scattering, 1980, ch. 14);
    // so R = 1 - T -> 1.
    let disc = Discretisation {
        nodes: 16,
        ..Default::default()
    };
    for tau in [1e2, 1e3, 1e4] {
        let sol = matched(1.0, tau, one_lobe(0.0)).solve(&disc).unwrap();
        let (r, t) = sol.totals_diffuse(Side::Front);
        let want = 4.0 / (3.0 * (tau + 2.0 * 0.710446));
        println!(
            "tau = {tau}: R = {r:.9}, T = {t:.6e}, diffusion {want:.6e} ({:+.2e})",
            t / want - 1.0
        );
        // round-off grows like 2^k eps over the k doublings (k = 27 for tau = 1e4)
        assert!((t / want - 1.0).abs() < 1e-3 && (r + t - 1.0).abs() < 1e-6, "{r} {t}");
    }
}
