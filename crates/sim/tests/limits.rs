//! Issue 16: the simulator's limits. Range errors for absurd settings, a
//! refusal of slabs too thick to represent, the achieved precision of an
//! adaptive run, and the work prediction checked against the collisions
//! actually simulated.

mod support;

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_sim::estimate::{check_slab, estimate_work, MAX_BATCHES};
use paperbsdf_sim::{simulate_bsdf, simulate_totals, Incidence, SimConfig, SimError, Slab};

fn slab(sigma_a: f64, sigma_s: f64, d: f64) -> Slab {
    let mut p = support::params("devA.json");
    p.sigma_a = paperbsdf_core::Colour::Scalar(sigma_a);
    p.sigma_s = paperbsdf_core::Colour::Scalar(sigma_s);
    p.d = d;
    Slab::from_params(&p).unwrap()
}

#[test]
fn absurd_settings_are_range_errors() {
    let s = slab(0.5, 100.0, 0.1);
    let (wi, _) = in_plane_directions(30.0, 0.0, false);
    let inc = Incidence::Collimated(wi);
    let too_many = SimConfig {
        batches: MAX_BATCHES + 1,
        ..Default::default()
    };
    assert!(matches!(
        simulate_totals(&s, inc, &too_many),
        Err(SimError::BadConfig { name: "batches", .. })
    ));
    let no_walks = SimConfig {
        rel_stderr: Some(0.1),
        max_samples: 0,
        ..Default::default()
    };
    assert!(matches!(
        simulate_totals(&s, inc, &no_walks),
        Err(SimError::BadConfig {
            name: "max_samples",
            ..
        })
    ));
    // sigma_s = 1e308: refused (the walk's depths would round and R + T came out 0.64).
    let huge = slab(0.5, 1e308, 0.1);
    let e = check_slab(&huge).unwrap_err().to_string();
    assert!(e.contains("sigma_t * d") && e.contains("1e9 mean free paths"), "{e}");
    assert!(simulate_bsdf(&huge, wi, &[], &SimConfig::default()).is_err());
    assert!(check_slab(&slab(0.0, 1e6, 1e6)).is_err());
    check_slab(&slab(0.0, 1e9, 1.0)).unwrap();
}

#[test]
fn adaptive_run_reports_its_precision() {
    let s = slab(0.5, 100.0, 0.1);
    let (wi, wo) = in_plane_directions(30.0, 0.0, false);
    let cfg = SimConfig {
        samples: 256,
        batches: 16,
        rel_stderr: Some(1e-9),
        max_samples: 2048,
        ..Default::default()
    };
    let run = simulate_bsdf(&s, wi, &[wo], &cfg).unwrap();
    assert!(!run.target_reached);
    let worst = run
        .f
        .iter()
        .chain([&run.reflectance, &run.transmittance])
        .map(|e| e.stderr.0[0] / e.mean.0[0])
        .fold(0.0, f64::max);
    assert_eq!(run.worst_rel_stderr, worst);
    assert!(worst > 1e-9);
    let cfg = SimConfig {
        rel_stderr: Some(0.5),
        ..cfg
    };
    assert!(simulate_bsdf(&s, wi, &[wo], &cfg).unwrap().target_reached);
}

/// The prediction of collisions per walk (used to refuse absurd runs) is
/// within a factor of 3 of the mean actually simulated, for a thick
/// conservative slab, an absorbing one and a thin one. (A factor, not a
/// statistical tolerance: the prediction is an order-of-magnitude model.)
#[test]
fn work_prediction_matches_the_simulated_collisions() {
    let (wi, _) = in_plane_directions(30.0, 0.0, false);
    for (sa, ss, d) in [(0.0, 500.0, 0.1), (50.0, 100.0, 0.5), (0.5, 20.0, 0.1)] {
        let s = slab(sa, ss, d);
        let cfg = SimConfig {
            samples: 4096,
            batches: 8,
            ..Default::default()
        };
        let predicted = estimate_work(&s, &cfg, 1).collisions_per_walk;
        let t = simulate_totals(&s, Incidence::Collimated(wi), &cfg).unwrap();
        // The run's own count (a grey slab: one distinct channel).
        assert_eq!(s.distinct_channels(), [0, 0, 0]);
        let measured = t.collisions as f64 / t.samples as f64;
        eprintln!(
            "sigma_a {sa} sigma_s {ss} d {d}: predicted {predicted:.1}, measured {measured:.1} collisions per walk"
        );
        assert!(
            predicted / measured < 3.0 && measured / predicted < 3.0,
            "sigma_a {sa} sigma_s {ss} d {d}: predicted {predicted}, measured {measured}"
        );
    }
}
