//! The next-event estimator against closed forms, and RGB handling.
//!
//! Single scattering (Hanrahan & Krueger 1993): with a tiny albedo `a`, higher
//! orders are `O(a)` relative, so `f / a` is the single-scattering kernel to
//! within `a`. A sheet with `eta_b = 1` and a smooth front of `eta_f = eta` is a
//! medium of index 1 under a smooth film of index `eta` (the coating of
//! `paperbsdf_core::sheet`), with an index-matched back; the only
//! single-scattering reflection path is in through the film, scatter, out
//! through the film, and directions inside are those outside, so exactly
//! `f_r = Tf(mu_i) Tf(mu_o) a p(cos_s) (1 - exp(-tau (1/mu_i + 1/mu_o))) / (mu_i + mu_o)`
//! with the film's transmittance `Tf = (1 - F)^2 / (1 - F^2) = (1 - F) / (1 + F)`
//! (incoherent multiple reflections between two interfaces of the same Fresnel
//! reflectance `F(mu)`, Born & Wolf 1.6), docs/design.md 4.4 with `eta = 1` inside.
//! This checks the coating's two interfaces, their bounces and the radiance
//! factors of its refractions. With both faces index-matched,
//! `f_t = a p (exp(-tau/mu_o) - exp(-tau/mu_i)) / (mu_o - mu_i)`.
//! Tolerance: 4 standard errors plus `2 a` relative for the multiple scattering.

mod support;

use paperbsdf_core::fresnel::fresnel_dielectric;
use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::phase::TwoLobeHg;
use paperbsdf_core::{Colour, DVec3, Distribution, PaperParams};
use paperbsdf_sim::{simulate_bsdf, simulate_totals, Incidence, SimConfig, Slab};

/// The phase function of [`params`].
const PHASE: TwoLobeHg = TwoLobeHg {
    g_f: 0.6,
    g_b: -0.3,
    w_b: 0.3,
};

/// A sheet of thickness 0.1 with albedo `a`, optical thickness `tau`, smooth
/// faces and the phase function [`PHASE`].
fn params(a: f64, tau: f64, eta_f: f64, eta_b: f64) -> PaperParams {
    PaperParams {
        name: None,
        d: 0.1,
        sigma_a: Colour::Scalar(tau / 0.1 * (1.0 - a)),
        sigma_s: Colour::Scalar(tau / 0.1 * a),
        g_f: PHASE.g_f,
        g_b: PHASE.g_b,
        w_b: PHASE.w_b,
        eta_f,
        eta_b,
        m_f: 0.0,
        m_b: 0.0,
        dist_f: Distribution::Ggx,
        dist_b: Distribution::Ggx,
        face_scattering: paperbsdf_core::FaceScattering::Single,
    }
}

/// Transmittance of a smooth film of index `eta` in air (module doc).
fn film(mu: f64, eta: f64) -> f64 {
    let f = fresnel_dielectric(mu, eta);
    (1.0 - f) / (1.0 + f)
}

/// Single-scattering reflection of a medium of index 1 under a smooth film of
/// index `eta` (module doc): inside, light propagates along `-wi` and leaves along `wo`.
fn film_reflection(wi: DVec3, wo: DVec3, a: f64, tau: f64, eta: f64) -> f64 {
    let (mi, mo) = (wi.z, wo.z);
    film(mi, eta) * film(mo, eta) * a * PHASE.eval((-wi).dot(wo)) * (1.0 - (-tau * (1.0 / mi + 1.0 / mo)).exp())
        / (mi + mo)
}

/// Simulates `f` from `theta_i` toward `tos` (reflection or transmission) and
/// checks each value against `want(wi, wo)` within 4 standard errors plus `2 a`
/// relative (module doc), with a standard error below 1 %.
fn check_single_scattering(
    slab: &Slab,
    what: &str,
    (ti, tos): (f64, &[f64]),
    transmission: bool,
    (a, seed): (f64, u64),
    want: impl Fn(DVec3, DVec3) -> f64,
) {
    let wos: Vec<_> = tos
        .iter()
        .map(|&o| in_plane_directions(ti, o, transmission).1)
        .collect();
    let (wi, _) = in_plane_directions(ti, 0.0, false);
    let cfg = SimConfig {
        samples: 1 << 17,
        batches: 32,
        seed,
        ..Default::default()
    };
    let run = simulate_bsdf(slab, wi, &wos, &cfg).unwrap();
    for (k, &wo) in wos.iter().enumerate() {
        let want = want(wi, wo);
        let (m, se) = (run.f[k].mean.0[0], run.f[k].stderr.0[0]);
        eprintln!(
            "{what} theta_o {}: sim {m:.6e} +- {se:.2e}, closed form {want:.6e}",
            tos[k]
        );
        assert!(
            (m - want).abs() <= 4.0 * se + 2.0 * a * want,
            "theta_o {}: {m} +- {se} vs {want}",
            tos[k]
        );
        assert!(se < 0.01 * want);
    }
}

#[test]
fn single_scattering_reflection_through_a_smooth_coating() {
    let (a, tau, eta) = (1e-3, 0.8, 1.5);
    let slab = Slab::from_params(&params(a, tau, eta, 1.0)).unwrap();
    check_single_scattering(
        &slab,
        "R",
        (35.0, &[-70.0, -20.0, 10.0, 50.0]),
        false,
        (a, 5),
        |wi, wo| film_reflection(wi, wo, a, tau, eta),
    );
}

#[test]
fn single_scattering_transmission_without_interfaces() {
    let (a, tau) = (1e-3, 1.2);
    let slab = Slab::from_params(&params(a, tau, 1.0, 1.0)).unwrap();
    check_single_scattering(
        &slab,
        "T",
        (20.0, &[-60.0, -20.0, 20.0, 45.0]),
        true,
        (a, 6),
        |wi, wo| {
            let (mi, mo) = (wi.z, -wo.z);
            let frac = if (mo - mi).abs() < 1e-9 {
                tau * (-tau / mi).exp() / (mi * mi)
            } else {
                ((-tau / mo).exp() - (-tau / mi).exp()) / (mo - mi)
            };
            a * PHASE.eval((-wi).dot(wo)) * frac
        },
    );
}

#[test]
fn unscattered_light_and_fresnel_totals() {
    // No medium at all between two smooth faces: R and T from the incoherent
    // sum of multiple reflections, R = F + (1-F)^2 F / (1 - F^2), T = (1-F)^2 / (1 - F^2)
    // (the inside angle sees the same F by reciprocity of Fresnel).
    let mut p = params(0.5, 0.0, 1.5, 1.5);
    p.sigma_a = Colour::Scalar(0.0);
    p.sigma_s = Colour::Scalar(0.0);
    let slab = Slab::from_params(&p).unwrap();
    let (wi, _) = in_plane_directions(40.0, 0.0, false);
    let f = fresnel_dielectric(wi.z, 1.5);
    let t = simulate_totals(
        &slab,
        Incidence::Collimated(wi),
        &SimConfig {
            samples: 1 << 16,
            batches: 32,
            seed: 8,
            ..Default::default()
        },
    )
    .unwrap();
    let (r_want, t_want) = (
        f + (1.0 - f).powi(2) * f / (1.0 - f * f),
        (1.0 - f).powi(2) / (1.0 - f * f),
    );
    let (r, rse) = (t.reflectance.mean.0[0], t.reflectance.stderr.0[0]);
    let (tt, tse) = (t.transmittance.mean.0[0], t.transmittance.stderr.0[0]);
    eprintln!("R {r} +- {rse} ({r_want}), T {tt} +- {tse} ({t_want})");
    assert!((r - r_want).abs() <= 4.0 * rse + 1e-12 && (tt - t_want).abs() <= 4.0 * tse + 1e-12);
    assert!((r + tt - 1.0).abs() < 1e-9);
}

#[test]
fn rgb_channels_are_independent_walks() {
    // Channel 0 of an RGB run uses the same random streams as a scalar run with
    // channel 0's parameters (identical numbers); the other channels agree with
    // scalar runs of their parameters within 4 combined standard errors.
    let mut p = support::params("devA.json");
    p.d = 0.04;
    let s_rgb = [120.0, 60.0, 20.0];
    let a_rgb = [0.6, 2.0, 8.0];
    p.sigma_s = Colour::Rgb(s_rgb);
    p.sigma_a = Colour::Rgb(a_rgb);
    let slab = Slab::from_params(&p).unwrap();
    assert!(slab.rgb);
    let (wi, wo_r) = in_plane_directions(30.0, -10.0, false);
    let (_, wo_t) = in_plane_directions(30.0, 10.0, true);
    let cfg = SimConfig {
        samples: 8192,
        batches: 32,
        seed: 12,
        ..Default::default()
    };
    let rgb = simulate_bsdf(&slab, wi, &[wo_r, wo_t], &cfg).unwrap();
    for c in 0..3 {
        let mut q = p.clone();
        q.sigma_s = Colour::Scalar(s_rgb[c]);
        q.sigma_a = Colour::Scalar(a_rgb[c]);
        let one = simulate_bsdf(&Slab::from_params(&q).unwrap(), wi, &[wo_r, wo_t], &cfg).unwrap();
        for k in 0..2 {
            let (m, se) = (rgb.f[k].mean.0[c], rgb.f[k].stderr.0[c]);
            let (m1, se1) = (one.f[k].mean.0[0], one.f[k].stderr.0[0]);
            eprintln!("channel {c} target {k}: rgb {m:.5} +- {se:.5}, scalar {m1:.5} +- {se1:.5}");
            if c == 0 {
                assert_eq!(m, m1, "channel 0 must reproduce the scalar run exactly");
            } else {
                assert!(
                    (m - m1).abs() <= 4.0 * (se * se + se1 * se1).sqrt(),
                    "channel {c}: {m} +- {se} vs {m1} +- {se1}"
                );
            }
        }
    }
    // The channels differ as the media do: the least absorbing, most scattering channel reflects most.
    assert!(rgb.f[0].mean.0[0] > rgb.f[0].mean.0[2]);
}

#[test]
fn scattering_orders_sum_to_f_and_order_one_is_single_scattering() {
    // Same sheet as the single-scattering test but a white medium (albedo 0.9):
    // the order-1 part must still be the closed form exactly, and the orders sum to f.
    let (a, tau, eta) = (0.9, 0.8, 1.5);
    let slab = Slab::from_params(&params(a, tau, eta, 1.0)).unwrap();
    let (wi, wo) = in_plane_directions(35.0, -20.0, false);
    let cfg = SimConfig {
        samples: 1 << 16,
        batches: 32,
        seed: 9,
        by_order: true,
        ..Default::default()
    };
    let run = simulate_bsdf(&slab, wi, &[wo], &cfg).unwrap();
    let o = run.by_order.as_ref().unwrap()[0];
    let sum = o[0].mean.0[0] + o[1].mean.0[0] + o[2].mean.0[0];
    assert!(
        (sum - run.f[0].mean.0[0]).abs() < 1e-12 * sum.max(1.0),
        "{sum} vs {}",
        run.f[0].mean.0[0]
    );
    assert_eq!(
        o[0].mean.0[0], 0.0,
        "a smooth face reflects only in the mirror direction"
    );
    let want = film_reflection(wi, wo, a, tau, eta);
    let (m, se) = (o[1].mean.0[0], o[1].stderr.0[0]);
    eprintln!(
        "order 1: {m:.5} +- {se:.5}, closed form {want:.5}; order 2+: {:.5}",
        o[2].mean.0[0]
    );
    assert!((m - want).abs() <= 4.0 * se, "{m} +- {se} vs {want}");
    assert!(o[2].mean.0[0] > 0.0);
}
