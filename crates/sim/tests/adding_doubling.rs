//! Total reflectance and transmittance against adding-doubling (iadpython 0.5.3,
//! `data/reference/slab_rt_dev.csv`) and van de Hulst's tabulated case.
//!
//! Slab: smooth Fresnel faces of index `n` in air (n = 1: no interface), one
//! Henyey-Greenstein lobe `g`, albedo `a`, optical thickness `tau` (d = 1 mm,
//! sigma_t = tau). `UR1`, `UT1`: collimated normal incidence (specular reflection
//! and unscattered light included); `URU`, `UTU`: diffuse incidence.
//! Tolerance: 3 standard errors of the simulation plus 0.002 for the
//! 16-point quadrature of the adding-doubling solver (3 sigma: 0.3% two-sided
//! chance per value for a correct simulator; with ~170 values a few such
//! misses would be expected, so the test allows 2% of the values to miss and
//! none by more than 5 sigma + 0.002).

mod support;

use paperbsdf_core::{Colour, DVec3, Distribution, PaperParams};
use paperbsdf_sim::{simulate_totals, Incidence, SimConfig, Slab};
use support::{ad_params, read_ad};

fn cfg(walks: u64, seed: u64) -> SimConfig {
    SimConfig {
        samples: walks,
        batches: 32,
        seed,
        ..Default::default()
    }
}

#[test]
fn totals_agree_with_adding_doubling() {
    let rows = read_ad();
    assert!(rows.len() >= 40);
    let mut misses = Vec::new();
    let mut n = 0;
    for (k, r) in rows.iter().enumerate() {
        let slab = Slab::from_params(&ad_params(r.albedo, r.tau, r.g, r.n)).unwrap();
        // Long walks (thick, nearly conservative slabs) get fewer of them.
        let walks = if r.albedo >= 0.99 && r.tau >= 10.0 {
            6_144
        } else {
            16_384
        };
        let col = simulate_totals(&slab, Incidence::Collimated(DVec3::Z), &cfg(walks, k as u64)).unwrap();
        let dif = simulate_totals(&slab, Incidence::Diffuse { front: true }, &cfg(walks, 1000 + k as u64)).unwrap();
        for (what, want, e) in [
            ("UR1", r.ur1, col.reflectance),
            ("UT1", r.ut1, col.transmittance),
            ("URU", r.uru, dif.reflectance),
            ("UTU", r.utu, dif.transmittance),
        ] {
            let (m, se) = (e.mean.0[0], e.stderr.0[0]);
            let dev = (m - want).abs();
            n += 1;
            eprintln!(
                "a={} tau={} g={} n={} {what}: ref {want:.6} sim {m:.6} +- {se:.6}",
                r.albedo, r.tau, r.g, r.n
            );
            if dev > 3.0 * se + 0.002 {
                misses.push(format!(
                    "a={} tau={} g={} n={} {what}: ref {want} sim {m} +- {se}",
                    r.albedo, r.tau, r.g, r.n
                ));
                assert!(dev <= 5.0 * se + 0.002, "{}", misses.last().unwrap());
            }
        }
    }
    eprintln!("{} of {n} values outside 3 sigma + 0.002: {misses:#?}", misses.len());
    assert!(misses.len() as f64 <= 0.02 * n as f64, "{misses:#?}");
}

#[test]
fn van_de_hulst_table() {
    // Albedo 0.9, optical thickness 2, g = 0.75, index-matched: R = 0.09739, T = 0.66096
    // (van de Hulst, Multiple Light Scattering, 1980; T includes the unscattered exp(-2)).
    let slab = Slab::from_params(&ad_params(0.9, 2.0, 0.75, 1.0)).unwrap();
    let t = simulate_totals(&slab, Incidence::Collimated(DVec3::Z), &cfg(1 << 19, 7)).unwrap();
    let (r, rse) = (t.reflectance.mean.0[0], t.reflectance.stderr.0[0]);
    let (tt, tse) = (t.transmittance.mean.0[0], t.transmittance.stderr.0[0]);
    eprintln!("van de Hulst: R {r:.5} +- {rse:.5} (0.09739), T {tt:.5} +- {tse:.5} (0.66096)");
    assert!((r - 0.09739).abs() <= 3.0 * rse, "R = {r} +- {rse}");
    assert!((tt - 0.66096).abs() <= 3.0 * tse, "T = {tt} +- {tse}");
    assert!(rse < 5e-4 && tse < 1e-3, "not enough walks for a meaningful test");
}

#[test]
fn energy_is_conserved_without_absorption_and_lost_only_by_rough_faces() {
    // No absorption, smooth faces: every walk leaves, R + T = 1 walk by walk
    // (so the batch spread of R + T is zero up to rounding).
    let mut p: PaperParams = ad_params(1.0, 3.0, 0.6, 1.5);
    p.w_b = 0.3;
    p.g_b = -0.5;
    let slab = Slab::from_params(&p).unwrap();
    for inc in [
        Incidence::Collimated(DVec3::new(0.6, 0.0, 0.8)),
        Incidence::Diffuse { front: false },
    ] {
        let t = simulate_totals(&slab, inc, &cfg(4096, 3)).unwrap();
        let s = t.reflectance.mean.0[0] + t.transmittance.mean.0[0];
        assert!((s - 1.0).abs() < 1e-9, "{inc:?}: R + T = {s}");
    }
    // Rough faces lose energy to shadowing (single-scattering microfacets), never gain.
    p.m_f = 0.5;
    p.m_b = 0.5;
    p.dist_b = Distribution::Beckmann;
    p.sigma_a = Colour::Scalar(0.0);
    let slab = Slab::from_params(&p).unwrap();
    let t = simulate_totals(&slab, Incidence::Collimated(DVec3::Z), &cfg(8192, 4)).unwrap();
    let s = t.reflectance.mean.0[0] + t.transmittance.mean.0[0];
    let se = t.reflectance.stderr.0[0] + t.transmittance.stderr.0[0];
    assert!(s < 1.0 - 5.0 * se && s > 0.5, "R + T = {s} +- {se}");
}
