//! Run settings: adaptive stopping, reproducibility across thread counts, and
//! clear errors for bad requests.

mod support;

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::DVec3;
use paperbsdf_sim::{simulate_bsdf, simulate_totals, Incidence, SimConfig, SimError, Slab};

fn slab() -> Slab {
    let mut p = support::params("devA.json");
    p.d = 0.03;
    Slab::from_params(&p).unwrap()
}

#[test]
fn adaptive_run_reaches_the_requested_relative_error() {
    let s = slab();
    let (wi, wo) = in_plane_directions(30.0, 0.0, false);
    let (_, wt) = in_plane_directions(30.0, 0.0, true);
    let cfg = SimConfig {
        samples: 256,
        batches: 16,
        seed: 4,
        rel_stderr: Some(0.03),
        ..Default::default()
    };
    let run = simulate_bsdf(&s, wi, &[wo, wt], &cfg).unwrap();
    assert!(run.samples > 256, "it had to run more than the first round");
    for e in run.f.iter().chain([&run.reflectance, &run.transmittance]) {
        assert!(e.stderr.0[0] <= 0.03 * e.mean.0[0], "{e:?}");
    }
    // The cap is respected.
    let cfg = SimConfig {
        rel_stderr: Some(1e-4),
        max_samples: 1024,
        ..cfg
    };
    let run = simulate_bsdf(&s, wi, &[wo], &cfg).unwrap();
    assert!(run.samples <= 1024 + 16, "{}", run.samples);
}

#[test]
fn reproducible_whatever_the_number_of_threads() {
    let s = slab();
    let (wi, wo) = in_plane_directions(60.0, -20.0, true);
    let cfg = SimConfig {
        samples: 2048,
        batches: 8,
        seed: 17,
        ..Default::default()
    };
    let a = simulate_bsdf(&s, wi, &[wo], &cfg).unwrap();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let b = pool.install(|| simulate_bsdf(&s, wi, &[wo], &cfg).unwrap());
    assert_eq!(a, b);
    let c = simulate_bsdf(
        &s,
        wi,
        &[wo],
        &SimConfig {
            seed: 18,
            ..cfg.clone()
        },
    )
    .unwrap();
    assert_ne!(a.f[0].mean, c.f[0].mean, "another seed, other numbers");
}

#[test]
fn bad_requests_are_errors() {
    let s = slab();
    let cfg = SimConfig {
        samples: 64,
        batches: 4,
        ..Default::default()
    };
    let e = simulate_bsdf(&s, DVec3::new(1.0, 0.0, 0.0), &[DVec3::Z], &cfg).unwrap_err();
    assert!(matches!(e, SimError::BadDirection { what: "wi", .. }), "{e}");
    let e = simulate_bsdf(&s, DVec3::Z, &[DVec3::new(0.0, 0.0, 2.0)], &cfg).unwrap_err();
    assert!(e.to_string().contains("wo"), "{e}");
    let e = simulate_totals(
        &s,
        Incidence::Collimated(DVec3::Z),
        &SimConfig {
            batches: 1,
            ..cfg.clone()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("batches"), "{e}");
    let e = simulate_totals(
        &s,
        Incidence::Collimated(DVec3::Z),
        &SimConfig {
            rel_stderr: Some(-1.0),
            ..cfg.clone()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("rel_stderr"), "{e}");
    let mut p = support::params("devA.json");
    p.m_b = 2.0;
    let e = Slab::from_params(&p).unwrap_err().to_string();
    assert!(e.contains("m_b") && e.contains('2'), "{e}");
}
