//! Reciprocity: with air on both sides and equal face indices the physical slab
//! satisfies f(wi, wo) = f(wo, wi). The two sides of each pair are estimated by
//! different walks (light from the other direction, even the other face for
//! transmission) and different next-event strategies, so agreement is a check
//! of the estimator, not of one code path. Tolerance: 4 combined standard errors
//! (a 6e-5 two-sided chance per pair for a correct simulator) plus 0.5%.
//! Also: R is reciprocal even when eta_f != eta_b, and T then is not (by about
//! (eta_f / eta_b)^2, exactly as in Mitsuba with the same two interfaces).

mod support;

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::{Colour, DVec3, PaperParams};
use paperbsdf_sim::{simulate_bsdf, SimConfig, Slab};

fn pair(slab: &Slab, wi: DVec3, wo: DVec3, walks: u64) -> ((f64, f64), (f64, f64)) {
    let cfg = SimConfig {
        samples: walks,
        batches: 32,
        seed: 99,
        ..Default::default()
    };
    let a = simulate_bsdf(slab, wi, &[wo], &cfg).unwrap().f[0];
    let b = simulate_bsdf(slab, wo, &[wi], &cfg).unwrap().f[0];
    ((a.mean.0[0], a.stderr.0[0]), (b.mean.0[0], b.stderr.0[0]))
}

fn check(name: &str, slab: &Slab, wi: DVec3, wo: DVec3, walks: u64) {
    let ((a, sa), (b, sb)) = pair(slab, wi, wo, walks);
    eprintln!("{name}: f(wi, wo) = {a:.5} +- {sa:.5}, f(wo, wi) = {b:.5} +- {sb:.5}");
    assert!(
        (a - b).abs() <= 4.0 * (sa * sa + sb * sb).sqrt() + 0.005 * a.max(b),
        "{name}: {a} +- {sa} vs {b} +- {sb}"
    );
}

#[test]
fn dev_a_pairs_at_grazing_light() {
    let p = support::params("devA.json");
    let slab = Slab::from_params(&p).unwrap();
    for (ti, to, t) in [
        (75.0, 0.0, false),
        (75.0, 60.0, false),
        (75.0, -40.0, false),
        (60.0, 20.0, true),
    ] {
        let (wi, wo) = in_plane_directions(ti, to, t);
        check(
            &format!("devA {} {ti} {to}", if t { 'T' } else { 'R' }),
            &slab,
            wi,
            wo,
            8192,
        );
    }
    // Surfaces only (no scattering): where Mitsuba is off by a factor 2.
    let mut q = p.clone();
    q.sigma_s = Colour::Scalar(0.0);
    let slab = Slab::from_params(&q).unwrap();
    let (wi, wo) = in_plane_directions(75.0, 0.0, false);
    check("devA sigma_s = 0 R 75 0", &slab, wi, wo, 16384);
}

#[test]
fn mixed_faces_and_back_lighting() {
    // Smooth front, rough Beckmann back, thin sheet: delta and rough exits, light
    // arriving at the back face for the reversed transmission pair.
    let p = PaperParams {
        name: None,
        d: 0.03,
        sigma_a: Colour::Scalar(1.0),
        sigma_s: Colour::Scalar(60.0),
        g_f: 0.7,
        g_b: -0.3,
        w_b: 0.25,
        eta_f: 1.5,
        eta_b: 1.5,
        m_f: 0.0,
        m_b: 0.3,
        dist_f: paperbsdf_core::Distribution::Ggx,
        dist_b: paperbsdf_core::Distribution::Beckmann,
        face_scattering: Default::default(),
    };
    let slab = Slab::from_params(&p).unwrap();
    let (wi, wo) = in_plane_directions(50.0, 10.0, true);
    check("smooth/rough T 50 10", &slab, wi, wo, 8192);
    let (wi, wo) = in_plane_directions(50.0, 20.0, false);
    check("smooth/rough R 50 20", &slab, wi, wo, 8192);
    // Seen and lit from the back.
    let flip = |v: DVec3| DVec3::new(v.x, v.y, -v.z);
    check("smooth/rough back R", &slab, flip(wi), flip(wo), 8192);
}

#[test]
fn unequal_indices_r_reciprocal_t_not() {
    let mut p = support::params("devB.json"); // eta_f = 1.55, eta_b = 1.45
    p.d = 0.05;
    let slab = Slab::from_params(&p).unwrap();
    let (wi, wo) = in_plane_directions(40.0, 10.0, false);
    check("devB-thin R 40 10", &slab, wi, wo, 8192);
    let (wi, wo) = in_plane_directions(40.0, 10.0, true);
    let ((a, sa), (b, sb)) = pair(&slab, wi, wo, 8192);
    let ratio = a / b;
    let want = (1.55f64 / 1.45).powi(2);
    let se = ratio * ((sa / a).powi(2) + (sb / b).powi(2)).sqrt();
    eprintln!("T(front lit) / T(back lit) = {ratio:.4} +- {se:.4}, (eta_f/eta_b)^2 = {want:.4}");
    assert!((ratio - want).abs() <= 4.0 * se + 0.01, "{ratio} +- {se} vs {want}");
}
