//! The simulator against Mitsuba 3's volumetric path tracer (`data/reference/devA.csv`,
//! `devB.csv`: brute-force in-plane BSDF of the same physical slab, parameters in
//! `devA.json`, `devB.json`; produced by `reference/tools/genref.py`).
//!
//! A point agrees when `|f_sim - f_ref| <= 4 sqrt(se_sim^2 + se_ref^2) + 0.01 f_ref`
//! (4 combined standard errors, i.e. a two-sided 6e-5 chance per point for a
//! correct simulator, plus 1% for the reference's own residual bias); at least
//! 95% of the points must agree. 8192 walks per incident angle give the simulator
//! standard errors of about 1-2% (R) and 3-5% (T), comparable to the reference's.
//!
//! The 9 `R` rows of devA at `theta_i = 75` are not counted: there
//! Mitsuba's result is not reciprocal although the slab is (eta_f = eta_b).
//! Measured with `reference/tools/slabref.py` on this machine (8 x 16384
//! samples): R(75 -> 0) = 0.1311 +- 0.0010 but R(0 -> 75) = 0.1076 +- 0.0013;
//! R(75 -> 60) = 0.1584 but R(60 -> 75) = 0.1171; with sigma_s = 0 (surfaces
//! only) 0.0204 vs 0.0095. The reference file itself shows it: R(75, 0) = 0.127
//! while R(0, 60) = 0.118 and R(0, 80) = 0.099 bracket R(0, 75). The simulator
//! is reciprocal there (`reciprocity.rs`) and matches Mitsuba's R(0 -> 75), so
//! the suspect is Mitsuba's light-side connection at grazing incidence on a
//! rough face; see `devA_grazing_light_rows_are_reported` below for the numbers.

mod support;

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_sim::{simulate_bsdf, SimConfig, Slab};
use support::{params, read_inplane, RefRow};

/// Simulates every row of a reference file; returns (row, mean, stderr).
fn simulate_rows(name: &str, walks: u64) -> Vec<(RefRow, f64, f64)> {
    let p = params(&format!("{name}.json"));
    let slab = Slab::from_params(&p).unwrap();
    let rows = read_inplane(&format!("{name}.csv"));
    let mut out = Vec::new();
    let mut tis: Vec<f64> = rows.iter().map(|r| r.theta_i).collect();
    tis.dedup();
    for ti in tis {
        let sel: Vec<&RefRow> = rows.iter().filter(|r| r.theta_i == ti).collect();
        let wos: Vec<_> = sel
            .iter()
            .map(|r| in_plane_directions(ti, r.theta_o, r.transmission).1)
            .collect();
        let wi = in_plane_directions(ti, 0.0, false).0;
        let cfg = SimConfig {
            samples: walks,
            batches: 32,
            seed: 2024,
            ..Default::default()
        };
        let run = simulate_bsdf(&slab, wi, &wos, &cfg).unwrap();
        for (r, e) in sel.iter().zip(&run.f) {
            out.push(((*r).clone(), e.mean.0[0], e.stderr.0[0]));
        }
    }
    out
}

fn agrees(r: &RefRow, m: f64, se: f64) -> bool {
    (m - r.f).abs() <= 4.0 * (se * se + r.stderr * r.stderr).sqrt() + 0.01 * r.f
}

fn report(name: &str, res: &[(RefRow, f64, f64)]) {
    for (r, m, se) in res {
        let z = (m - r.f) / (se * se + r.stderr * r.stderr).sqrt();
        eprintln!(
            "{name} {} {:>3} {:>4}: ref {:.5} +- {:.5}  sim {:.5} +- {:.5}  z {:+.2} {}",
            if r.transmission { 'T' } else { 'R' },
            r.theta_i,
            r.theta_o,
            r.f,
            r.stderr,
            m,
            se,
            z,
            if agrees(r, *m, *se) { "" } else { "DISAGREES" }
        );
    }
}

#[test]
fn dev_b_agrees_with_mitsuba() {
    let res = simulate_rows("devB", 8192);
    report("devB", &res);
    let ok = res.iter().filter(|(r, m, se)| agrees(r, *m, *se)).count();
    eprintln!("devB: {ok} of {} points agree", res.len());
    assert!(
        ok as f64 >= 0.95 * res.len() as f64,
        "devB: only {ok} of {} points agree",
        res.len()
    );
}

#[test]
#[allow(non_snake_case)]
fn dev_a_agrees_with_mitsuba_except_grazing_light_reflection() {
    let res = simulate_rows("devA", 8192);
    report("devA", &res);
    let counted: Vec<_> = res
        .iter()
        .filter(|(r, _, _)| r.theta_i != 75.0 || r.transmission)
        .collect();
    assert_eq!(counted.len(), 63);
    let ok = counted.iter().filter(|(r, m, se)| agrees(r, *m, *se)).count();
    let all = res.iter().filter(|(r, m, se)| agrees(r, *m, *se)).count();
    eprintln!(
        "devA: {ok} of {} counted points agree ({all} of {} including R at theta_i = 75)",
        counted.len(),
        res.len()
    );
    assert!(
        ok as f64 >= 0.95 * counted.len() as f64,
        "devA: only {ok} of {} points agree",
        counted.len()
    );
    // The excluded rows: the simulator is below the reference there, by about
    // the amount that the reference's own reciprocal rows imply (R(0, 60..80)
    // brackets the reciprocal value of R(75, 0)).
    let rows = read_inplane("devA.csv");
    let r0 = |to: f64| {
        rows.iter()
            .find(|r| r.theta_i == 0.0 && !r.transmission && r.theta_o == to)
            .unwrap()
            .f
    };
    let (lo, hi) = (r0(80.0).min(r0(60.0)), r0(80.0).max(r0(60.0)));
    let sim_75_0 = res
        .iter()
        .find(|(r, _, _)| r.theta_i == 75.0 && !r.transmission && r.theta_o == 0.0)
        .unwrap();
    let ref_75_0 = sim_75_0.0.f;
    eprintln!("devA R(75, 0): reference {ref_75_0:.4}, simulator {:.4} +- {:.4}; reference R(0, 60..80) in [{lo:.4}, {hi:.4}]", sim_75_0.1, sim_75_0.2);
    assert!(
        ref_75_0 > hi,
        "the reference's R(75, 0) is above its reciprocal bracket"
    );
    assert!(
        sim_75_0.1 > lo - 4.0 * sim_75_0.2 && sim_75_0.1 < hi + 4.0 * sim_75_0.2,
        "simulator R(75, 0) outside the reciprocal bracket"
    );
}
