//! The measurements' approximations against the exact simulator: Kubelka
//! stacking of one sheet against a simulated pad of sheets with air gaps, the
//! lateral exit profile's total against the simulator's own reflectance, and
//! the opacity limits of the model.

use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::{Colour, DVec3, Distribution, PaperParams};
use paperbsdf_metrics::instrument::{self, luminance, Quality};
use paperbsdf_metrics::measure::{measure_model, Selection};
use paperbsdf_metrics::pad::{simulate_pad, Backing, PadConfig};
use paperbsdf_sim::{simulate_exit_profile, simulate_totals, Incidence, LateralConfig, SimConfig, Slab};

fn sheet(d: f64, sigma_s: f64, sigma_a: f64, m: f64) -> PaperParams {
    PaperParams {
        name: None,
        d,
        sigma_a: Colour::Scalar(sigma_a),
        sigma_s: Colour::Scalar(sigma_s),
        g_f: 0.8,
        g_b: -0.4,
        w_b: 0.2,
        eta_f: 1.5,
        eta_b: 1.5,
        m_f: m,
        m_b: m,
        dist_f: Distribution::Ggx,
        dist_b: Distribution::Ggx,
        face_scattering: Default::default(),
    }
}

/// Kubelka/Stokes stacking of the *simulated* sheet's diffuse totals against
/// the simulated pad: this tests the stacking (Lambertian light in the gaps),
/// not the model. Two sheets: a thin translucent one (where the gaps matter
/// most) and an office-like one, with unequal faces for the first.
#[test]
fn kubelka_stacking_matches_simulated_pad() {
    let mut thin = sheet(0.05, 80.0, 0.5, 0.3);
    thin.m_b = 0.1;
    let office = sheet(0.1, 250.0, 0.2, 0.15);
    for (name, p) in [("thin", thin), ("office", office)] {
        let slab = Slab::from_params(&p).unwrap();
        let cfg = PadConfig {
            samples: 1 << 16,
            batches: 16,
            seed: 3,
        };
        let one = simulate_pad(&slab, 1, Backing::Black, DVec3::Z, None, &cfg);
        let sc = SimConfig {
            samples: 1 << 16,
            ..SimConfig::default()
        };
        let front = simulate_totals(&slab, Incidence::Diffuse { front: true }, &sc).unwrap();
        let back = simulate_totals(&slab, Incidence::Diffuse { front: false }, &sc).unwrap();
        let (r_dir, t_dir) = (one.reflected.mean.0[0], one.transmitted.mean.0[0]);
        let (rf, rb, t) = (
            front.reflectance.mean.0[0],
            back.reflectance.mean.0[0],
            front.transmittance.mean.0[0],
        );
        let n = 6;
        let pad = simulate_pad(&slab, n, Backing::Black, DVec3::Z, None, &cfg);
        let kub = instrument::over_backing(r_dir, t_dir, rb, t, instrument::pad_reflectance_n(rf, rb, t, n - 1));
        let sim = pad.reflected.mean.0[0];
        let se = pad.reflected.stderr.0[0];
        // Statistical error: sigma of the pad about 1e-3 (printed); 0.01 is the tolerance.
        eprintln!("{name}: pad of {n}: stacking {kub:.4}, simulated {sim:.4} +- {se:.4}");
        assert!(se < 2.5e-3, "{name}: too noisy to test ({se})");
        assert!(
            (kub - sim).abs() < 0.01,
            "{name}: stacking {kub} vs simulated pad {sim}"
        );
        // A white backing (TAPPI's 89 %) the same way.
        let w = simulate_pad(&slab, 1, Backing::Lambertian(0.89), DVec3::Z, None, &cfg);
        let kub = instrument::over_backing(r_dir, t_dir, rb, t, 0.89);
        let sim = w.reflected.mean.0[0];
        eprintln!(
            "{name}: over 89 %: stacking {kub:.4}, simulated {sim:.4} +- {:.4}",
            w.reflected.stderr.0[0]
        );
        assert!((kub - sim).abs() < 0.01, "{name}: over backing {kub} vs {sim}");
    }
}

/// The lateral profile is the simulator's own walk: its total is the
/// simulator's reflectance for the same beam (two independent runs; 4 sigma).
#[test]
fn lateral_profile_total_is_the_reflectance() {
    let p = sheet(0.1, 250.0, 0.2, 0.15);
    let slab = Slab::from_params(&p).unwrap();
    let lc = LateralConfig {
        samples: 1 << 15,
        ..LateralConfig::default()
    };
    let prof = simulate_exit_profile(&slab, DVec3::Z, &lc).unwrap();
    let sum: f64 = prof.reflected[0].iter().sum();
    assert!((sum - prof.reflectance.0[0]).abs() < 1e-9);
    let tot = simulate_totals(&slab, Incidence::Collimated(DVec3::Z), &SimConfig::default()).unwrap();
    let (a, b) = (prof.reflectance.0[0], tot.reflectance.mean.0[0]);
    let se = (prof.reflectance_stderr.0[0].powi(2) + tot.reflectance.stderr.0[0].powi(2)).sqrt();
    assert!((a - b).abs() < 4.0 * se + 1e-4, "lateral {a} vs totals {b} (se {se})");
    // Light spreads symmetrically: the mean offset is zero within 4 sigma of the bins' spread.
    let mean: f64 = (0..prof.reflected[0].len())
        .map(|k| prof.bin_centre(k) * prof.reflected[0][k])
        .sum::<f64>()
        / sum;
    assert!(mean.abs() < 0.01, "mean lateral offset {mean} mm");
}

fn opacity(p: &PaperParams) -> f64 {
    let b = PaperBsdf::new(p).unwrap();
    measure_model(
        &b,
        Some(p),
        None,
        &Selection::parse("opacity_iso2471").unwrap(),
        &Quality::default(),
    )
    .opacity_iso2471
    .unwrap()
}

#[test]
fn opacity_limits() {
    // Optically thick: opaque.
    let thick = sheet(1.0, 3000.0, 0.1, 0.15);
    let o = opacity(&thick);
    eprintln!("thick sheet: opacity {o:.4} %");
    assert!(o > 99.9, "thick sheet: opacity {o}");
    // Non-scattering, non-absorbing, index-matched: invisible (R0 = 0).
    let mut clear = sheet(0.1, 0.0, 0.0, 0.0);
    clear.eta_f = 1.0;
    clear.eta_b = 1.0;
    let o = opacity(&clear);
    eprintln!("clear sheet: opacity {o:e} %");
    assert!(o.abs() < 1e-9, "clear sheet: opacity {o}");
    // Tends to 0 as scattering vanishes, and rises with it.
    let mut last = 0.0;
    for ss in [0.01, 0.1, 1.0, 10.0, 100.0] {
        let mut p = clear.clone();
        p.sigma_s = Colour::Scalar(ss);
        let o = opacity(&p);
        eprintln!("clear sheet with sigma_s {ss}: opacity {o:.4} %");
        assert!(o > last, "sigma_s {ss}: opacity {o} not above {last}");
        if ss == 0.01 {
            assert!(o < 0.1, "sigma_s 0.01: opacity {o}");
        }
        last = o;
    }
    // Increases with caliper.
    let mut last = 0.0;
    for d in [0.03, 0.05, 0.1, 0.2, 0.4] {
        let o = opacity(&sheet(d, 150.0, 0.2, 0.15));
        eprintln!("caliper {d} mm: opacity {o:.2} %");
        assert!(o > last + 0.05, "d {d}: opacity {o} not above {last}");
        last = o;
    }
}

/// The Y weights sum to 1, so a grey value's luminance is itself.
#[test]
fn luminance_of_grey() {
    assert!((luminance(paperbsdf_core::Rgb::splat(0.37)) - 0.37).abs() < 1e-12);
}
