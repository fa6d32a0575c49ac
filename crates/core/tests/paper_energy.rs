//! Energy, reciprocity, limits and robustness of every model over random
//! parameters within the full ranges of docs/design.md section 3 (unequal faces,
//! coatings, thin sheets, weak scattering, `g` near +-1, `m` near 0, both
//! face modes).
//!
//! **Energy is checked by integrating over each argument, with every
//! component and every delta lobe included:**
//!
//! - over `wo` for fixed `wi` (the physical albedo: the fraction of the flux
//!   arriving from `wi` that the sheet reflects and transmits):
//!   `int f(wi, wo) |cos wo| dwo`, estimated by importance sampling with
//!   directions `w'` drawn by the model's sampler started from `wi` (density
//!   `pdf(w', wi)`), weight `f(wi, w') |cos w'| / pdf(w', wi)`; a delta lobe's
//!   sample carries its weight as it is (deltas are symmetric);
//! - over `wi` for fixed `wo`: `int f(wi, wo) |cos wi| dwi`, the sampler's
//!   own weights `f(wi, wo) |cos wi| / pdf(wi, wo)`.
//!
//! Both in independent stratified batches, so each estimate has a measured
//! standard error. Neither integral assumes the model is reciprocal (the
//! reciprocity test checks that separately). A single rough interface in
//! radiance transport (`rough-dielectric`) compresses radiance by `eta^2` on
//! refraction into the denser side: its integral over `wi` is compared after
//! dividing each transmitted sample by that factor (flux, not radiance).

use paperbsdf_core::dielectric::RoughDielectricParams;
use paperbsdf_core::geometry::spherical_direction;
use paperbsdf_core::models::{LambertGlass, LambertGlassParams};
use paperbsdf_core::paper::{Component, PaperBsdf};
use paperbsdf_core::{Bsdf, Colour, DVec3, Distribution, FaceScattering, PaperParams, Rgb};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;

fn random_params(rng: &mut Pcg64) -> PaperParams {
    let pick = |rng: &mut Pcg64, special: f64, lo: f64, hi: f64| {
        if rng.gen::<f64>() < 0.15 {
            special
        } else {
            lo + (hi - lo) * rng.gen::<f64>()
        }
    };
    let logu = |rng: &mut Pcg64, lo: f64, hi: f64| (lo.ln() + (hi.ln() - lo.ln()) * rng.gen::<f64>()).exp();
    let colour = |rng: &mut Pcg64, lo: f64, hi: f64, zero: f64| {
        let one = |rng: &mut Pcg64| {
            if rng.gen::<f64>() < zero {
                0.0
            } else {
                logu(rng, lo, hi)
            }
        };
        if rng.gen::<bool>() {
            Colour::Scalar(one(rng))
        } else {
            Colour::Rgb([one(rng), one(rng), one(rng)])
        }
    };
    let dist = |rng: &mut Pcg64| {
        if rng.gen::<bool>() {
            Distribution::Ggx
        } else {
            Distribution::Beckmann
        }
    };
    // g near the ends of its range as often as anywhere.
    let g = |rng: &mut Pcg64| match rng.gen_range(0..6) {
        0 => 1.0 - logu(rng, 1e-9, 1e-2),
        1 => -1.0 + logu(rng, 1e-9, 1e-2),
        2 => [1.0, -1.0, 0.0][rng.gen_range(0..3)],
        _ => rng.gen_range(-1.0..1.0),
    };
    let m = |rng: &mut Pcg64| match rng.gen_range(0..8) {
        0 => 0.0,
        1 => logu(rng, 1e-10, 1e-3),
        _ => rng.gen_range(0.01..std::f64::consts::FRAC_PI_2),
    };
    PaperParams {
        name: None,
        d: logu(rng, 1e-3, 2.0),
        sigma_a: colour(rng, 1e-3, 50.0, 0.2),
        sigma_s: colour(rng, 1e-2, 2000.0, 0.05),
        g_f: g(rng),
        g_b: g(rng),
        w_b: pick(rng, 0.0, 0.0, 1.0),
        eta_f: pick(rng, 1.0, 1.0, 5.0),
        eta_b: pick(rng, 1.0, 1.0, 5.0),
        m_f: m(rng),
        m_b: m(rng),
        dist_f: dist(rng),
        dist_b: dist(rng),
        face_scattering: if rng.gen::<f64>() < 0.7 {
            FaceScattering::Multiple
        } else {
            FaceScattering::Single
        },
    }
}

/// A direction at polar angle `theta` (radians) on side `side`, random azimuth.
fn dir(theta: f64, side: f64, rng: &mut Pcg64) -> DVec3 {
    let w = spherical_direction(theta, rng.gen::<f64>() * std::f64::consts::TAU);
    DVec3::new(w.x, w.y, side * w.z)
}

/// Which argument is integrated.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Over {
    /// `int f(wi, wo) |cos wo| dwo` for fixed `wi`.
    Wo,
    /// `int f(wi, wo) |cos wi| dwi` for fixed `wo`.
    Wi,
}

/// `(reflected, transmitted, standard error of the total)` of the integral
/// `over` for the fixed direction `w`, by `batches` stratified batches of `n^2`
/// samples (module doc). `radiance_eta` is `Some(eta)` for a single interface
/// in radiance transport (module doc).
fn albedo(
    b: &dyn Bsdf,
    w: DVec3,
    over: Over,
    n: usize,
    batches: usize,
    seed: u64,
    radiance_eta: Option<f64>,
) -> (Rgb, Rgb, Rgb) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut means = Vec::new();
    for _ in 0..batches {
        let shift: [f64; 3] = [rng.gen(), rng.gen(), rng.gen()];
        let (mut r, mut t) = (Rgb::ZERO, Rgb::ZERO);
        for i in 0..n {
            for j in 0..n {
                let u1 = ((i as f64 + 0.5) / n as f64 + shift[1]).fract();
                let u2 = ((j as f64 + 0.5) / n as f64 + shift[2]).fract();
                let uc = (((i * n + j) as f64) * 0.618_033_988_749_895 + shift[0]).fract();
                let Some(s) = b.sample(w, uc, [u1, u2]) else { continue };
                let mut v = if s.flags.is_specular() || over == Over::Wi {
                    s.weight()
                } else {
                    // s.wi has density pdf(s.wi, w); integrand f(w, s.wi) |cos s.wi|.
                    b.eval(w, s.wi) * (s.wi.z.abs() / s.pdf)
                };
                let reflect = s.wi.z * w.z > 0.0;
                if let (Some(eta), false, true) = (radiance_eta, reflect, over == Over::Wi || s.flags.is_specular()) {
                    // Radiance in the viewer's medium over that in the light's
                    // (a delta lobe's sample weight is in the sampler's radiance
                    // convention whichever integral it stands in).
                    let ratio = if w.z > 0.0 { 1.0 / (eta * eta) } else { eta * eta };
                    v = v / ratio;
                }
                if reflect {
                    r += v;
                } else {
                    t += v;
                }
            }
        }
        let k = (n * n) as f64;
        means.push((r / k, t / k));
    }
    let k = batches as f64;
    let (mr, mt) = means.iter().fold((Rgb::ZERO, Rgb::ZERO), |a, m| (a.0 + m.0, a.1 + m.1));
    let (mr, mt) = (mr / k, mt / k);
    let mean = mr + mt;
    let var = means
        .iter()
        .fold(Rgb::ZERO, |a, m| a + (m.0 + m.1 - mean) * (m.0 + m.1 - mean))
        / (k - 1.0);
    (mr, mt, var.map(|v| (v / k).sqrt()))
}

/// Checks that neither integral exceeds `1 + 1e-3` (plus 4 standard errors of
/// the estimate) at one random direction on each side; returns the violations
/// and the number of screening alarms that the precise estimate cleared.
///
/// Two stages. The screening estimate (10 batches of 10 x 10 samples) is
/// cheap but its standard error, from only 10 batch means of a heavy-tailed
/// weight (delta lobes and strategies picked a few times per batch), is
/// itself uncertain: now and then it comes out far too small and a set with
/// an albedo of 0.999 reads 1.04 "+- 1e-3". Every alarm is therefore measured
/// again independently with 8 batches of 200 x 200 samples (batch means of
/// 40000 samples are close to normal, so their standard error is reliable),
/// and only what that estimate confirms is a violation. The tolerance is not
/// widened: the confirmed estimate must itself stay below `1 + 1e-3 + 4 sigma`.
fn check_energy(
    name: &str,
    b: &dyn Bsdf,
    rng: &mut Pcg64,
    radiance_eta: Option<f64>,
    what: &str,
) -> (Vec<String>, usize) {
    let mut bad = Vec::new();
    let mut cleared = 0;
    for side in [1.0, -1.0] {
        let theta = if rng.gen::<bool>() {
            rng.gen::<f64>() * 89.5
        } else {
            70.0 + 19.9 * rng.gen::<f64>()
        };
        let w = dir(theta.to_radians(), side, rng);
        for over in [Over::Wo, Over::Wi] {
            let (r, t, se) = albedo(b, w, over, 10, 10, rng.gen(), radiance_eta);
            let a = r + t;
            let seed2: u64 = rng.gen();
            for c in 0..3 {
                assert!(a.0[c].is_finite() && a.0[c] >= 0.0, "{name} {what} {w:?}: {a:?}");
            }
            if (0..3).all(|c| a.0[c] <= 1.0 + 1e-3 + 4.0 * se.0[c]) {
                continue;
            }
            let (r, t, se) = albedo(b, w, over, 200, 8, seed2, radiance_eta);
            let a = r + t;
            let mut confirmed = false;
            for c in 0..3 {
                if a.0[c] > 1.0 + 1e-3 + 4.0 * se.0[c] {
                    confirmed = true;
                    bad.push(format!(
                        "{name} over {over:?} at {w:?}: albedo {:.5} +- {:.1e} (channel {c}) {what}",
                        a.0[c], se.0[c]
                    ));
                }
            }
            if !confirmed {
                cleared += 1;
            }
        }
    }
    (bad, cleared)
}

/// No albedo above 1 for 2000 random parameter sets of the Paper BSDF and
/// of the reduced multilayer model, and 1000 of `lambert-glass` and of the
/// rough dielectric, by both integrals, light from both faces.
#[test]
fn no_albedo_above_one_by_either_integral() {
    let (bad, cleared): (Vec<String>, usize) = (0..2000u64)
        .into_par_iter()
        .map(|set| {
            let mut rng = Pcg64::seed_from_u64(1000 + set);
            let p = random_params(&mut rng);
            let what = format!("{p:?}");
            let mut out = check_energy("paper", &PaperBsdf::new(&p).unwrap(), &mut rng, None, &what);
            let mut add = |(b, c): (Vec<String>, usize)| {
                out.0.extend(b);
                out.1 += c;
            };
            add(check_energy(
                "reduced-multilayer",
                &PaperBsdf::reduced_multilayer(&p).unwrap(),
                &mut rng,
                None,
                &what,
            ));
            if set % 2 == 0 {
                let k_d = rng.gen::<f64>();
                let lg = LambertGlassParams {
                    name: None,
                    k_d: Colour::Scalar(k_d),
                    k_t: Colour::Scalar((1.0 - k_d) * rng.gen::<f64>()),
                    eta: p.eta_f,
                    m: p.m_f,
                    dist: p.dist_f,
                };
                let what = format!("{lg:?}");
                add(check_energy(
                    "lambert-glass",
                    &LambertGlass::new(&lg).unwrap(),
                    &mut rng,
                    None,
                    &what,
                ));
                let rd = RoughDielectricParams {
                    name: None,
                    eta: p.eta_b,
                    m: p.m_b,
                    dist: p.dist_b,
                };
                let what = format!("{rd:?}");
                let b = rd.build().unwrap();
                add(check_energy("rough-dielectric", &b, &mut rng, Some(rd.eta), &what));
            }
            out
        })
        .reduce(
            || (Vec::new(), 0),
            |mut a, b| {
                a.0.extend(b.0);
                (a.0, a.1 + b.1)
            },
        );
    eprintln!(
        "16000 checks: {} screening alarms cleared by the precise estimate, {} confirmed violations",
        cleared,
        bad.len()
    );
    assert!(bad.is_empty(), "{} albedos above 1:\n{}", bad.len(), bad.join("\n"));
}

/// The white furnace: a sheet that absorbs nothing, with energy-conserving
/// faces of any roughness (to 1.5), both distributions, indices to 3
/// (unequal faces, so coatings too), thickness 0.02 to 1 mm, reflects and
/// transmits exactly what arrives, from both faces, at 0 to 85 degrees.
/// Tolerance: the 2e-3 asked of the model plus 3 standard errors of the
/// estimate. An estimate of 10 x 24 x 16^2 samples that is off by more than
/// 2e-3 is measured again with 131072 samples (standard error about 2e-4 to
/// 1e-3) and judged on that, so the printed worst deviation is a precise one.
#[test]
fn white_furnace() {
    let (bad, worst): (Vec<String>, f64) = (0..160u64)
        .into_par_iter()
        .map(|set| {
            let mut rng = Pcg64::seed_from_u64(77 + set);
            let logu = |rng: &mut Pcg64, lo: f64, hi: f64| (lo.ln() + (hi.ln() - lo.ln()) * rng.gen::<f64>()).exp();
            let dist = |rng: &mut Pcg64| {
                if rng.gen::<bool>() {
                    Distribution::Ggx
                } else {
                    Distribution::Beckmann
                }
            };
            let p = PaperParams {
                name: None,
                d: logu(&mut rng, 0.02, 1.0),
                sigma_a: Colour::Scalar(0.0),
                sigma_s: Colour::Scalar(logu(&mut rng, 1.0, 3000.0)),
                g_f: rng.gen_range(-0.9..0.95),
                g_b: rng.gen_range(-0.9..0.5),
                w_b: rng.gen::<f64>(),
                eta_f: rng.gen_range(1.0..3.0),
                eta_b: if set % 3 == 0 { 1.5 } else { rng.gen_range(1.0..3.0) },
                m_f: if set % 7 == 0 { 0.0 } else { rng.gen_range(0.0..1.5) },
                m_b: rng.gen_range(0.0..1.5),
                dist_f: dist(&mut rng),
                dist_b: dist(&mut rng),
                face_scattering: FaceScattering::Multiple,
            };
            let b = PaperBsdf::new(&p).unwrap();
            let mut bad = Vec::new();
            let mut worst: f64 = 0.0;
            for side in [1.0, -1.0] {
                for deg in [0.0f64, 30.0, 60.0, 75.0, 85.0] {
                    let w = dir(deg.to_radians(), side, &mut rng);
                    for over in [Over::Wo, Over::Wi] {
                        let (r, t, se) = albedo(&b, w, over, 16, 24, rng.gen(), None);
                        let seed2: u64 = rng.gen();
                        let (mut r, mut t, mut se, mut a) = (r, t, se, (r + t).0[0]);
                        if (a - 1.0).abs() > 2e-3 {
                            // Re-measured independently and more precisely (as in
                            // `check_energy`): 8 batches of 128 x 128 samples.
                            (r, t, se) = albedo(&b, w, over, 128, 8, seed2, None);
                            a = (r + t).0[0];
                        }
                        worst = worst.max((a - 1.0).abs());
                        if (a - 1.0).abs() > 2e-3 + 3.0 * se.0[0] {
                            bad.push(format!(
                                "{deg} deg side {side} over {over:?}: R {:.4} + T {:.4} = {a:.5} +- {:.1e}\n  {p:?}",
                                r.0[0], t.0[0], se.0[0]
                            ));
                        }
                    }
                }
            }
            (bad, worst)
        })
        .reduce(
            || (Vec::new(), 0.0),
            |mut a, b| {
                a.0.extend(b.0);
                (a.0, a.1.max(b.1))
            },
        );
    eprintln!("white furnace: 160 sheets x 5 angles x 2 sides x 2 integrals, worst |R + T - 1| = {worst:.2e}");
    assert!(bad.is_empty(), "{} furnace violations:\n{}", bad.len(), bad.join("\n"));
}

fn rel_close(a: Rgb, b: Rgb, tol: f64) -> bool {
    (0..3).all(|c| (a.0[c] - b.0[c]).abs() <= tol * a.0[c].abs().max(b.0[c].abs()).max(1e-300))
}

/// `f(wi, wo) = f(wo, wi)` to 1e-9 relative, every component, in reflection
/// from both faces and in transmission both ways, for random parameters with
/// unequal faces (and the coatings they stand for), both face modes, and the
/// reduced multilayer model.
#[test]
fn reciprocity_with_unequal_faces() {
    let mut rng = Pcg64::seed_from_u64(11);
    let mut checked = 0;
    for _ in 0..300 {
        let p = random_params(&mut rng);
        for b in [PaperBsdf::new(&p).unwrap(), PaperBsdf::reduced_multilayer(&p).unwrap()] {
            for _ in 0..40 {
                let a = dir(rng.gen::<f64>() * 1.56, 1.0, &mut rng);
                let c = dir(rng.gen::<f64>() * 1.56, 1.0, &mut rng);
                for (s1, s2) in [(1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0)] {
                    let wi = DVec3::new(a.x, a.y, s1 * a.z);
                    let wo = DVec3::new(c.x, c.y, s2 * c.z);
                    for comp in Component::ALL {
                        let (f1, f2) = (
                            b.eval_components(wi, wo, comp.into()),
                            b.eval_components(wo, wi, comp.into()),
                        );
                        assert!(rel_close(f1, f2, 1e-9), "{comp} {wi:?} {wo:?}: {f1:?} vs {f2:?}\n{p:?}");
                    }
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 90_000);
}

/// Hemispherical albedo (over `wo`) of light at `theta_deg` from the front,
/// fine enough to compare two models within 1e-3.
fn front_albedo(p: &PaperParams, theta_deg: f64) -> Rgb {
    let b = PaperBsdf::new(p).unwrap();
    let t = theta_deg.to_radians();
    let w = DVec3::new(t.sin(), 0.0, t.cos());
    let (r, tr, _) = albedo(&b, w, Over::Wo, 128, 2, 5, None);
    r + tr
}

fn dev_a() -> PaperParams {
    PaperParams {
        name: None,
        d: 0.1,
        sigma_a: Colour::Scalar(0.6),
        sigma_s: Colour::Scalar(120.0),
        g_f: 0.85,
        g_b: -0.4,
        w_b: 0.15,
        eta_f: 1.45,
        eta_b: 1.45,
        m_f: 0.35,
        m_b: 0.35,
        dist_f: Distribution::Ggx,
        dist_b: Distribution::Ggx,
        face_scattering: FaceScattering::Multiple,
    }
}

/// The limits are continuous: `m = 1e-9` is `m = 0` (within 0.005 in albedo),
/// `g = 1` is `g = 0.999` (within 0.01), `sigma_s = 1e-9` is `sigma_s = 0`,
/// and a very thick sheet is a thick one, in both face modes.
#[test]
fn limits_are_continuous() {
    for fs in [FaceScattering::Multiple, FaceScattering::Single] {
        for theta in [0.0, 45.0, 80.0] {
            let base = PaperParams {
                face_scattering: fs,
                ..dev_a()
            };
            let cases: [(&str, PaperParams, PaperParams, f64); 5] = [
                (
                    "m -> 0 (front)",
                    PaperParams {
                        m_f: 1e-9,
                        ..base.clone()
                    },
                    PaperParams {
                        m_f: 0.0,
                        ..base.clone()
                    },
                    0.005,
                ),
                (
                    "m -> 0 (both, thin)",
                    PaperParams {
                        m_f: 1e-9,
                        m_b: 1e-9,
                        d: 0.01,
                        sigma_s: Colour::Scalar(5.0),
                        ..base.clone()
                    },
                    PaperParams {
                        m_f: 0.0,
                        m_b: 0.0,
                        d: 0.01,
                        sigma_s: Colour::Scalar(5.0),
                        ..base.clone()
                    },
                    0.005,
                ),
                (
                    "g -> 1",
                    PaperParams {
                        g_f: 0.999,
                        g_b: 0.999,
                        ..base.clone()
                    },
                    PaperParams {
                        g_f: 1.0,
                        g_b: 1.0,
                        ..base.clone()
                    },
                    0.01,
                ),
                (
                    "sigma_s -> 0",
                    PaperParams {
                        sigma_s: Colour::Scalar(1e-9),
                        ..base.clone()
                    },
                    PaperParams {
                        sigma_s: Colour::Scalar(0.0),
                        ..base.clone()
                    },
                    0.005,
                ),
                (
                    "d -> inf",
                    PaperParams { d: 1e3, ..base.clone() },
                    PaperParams { d: 1e6, ..base.clone() },
                    0.005,
                ),
            ];
            for (what, a, b, tol) in cases {
                let (x, y) = (front_albedo(&a, theta), front_albedo(&b, theta));
                for c in 0..3 {
                    assert!(
                        (x.0[c] - y.0[c]).abs() <= tol,
                        "{what} ({fs:?}, {theta} deg): {} vs {}",
                        x.0[c],
                        y.0[c]
                    );
                }
            }
        }
    }
}

fn dir_strategy() -> impl Strategy<Value = DVec3> {
    prop_oneof![
        (0.0f64..1.0, 0.0f64..std::f64::consts::TAU, prop::bool::ANY).prop_map(|(c, phi, up)| {
            let s = (1.0 - c * c).sqrt();
            DVec3::new(s * phi.cos(), s * phi.sin(), if up { c } else { -c })
        }),
        // Grazing, including exactly in the plane.
        (
            prop_oneof![Just(0.0f64), Just(1e-300), Just(1e-12), Just(-1e-12), Just(1e-6)],
            0.0f64..std::f64::consts::TAU
        )
            .prop_map(|(z, phi): (f64, f64)| {
                let s = (1.0 - z * z).sqrt();
                DVec3::new(s * phi.cos(), s * phi.sin(), z)
            }),
        Just(DVec3::Z),
        Just(-DVec3::Z),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]
    #[test]
    fn never_nan_inf_or_negative(seed in 0u64..1_000_000, wi in dir_strategy(), wo in dir_strategy(), u in prop::array::uniform3(0.0f64..1.0)) {
        let mut rng = Pcg64::seed_from_u64(seed);
        let p = random_params(&mut rng);
        for b in [PaperBsdf::new(&p).unwrap(), PaperBsdf::reduced_multilayer(&p).unwrap()] {
            let f = b.eval(wi, wo);
            prop_assert!(f.is_finite() && f.0.iter().all(|&v| v >= 0.0), "eval {:?}", f);
            for c in Component::ALL {
                let f = b.eval_components(wi, wo, c.into());
                prop_assert!(f.is_finite() && f.0.iter().all(|&v| v >= 0.0), "{} {:?}", c, f);
            }
            let pdf = b.pdf(wi, wo);
            prop_assert!(pdf.is_finite() && pdf >= 0.0, "pdf {}", pdf);
            if let Some(s) = b.sample(wo, u[0], [u[1], u[2]]) {
                prop_assert!(s.pdf > 0.0 && s.pdf.is_finite());
                prop_assert!(s.f.is_finite() && s.f.0.iter().all(|&v| v >= 0.0));
                prop_assert!((s.wi.length() - 1.0).abs() < 1e-9);
                prop_assert!(s.weight().is_finite());
            }
        }
    }
}

/// `albedo_from` (what `paperbsdf albedo` prints) agrees with an independent
/// quadrature of `eval` over the outgoing hemispheres to 2e-3, for sheets
/// without delta lobes or very narrow ones (rough faces, m >= 0.2, so a
/// 400 x 800 midpoint rule in `(sqrt(mu), phi)` resolves every lobe), unequal
/// faces, thin and thick, light at 0 to 80 degrees from both faces.
#[test]
fn albedo_agrees_with_quadrature_of_eval() {
    let cases = [
        dev_a(),
        PaperParams {
            d: 0.03,
            sigma_s: Colour::Scalar(15.0),
            eta_f: 1.9,
            m_f: 0.45,
            m_b: 0.8,
            dist_b: Distribution::Beckmann,
            ..dev_a()
        },
        PaperParams {
            sigma_a: Colour::Rgb([0.2, 1.0, 5.0]),
            eta_b: 2.2,
            m_f: 0.25,
            face_scattering: FaceScattering::Single,
            ..dev_a()
        },
    ];
    cases.par_iter().for_each(|p| {
        let b = PaperBsdf::new(p).unwrap();
        for side in [1.0, -1.0] {
            for deg in [0.0f64, 40.0, 80.0] {
                let t = deg.to_radians();
                let wi = DVec3::new(t.sin(), 0.0, side * t.cos());
                let (r, tr) = paperbsdf_core::bsdf::albedo_from(&b, wi, 512);
                let n = 400;
                let mut q = Rgb::ZERO;
                for h in [1.0, -1.0] {
                    for i in 0..n {
                        let s = (i as f64 + 0.5) / n as f64;
                        let mu = s * s;
                        let st = (1.0 - mu * mu).sqrt();
                        for j in 0..2 * n {
                            let phi = (j as f64 + 0.5) / (2 * n) as f64 * std::f64::consts::TAU;
                            let wo = DVec3::new(st * phi.cos(), st * phi.sin(), h * mu);
                            // dw |cos| = mu d(mu) dphi = 2 s^3 ds dphi.
                            q += b.eval(wi, wo) * (2.0 * s * s * s / n as f64 * std::f64::consts::TAU / (2 * n) as f64);
                        }
                    }
                }
                let a = r + tr;
                for c in 0..3 {
                    assert!(
                        (a.0[c] - q.0[c]).abs() < 2e-3,
                        "{deg} deg side {side}: albedo {} vs quadrature {}\n{p:?}",
                        a.0[c],
                        q.0[c]
                    );
                }
            }
        }
    });
}
