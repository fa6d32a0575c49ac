//! (a) energy conservation of non-absorbing sheets and (b) reciprocity of the
//! discretised matrices, for every Fourier order.
//!
//! Energy: for light at outside node `j`, `sum_o w_o mu_o (R[o][j] + T[o][j]) / (w_j mu_j) = 1`
//! (order 0; Radau weights `w`, nodes `mu`), asked within 1e-4 for tau from
//! 0.01 to 100 and g up to 0.9, from both sides, with and without Fresnel faces.
//! Reciprocity: with `W = diag(w_j mu_j / eta^2)` of each side,
//! `W R_top`, `W R_bot` symmetric and `W_bot T_down = (W_top T_up)^T`, for the
//! sheet (outside grids), the medium alone and the interface (inside grid,
//! `eta` the medium's index), asked to 1e-10 relative to the largest entry.

mod support;

use paperbsdf_core::phase::TwoLobeHg;
use paperbsdf_slab::{interface::smooth_interface, Discretisation, Face, Medium, Side, SlabSpec};
use support::layer_asymmetry;

fn sheet(albedo: f64, tau: f64, phase: TwoLobeHg, eta: f64) -> SlabSpec {
    SlabSpec {
        medium: Medium { albedo, tau, phase },
        front: Face::Smooth { eta },
        back: Face::Smooth { eta },
    }
}

fn hg(g: f64) -> TwoLobeHg {
    TwoLobeHg {
        g_f: g,
        g_b: 0.0,
        w_b: 0.0,
    }
}

const PAPER_PHASE: TwoLobeHg = TwoLobeHg {
    g_f: 0.8,
    g_b: -0.4,
    w_b: 0.2,
};

#[test]
fn non_absorbing_sheets_conserve_energy() {
    let disc = Discretisation {
        nodes: 24,
        tir_nodes: 12,
        ..Default::default()
    };
    let mut worst: f64 = 0.0;
    for tau in [0.01, 0.5, 3.0, 30.0, 100.0] {
        for phase in [hg(0.0), hg(0.5), hg(0.9), hg(-0.6), PAPER_PHASE] {
            for eta in [1.0, 1.5] {
                let sol = sheet(1.0, tau, phase, eta).solve(&disc).unwrap();
                for side in [Side::Front, Side::Back] {
                    for j in 0..sol.outside.len() {
                        let (r, t) = sol.totals_collimated(side, j);
                        worst = worst.max((r + t - 1.0).abs());
                    }
                    let (r, t) = sol.totals_diffuse(side);
                    worst = worst.max((r + t - 1.0).abs());
                }
            }
        }
    }
    println!("worst |R + T - 1| = {worst:.2e}");
    assert!(worst < 1e-4, "{worst}");
}

#[test]
fn absorption_only_removes_energy() {
    let disc = Discretisation {
        nodes: 16,
        tir_nodes: 8,
        ..Default::default()
    };
    for albedo in [0.0, 0.5, 0.99] {
        let sol = sheet(albedo, 2.0, PAPER_PHASE, 1.5).solve(&disc).unwrap();
        for j in 0..sol.outside.len() {
            let (r, t) = sol.totals_collimated(Side::Front, j);
            assert!(r >= 0.0 && t >= 0.0 && r + t < 1.0, "a={albedo} j={j}: {r} {t}");
        }
    }
}

#[test]
fn matrices_are_reciprocal_in_every_order() {
    let disc = Discretisation {
        nodes: 20,
        tir_nodes: 10,
        orders: 12,
        start_thickness: None,
        ..Default::default()
    };
    let mut worst: f64 = 0.0;
    for (albedo, tau, phase, eta) in [
        (0.9, 0.3, PAPER_PHASE, 1.5),
        (0.999, 30.0, PAPER_PHASE, 1.5),
        (1.0, 5.0, hg(0.7), 1.0),
        (0.5, 2.0, hg(-0.3), 1.33),
    ] {
        let sol = sheet(albedo, tau, phase, eta).solve(&disc).unwrap();
        for m in 0..disc.orders {
            worst = worst.max(layer_asymmetry(&sol.orders[m], &sol.outside, &sol.outside));
            worst = worst.max(layer_asymmetry(&sol.medium[m], &sol.inside, &sol.inside));
        }
        let face = smooth_interface(&sol.outside, &sol.inside);
        worst = worst.max(layer_asymmetry(&face, &sol.outside, &sol.inside));
    }
    println!("worst relative asymmetry {worst:.2e}");
    assert!(worst < 1e-10, "{worst}");
}

#[test]
fn a_homogeneous_sheet_looks_the_same_from_both_sides() {
    let disc = Discretisation {
        nodes: 16,
        tir_nodes: 8,
        orders: 4,
        start_thickness: None,
        ..Default::default()
    };
    let sol = sheet(0.95, 4.0, PAPER_PHASE, 1.5).solve(&disc).unwrap();
    for l in &sol.orders {
        let d = (&l.r_top - &l.r_bot).amax().max((&l.t_down - &l.t_up).amax());
        assert!(d < 1e-10 * l.r_top.amax().max(l.t_down.amax()), "{d}");
    }
}
