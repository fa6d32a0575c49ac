//! (d) Total reflectance and transmittance of sheets with rough faces against
//! the Monte Carlo simulator (`paperbsdf-sim`, the project's ground truth),
//! run in the test.
//!
//! Sheets (scalar channel, matte preset's phase function, eta = 1.5, GGX
//! m = 0.15 front, Beckmann m = 0.3 back, both `face_scattering` modes): a
//! thin one (d = 0.01 mm, sigma_s = 200, sigma_a = 0.5 /mm: tau = 2.005,
//! albedo 0.9975) and a paper-like one (d = 0.1 mm, sigma_s = 300,
//! sigma_a = 0.1 /mm: tau = 30.01, albedo 0.99967). Light on the front at the
//! outside nodes of 0 and 75.3 degrees (the simulator gets the node's exact
//! direction), and once on the back (thin sheet, `"multiple"`, 0 degrees);
//! default discretisation (32 nodes).
//!
//! **Tolerance**: `3 sigma + 3e-3` per total, sigma the simulator's standard
//! error. The 3e-3 holds the solver's discretisation (32 -> 64 nodes moves
//! these totals by at most 5.6e-4, tests/rough_convergence.rs), the split of
//! each face's R and T (from outside within 2.2e-3 of core's quadrature,
//! tests/rough_face.rs; from inside exact since 2026-12-05, 5e-3 before) and, for `"multiple"`, the
//! discretisation of the faces' microsurface walk (the simulator's walk,
//! Heitz et al. 2016, solved on the grids: `paperbsdf_slab::face_walk`;
//! until 2026-12-04 the solver's face was core's separable compensation
//! instead, and the figures below were measured with it). Measured once with 40 times the walks of this test
//! (800k thin, 160k paper-like; 0, 43.5 and 75.3 degrees): every total
//! within 2.2 sigma (sigma 4e-4 to 1.2e-3), largest differences 1.2e-3
//! (`"single"`, paper-like, 75.3 degrees) and 1.9e-3 (`"multiple"`,
//! paper-like, 75.3 degrees: slab R 0.8342, simulator 0.8361 +- 0.0008).

mod support;

use paperbsdf_core::{Colour, DVec3, Distribution, FaceScattering, PaperParams};
use paperbsdf_sim::Slab;
use paperbsdf_slab::{Discretisation, Side, SlabSpec};
use support::{simulated_totals, with_both_faces};

fn sheet(d: f64, sigma_s: f64, sigma_a: f64, fs: FaceScattering) -> PaperParams {
    PaperParams {
        d,
        sigma_s: Colour::Scalar(sigma_s),
        sigma_a: Colour::Scalar(sigma_a),
        m_f: 0.15,
        m_b: 0.3,
        dist_f: Distribution::Ggx,
        dist_b: Distribution::Beckmann,
        face_scattering: fs,
        ..paperbsdf_core::presets::matte_office()
    }
}

/// The discretisation and face tolerance of the module doc.
const TOLERANCE: f64 = 3e-3;

/// Prints slab's totals `(r, t)` beside the simulator's `(R, stderr R, T,
/// stderr T)` under `label`, asserts that each differs by at most 3 sigma
/// plus `tolerance`, and returns the larger of the two differences less
/// 3 sigma.
fn check_totals(label: &str, (r, t): (f64, f64), (sr, se_r, st, se_t): (f64, f64, f64, f64), tolerance: f64) -> f64 {
    println!("{label}: slab R {r:.4} T {t:.4}; simulator R {sr:.4} +- {se_r:.4} T {st:.4} +- {se_t:.4}");
    let mut worst = f64::NEG_INFINITY;
    for (what, a, b, se) in [("R", r, sr, se_r), ("T", t, st, se_t)] {
        let excess = (a - b).abs() - 3.0 * se;
        worst = worst.max(excess);
        assert!(excess <= tolerance, "{label} {what}: slab {a} simulator {b} +- {se}");
    }
    worst
}

#[test]
fn totals_agree_with_the_simulator() {
    let disc = Discretisation::default();
    let mut worst = f64::NEG_INFINITY;
    for fs in [FaceScattering::Single, FaceScattering::Multiple] {
        for (name, p, walks) in [
            ("thin", sheet(0.01, 200.0, 0.5, fs), 60_000u64),
            ("paper-like", sheet(0.1, 300.0, 0.1, fs), 16_000),
        ] {
            let sol = SlabSpec::from_params(&p, 0).unwrap().solve(&disc).unwrap();
            let slab = Slab::from_params(&p).unwrap();
            let g = &sol.outside;
            // the back face lit too, once (the sheet's faces differ)
            let back = fs == FaceScattering::Multiple && name == "thin";
            let cases = [(Side::Front, g.len() - 1), (Side::Front, 10), (Side::Back, g.len() - 1)];
            for (side, j) in cases.into_iter().take(if back { 3 } else { 2 }) {
                let mu = g.mu[j];
                let z = if side == Side::Front { mu } else { -mu };
                let wi = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, z);
                let label = format!("{fs:?} {name} {side:?} theta {:.1}", mu.acos().to_degrees());
                let sim = simulated_totals(&slab, wi, walks, 17 + j as u64);
                let excess = check_totals(&label, sol.totals_collimated(side, j), sim, TOLERANCE);
                worst = worst.max(excess);
            }
        }
    }
    println!("largest |slab - simulator| - 3 sigma: {worst:+.1e} (allowed {TOLERANCE:.0e})");
}

/// Faces close to index-matched: the thin sheet of the test above with
/// both faces so, lit on the front at the outside nodes of 0, 43.5, 75.3
/// and 85.5 degrees, both face modes, against the simulator. All four
/// were refused until 2026-12-07 (the normalisation had reached 1e-10 or
/// 1e-11, not 1e-12, in its 20,000 iterations), and their
/// lobe around the Snell image is narrower than the nodes' cells
/// (crates/slab/src/interface.rs, "Narrow transmission lobes"): with the
/// nodes' values alone slab's reflectance was 4.5e-3 under the
/// simulator's at 75.3 degrees (7.9 sigma at 480k walks, Beckmann 1.12,
/// `"single"`) and 4.9e-3 at 85.5 (`"multiple"`); with the cells' averages the largest
/// difference is 2.3e-3 (3.8 sigma, 85.5 degrees, `"multiple"`) and the
/// RMS 7.5e-4 over these and two paper-like faces
/// (examples/near_index_totals.rs, 480k walks). GGX 1.03 with `m` 0.3 and
/// 1.05 with 1.3 (a corner of the fit's bounds) were refused until Newton's
/// method finished the normalisation (crates/slab/src/interface.rs,
/// `newton_scaling`, 2026-12-07); with them, and five more faces built
/// since then, the same example's RMS is 8.2e-4 over 56 totals (9.1e-4
/// before the normalisation took the face's own albedo,
/// `interface::walter_albedo`; the first set's 7.5e-4 and 2.3e-3 then
/// 7.5e-4 and 2.1e-3).
///
/// **Tolerance** `3 sigma + 1.5e-3` ([`NEAR_INDEX_TOLERANCE`]), half the
/// test above's: these faces reflect little (Fresnel 3.2e-3 at normal
/// incidence for eta 1.12, against 0.04 for 1.5), so the error of the
/// faces' split between R and T, which most of that test's 3e-3 holds
/// (2.2e-3), is smaller by as much; the discretisation's 5.6e-4 stays.
/// The nodes' values alone fail it (checked with the projection of the
/// commit before: 85.5 degrees, Beckmann 1.12, `"multiple"`).
/// The tolerance of [`near_index_matched_faces_agree_with_the_simulator`]
/// beyond 3 sigma (its doc).
const NEAR_INDEX_TOLERANCE: f64 = 1.5e-3;

#[test]
fn near_index_matched_faces_agree_with_the_simulator() {
    let disc = Discretisation::default();
    let mut worst = f64::NEG_INFINITY;
    for fs in [FaceScattering::Single, FaceScattering::Multiple] {
        for (eta, m, dist) in [
            (1.1, 0.05, Distribution::Ggx),
            (1.12, 0.1, Distribution::Beckmann),
            (1.05, 0.3, Distribution::Ggx),
            (1.08, 0.8, Distribution::Ggx),
            (1.03, 0.3, Distribution::Ggx),
            (1.05, 1.3, Distribution::Ggx),
        ] {
            let p = with_both_faces(sheet(0.01, 200.0, 0.5, fs), eta, m, dist);
            let sol = SlabSpec::from_params(&p, 0).unwrap().solve(&disc).unwrap();
            let slab = Slab::from_params(&p).unwrap();
            let g = &sol.outside;
            for j in [g.len() - 1, 20, 10, 5] {
                let mu = g.mu[j];
                let wi = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let label = format!("{fs:?} eta {eta} {dist:?} m {m} theta {:.1}", mu.acos().to_degrees());
                let sim = simulated_totals(&slab, wi, 240_000, 29 + j as u64);
                let excess = check_totals(&label, sol.totals_collimated(Side::Front, j), sim, NEAR_INDEX_TOLERANCE);
                worst = worst.max(excess);
            }
        }
    }
    println!("largest |slab - simulator| - 3 sigma: {worst:+.1e} (allowed {NEAR_INDEX_TOLERANCE:.1e})");
}
