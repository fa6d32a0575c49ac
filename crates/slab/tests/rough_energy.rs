//! (c) Energy of whole sheets with rough faces and no absorption: with
//! energy-conserving (`"multiple"`) faces `R + T = 1` for light at every
//! outside node and for diffuse light, from both sides; with Walter's
//! (`"single"`) faces the faces lose light, so `R + T < 1`.
//!
//! The `"multiple"` face conserves energy on the grid to the tolerance of its
//! normalisation (1e-12 per node: its compensation closes `1 - R - T` of the
//! projected face; tests/rough_face.rs) and the medium to rounding (the
//! normalised phase matrix), so what is left is that tolerance amplified by
//! the internal reflections, and rounding: measured `|R + T - 1| <= 8.8e-11`
//! (tau = 3 and 30, m = 0.15 to 0.8, 24 nodes; printed), asked below 1e-9.
//! The faces' own energy error in core's model (its tables, up to 2e-3,
//! issue 14) is not inherited: the solver closes the energy on its own grid.
//! With Walter's faces the same sheets keep at most 89% (tau = 3, m = 0.15 and
//! 0.3) and 59% (tau = 30, m = 0.5 and 0.8).

use paperbsdf_core::{Colour, Distribution, FaceScattering, PaperParams};
use paperbsdf_slab::{Discretisation, Side, SlabSpec};

fn sheet(d: f64, m_f: f64, m_b: f64, fs: FaceScattering) -> PaperParams {
    PaperParams {
        d,
        sigma_s: Colour::Scalar(300.0),
        sigma_a: Colour::Scalar(0.0),
        m_f,
        m_b,
        dist_f: Distribution::Ggx,
        dist_b: Distribution::Beckmann,
        face_scattering: fs,
        ..paperbsdf_core::presets::matte_office()
    }
}

/// The largest `|R + T - 1|` and the largest `R + T` over the outside nodes and diffuse light, both sides.
fn energy(p: &PaperParams, disc: &Discretisation) -> (f64, f64) {
    let sol = SlabSpec::from_params(p, 0).unwrap().solve(disc).unwrap();
    let (mut dev, mut most): (f64, f64) = (0.0, 0.0);
    for side in [Side::Front, Side::Back] {
        let mut check = |(r, t): (f64, f64)| {
            dev = dev.max((r + t - 1.0).abs());
            most = most.max(r + t);
        };
        for j in 0..sol.outside.len() {
            check(sol.totals_collimated(side, j));
        }
        check(sol.totals_diffuse(side));
    }
    (dev, most)
}

#[test]
fn conservative_sheets_with_multiple_faces_conserve_energy() {
    let disc = Discretisation {
        nodes: 24,
        tir_nodes: 12,
        ..Default::default()
    };
    let mut worst: f64 = 0.0;
    // optical thickness 3 and 30; a rough pair and a very rough pair of faces
    for (d, m_f, m_b) in [(0.01, 0.15, 0.3), (0.1, 0.15, 0.3), (0.1, 0.5, 0.8)] {
        let (dev, _) = energy(&sheet(d, m_f, m_b, FaceScattering::Multiple), &disc);
        println!(
            "multiple faces m = {m_f}, {m_b}, tau = {}: |R + T - 1| <= {dev:.1e}",
            300.0 * d
        );
        worst = worst.max(dev);
    }
    assert!(worst < 1e-9, "{worst}");
}

#[test]
fn single_faces_lose_light() {
    let disc = Discretisation {
        nodes: 24,
        tir_nodes: 12,
        ..Default::default()
    };
    for (d, m_f, m_b) in [(0.01, 0.15, 0.3), (0.1, 0.5, 0.8)] {
        let (_, most) = energy(&sheet(d, m_f, m_b, FaceScattering::Single), &disc);
        println!(
            "single faces m = {m_f}, {m_b}, tau = {}: largest R + T {most:.4}",
            300.0 * d
        );
        assert!(most < 1.0 - 1e-3, "{most}");
    }
}

/// Largest asymmetry of `W_a K_ab` against `(W_b K_ba)^T`, relative to the largest entry.
fn asymmetry(w: &[f64], kab: &nalgebra::DMatrix<f64>, kba: &nalgebra::DMatrix<f64>) -> f64 {
    let d = nalgebra::DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(w));
    let (a, b) = (&d * kab, &d * kba);
    (&a - b.transpose()).amax() / a.amax().max(b.amax()).max(1e-300)
}

#[test]
fn sheets_with_unequal_rough_faces_are_reciprocal_in_every_order() {
    // GGX m = 0.15 in front, Beckmann m = 0.3 behind: R_top and R_bot differ,
    // and reciprocity ties T_down to T_up
    let disc = Discretisation {
        nodes: 16,
        tir_nodes: 8,
        orders: 8,
        ..Default::default()
    };
    let mut worst: f64 = 0.0;
    for fs in [FaceScattering::Single, FaceScattering::Multiple] {
        let mut p = sheet(0.01, 0.15, 0.3, fs);
        p.sigma_a = Colour::Scalar(1.0);
        let sol = SlabSpec::from_params(&p, 0).unwrap().solve(&disc).unwrap();
        let w = sol.outside.reciprocity_weights();
        for l in &sol.orders {
            worst = worst
                .max(asymmetry(&w, &l.r_top, &l.r_top))
                .max(asymmetry(&w, &l.r_bot, &l.r_bot))
                .max(asymmetry(&w, &l.t_down, &l.t_up));
        }
        let (r_f, _) = sol.totals_normal(Side::Front);
        let (r_b, _) = sol.totals_normal(Side::Back);
        // That the two faces differ, so that the relations are not met by
        // symmetry: 9.6e-4 apart at the normal (1e-3 and more until the
        // Snell image's cell averages of 2026-12-07 moved the front's
        // transmission); the threshold only has to tell them from equal.
        assert!((r_f - r_b).abs() > 5e-4, "the faces differ: {r_f} {r_b}");
    }
    println!("worst relative asymmetry of the sheet (8 orders): {worst:.1e}");
    assert!(worst < 1e-10, "{worst}");
}
