//! (e) Convergence of a sheet with rough faces in the nodes and in the
//! azimuth rule: the thin sheet of tests/simulator.rs (tau = 2.005, GGX
//! m = 0.15 front, Beckmann m = 0.3 back, `"multiple"` faces; where the
//! discretisation errors are largest), R and T at normal incidence and for
//! diffuse light.
//!
//! Measured (release build, both face modes and both sheets of
//! tests/simulator.rs): against 64 nodes, 16 / 24 / 32 / 48 nodes differ by
//! at most 7.0e-3 / 2.2e-3 / 5.6e-4 / 2.8e-5 (thin sheet; the paper-like
//! one 2.7e-3 / 8.5e-4 / 2.4e-4 / 2.1e-5), the collimated totals carrying
//! the error (the diffuse ones move by 3e-4 from 16 nodes on); 16 instead
//! of 8 Gauss-Legendre points per azimuth panel change them by at most
//! 1.1e-6. Solve times at 32 / 64 nodes: 0.6 s / 1.5-2 s (two distinct
//! faces). Asked here: 32 -> 48 nodes within 1e-3, monotone decrease of
//! the change with nodes, azimuth points within 1e-5.

use paperbsdf_core::{Colour, Distribution, FaceScattering, PaperParams};
use paperbsdf_slab::{Discretisation, Side, SlabSpec};

fn thin_sheet() -> PaperParams {
    PaperParams {
        d: 0.01,
        sigma_s: Colour::Scalar(200.0),
        sigma_a: Colour::Scalar(0.5),
        m_f: 0.15,
        m_b: 0.3,
        dist_f: Distribution::Ggx,
        dist_b: Distribution::Beckmann,
        face_scattering: FaceScattering::Multiple,
        ..paperbsdf_core::presets::matte_office()
    }
}

/// R and T at normal incidence and for diffuse light, front side.
fn totals(p: &PaperParams, nodes: usize, q: usize) -> [f64; 4] {
    let disc = Discretisation {
        nodes,
        tir_nodes: nodes / 2,
        azimuth_points: q,
        ..Default::default()
    };
    let sol = SlabSpec::from_params(p, 0).unwrap().solve(&disc).unwrap();
    let (r1, t1) = sol.totals_normal(Side::Front);
    let (ru, tu) = sol.totals_diffuse(Side::Front);
    [r1, t1, ru, tu]
}

fn max_abs(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

#[test]
fn totals_converge_in_nodes_and_azimuth_points() {
    let p = thin_sheet();
    let (a16, a24, a32, a48) = (
        totals(&p, 16, 8),
        totals(&p, 24, 8),
        totals(&p, 32, 8),
        totals(&p, 48, 8),
    );
    let q = totals(&p, 24, 16);
    let (d16, d24, d32) = (max_abs(&a16, &a48), max_abs(&a24, &a48), max_abs(&a32, &a48));
    let dq = max_abs(&a24, &q);
    println!("totals at 48 nodes {a48:.5?}; 16 / 24 / 32 nodes differ by {d16:.1e} / {d24:.1e} / {d32:.1e}; 8 -> 16 azimuth points per panel: {dq:.1e}");
    assert!(d32 < 1e-3 && d24 > d32 && d16 > d24, "{d16} {d24} {d32}");
    assert!(dq < 1e-5, "{dq}");
}

#[test]
fn bad_face_settings_are_typed_errors() {
    let p = thin_sheet();
    let spec = SlabSpec::from_params(&p, 0).unwrap();
    for (disc, name) in [
        (
            Discretisation {
                azimuth_points: 1,
                ..Default::default()
            },
            "azimuth_points",
        ),
        (
            Discretisation {
                azimuth_points: 65,
                ..Default::default()
            },
            "azimuth_points",
        ),
    ] {
        let e = spec.solve(&disc).unwrap_err();
        assert!(e.to_string().contains(name), "{e}");
    }
    let mut bad = spec;
    if let paperbsdf_slab::Face::Rough { ref mut m, .. } = bad.front {
        *m = 2.0;
    }
    let e = bad.solve(&Discretisation::default()).unwrap_err();
    assert!(e.to_string().contains("m_f"), "{e}");
    let e = SlabSpec::from_params(&p, 3).unwrap_err();
    assert!(e.to_string().contains("channel"), "{e}");
    // A coated front (eta_f != eta_b) is a sheet like any other (tests/coated.rs).
    let coated = PaperParams { eta_f: 1.6, ..p };
    let spec = SlabSpec::from_params(&coated, 0).unwrap();
    assert_eq!((spec.front.eta(), spec.back.eta()), (1.6, coated.eta_b));
}
