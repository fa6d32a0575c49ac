//! Issue 16: the per-walk collision cap is reached and reported. A slab
//! 1e4 mean free paths thick, conservative (`sigma_a = 0`), isotropically
//! scattering, between index-matched faces (`eta = 1`: no surface event
//! changes a walk's weight), so every walk carries exactly unit flux until it
//! leaves (adding 1 to `R` or `T`) or is cut (adding nothing). Crossing it
//! takes about `tau^2 = 1e8` collisions, so with a small cap many walks are
//! cut, and without one the run would take minutes.
//!
//! Only `cap_cuts_walks_quickly_and_their_flux_is_missing` runs walks through
//! `simulate_*` in this binary (it reads the process-wide collision counter).

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::PaperParams;
use paperbsdf_sim::estimate::estimate_work;
use paperbsdf_sim::walk::{Tally, Tracer, MAX_COLLISIONS_PER_WALK};
use paperbsdf_sim::{simulate_totals, Incidence, SimConfig, SimError, Slab};
use rand::SeedableRng;
use std::time::{Duration, Instant};

const THICK: &str = r#"{"d":1.0,"sigma_a":0.0,"sigma_s":1e4,"g_f":0.0,"g_b":0.0,"w_b":0.0,"eta_f":1.0,"eta_b":1.0,"m_f":0.0,"m_b":0.0,"dist_f":"ggx","dist_b":"ggx"}"#;

fn thick() -> Slab {
    let p: PaperParams = serde_json::from_str(THICK).unwrap();
    p.validate().unwrap();
    Slab::from_params(&p).unwrap()
}

#[test]
fn default_cap_is_unchanged() {
    assert_eq!(MAX_COLLISIONS_PER_WALK, 10_000_000);
    assert_eq!(SimConfig::default().max_collisions_per_walk, 10_000_000);
    let s = thick();
    assert_eq!(Tracer::new(&s, 0, &[]).max_collisions(), MAX_COLLISIONS_PER_WALK);
    assert_eq!(Tracer::new(&s, 0, &[]).with_max_collisions(0).max_collisions(), 1);
}

#[test]
fn zero_cap_is_a_range_error() {
    let s = thick();
    let cfg = SimConfig {
        samples: 64,
        batches: 4,
        max_collisions_per_walk: 0,
        ..Default::default()
    };
    let e = simulate_totals(&s, Incidence::Collimated(paperbsdf_core::DVec3::Z), &cfg).unwrap_err();
    assert!(
        matches!(
            e,
            SimError::BadConfig {
                name: "max_collisions_per_walk",
                ..
            }
        ),
        "{e}"
    );
    let m = e.to_string();
    assert!(m.contains("max_collisions_per_walk") && m.contains("1 to"), "{m}");
}

/// Walk by walk: no walk has more collisions than the cap, a cut walk has
/// exactly the cap and contributes no flux, every other walk's unit flux
/// leaves as `R` or `T`.
#[test]
fn tracer_cuts_each_walk_at_its_cap() {
    let s = thick();
    let cap = 50;
    let tracer = Tracer::new(&s, 0, &[]).with_max_collisions(cap);
    let (wi, _) = in_plane_directions(30.0, 0.0, false);
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(11);
    let mut one = Tally::new(0);
    let (mut cut, mut left) = (0, 0);
    for _ in 0..2000 {
        one.clear();
        tracer.walk(wi, &mut rng, &mut one);
        assert!(one.collisions <= cap as u64, "{} collisions", one.collisions);
        if one.truncated == 1 {
            cut += 1;
            assert_eq!(one.collisions, cap as u64);
            assert_eq!((one.r, one.t), (0.0, 0.0), "a cut walk's flux is dropped");
        } else {
            assert_eq!(one.truncated, 0);
            left += 1;
            assert_eq!(one.r + one.t, 1.0, "{} {}", one.r, one.t);
        }
    }
    // In a half-space about 1 / sqrt(pi cap) of the walks are still inside
    // after `cap` collisions (8% here).
    assert!(cut > 40 && left > 1000, "{cut} cut, {left} left");
}

/// Through `simulate_totals`: the run is quick, reports its cut walks, and
/// `R + T` is short of 1 by exactly the cut walks' flux (`truncated / samples`,
/// each carried unit flux). Without the cap the walks would take about
/// `2 sqrt(1e7)` collisions each on average, some 1e7.
#[test]
fn cap_cuts_walks_quickly_and_their_flux_is_missing() {
    let s = thick();
    let cap = 1000u64;
    let cfg = SimConfig {
        samples: 4096,
        batches: 16,
        seed: 5,
        max_collisions_per_walk: cap,
        ..Default::default()
    };
    let (wi, _) = in_plane_directions(30.0, 0.0, false);
    let start = Instant::now();
    let t = simulate_totals(&s, Incidence::Collimated(wi), &cfg).unwrap();
    let collisions = t.collisions;
    let elapsed = start.elapsed();
    eprintln!(
        "{} of {} walks cut, {collisions} collisions ({:.1} per walk, predicted {:.1}) in {elapsed:?}",
        t.truncated,
        t.samples,
        collisions as f64 / t.samples as f64,
        estimate_work(&s, &cfg, 1).collisions_per_walk
    );
    assert_eq!(t.samples, 4096);
    // (a) bounded work: every walk stops at the cap, and each cut walk had exactly the cap.
    assert!(collisions <= t.samples * cap, "{collisions} collisions");
    assert!(collisions >= t.truncated * cap, "{collisions} collisions");
    assert!(elapsed < Duration::from_secs(60), "took {elapsed:?}");
    // (b) the cut is reported: in a half-space some 1 / sqrt(pi cap), 2%, are still inside.
    assert!(t.truncated > 20 && t.truncated < 400, "{} cut", t.truncated);
    // (c) the cut walks' flux is in neither R nor T, and nothing else is lost.
    let missing = t.truncated as f64 / t.samples as f64;
    let sum = t.reflectance.mean.0[0] + t.transmittance.mean.0[0];
    assert!((sum - (1.0 - missing)).abs() < 1e-12, "R + T = {sum}, cut {missing}");
    // Almost all of it leaves through the lit face: the slab is opaque.
    assert!(t.transmittance.mean.0[0] < 1e-3, "{:?}", t.transmittance);
    // The work prediction knows the cap (a cap of 1000 at most 1001 per walk).
    let predicted = estimate_work(&s, &cfg, 1).collisions_per_walk;
    let measured = collisions as f64 / t.samples as f64;
    assert!(predicted <= cap as f64 + 1.0, "{predicted}");
    assert!(
        predicted / measured < 3.0 && measured / predicted < 3.0,
        "{predicted} vs {measured}"
    );
}
