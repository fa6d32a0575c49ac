//! Totals of smooth-faced slabs against iadpython's adding-doubling (an
//! independent program; Prahl's method in Python), asked to agree within 0.5%.
//!
//! - `tests/data/iad_smooth.csv` (made by `tests/data/iad_smooth.py`, which
//!   says why it uses 24 or 64 points): one HG lobe `g` in {0, 0.5, 0.85},
//!   smooth Fresnel faces of index `n` in {1, 1.33, 1.5} in air, albedo in
//!   {0.3, 0.9, 0.99, 1}, optical thickness in {0.1, 1, 8, 30}. Columns:
//!   `albedo, optical_thickness` (sigma_t d), `g`, `n`, `quad_pts`
//!   (iadpython's points), `UR1`, `UT1` (total reflectance and transmittance
//!   for collimated light at normal incidence, the mirror reflection of the
//!   first face and the unscattered light included), `URU`, `UTU` (the same
//!   for diffuse incidence). For conservative slabs (albedo 1) with `n > 1`
//!   iadpython's own totals do not add up to 1 (`UR1 + UT1 = 0.99869` for
//!   tau = 30, g = 0, n = 1.5; up to 2.1e-3 short), while this solver's do to
//!   1e-9 and do not move with nodes or starting thickness; so those entries
//!   are allowed 0.5% plus iadpython's own energy defect of that row.
//! - `data/reference/slab_rt_dev.csv` (16 points): the project's reference
//!   file. Its `URU` for `n > 1` is iadpython's 16-point value, which is
//!   0.5-0.8% low (iadpython itself moves to within 0.02% of this solver with
//!   64 points: 0.135356, 0.136020, 0.136103 for 16, 32, 64 points against
//!   0.136122 here, a = 0.5, tau = 40, g = 0, n = 1.5); those entries are
//!   held to 1%, as is `UR1` for g = 0.85 (a = 0.5, tau = 0.5: 0.005569 with
//!   16 points, 0.005541 with 32, and 0.005541 here); every other entry to 0.5%.
//!
//! Relative differences with an absolute floor of 1e-5 (the files' six decimals).

use paperbsdf_core::phase::TwoLobeHg;
use paperbsdf_slab::{Discretisation, Face, Medium, Side, SlabSpec};

fn read(path: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut rdr = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_path(path)
        .expect("reference file");
    let head = rdr.headers().unwrap().iter().map(String::from).collect();
    let rows = rdr
        .records()
        .map(|r| r.unwrap().iter().map(|x| x.parse().unwrap()).collect())
        .collect();
    (head, rows)
}

/// Compares every row of `path`; `tol(name, n, g)` is the allowed relative difference.
fn compare(path: &str, tol: impl Fn(&str, f64, f64) -> f64) -> f64 {
    let (head, rows) = read(path);
    let col = |name: &str| head.iter().position(|h| h == name).unwrap();
    let disc = Discretisation {
        nodes: 32,
        tir_nodes: 16,
        orders: 1,
        start_thickness: None,
        ..Default::default()
    };
    let (mut worst, mut failures) = (0.0f64, Vec::new());
    for row in &rows {
        let (a, tau, g, n) = (
            row[col("albedo")],
            row[col("optical_thickness")],
            row[col("g")],
            row[col("n")],
        );
        let spec = SlabSpec {
            medium: Medium {
                albedo: a,
                tau,
                phase: TwoLobeHg {
                    g_f: g,
                    g_b: 0.0,
                    w_b: 0.0,
                },
            },
            front: Face::Smooth { eta: n },
            back: Face::Smooth { eta: n },
        };
        let sol = spec.solve(&disc).unwrap();
        let (r1, t1) = sol.totals_normal(Side::Front);
        let (ru, tu) = sol.totals_diffuse(Side::Front);
        for (name, got) in [("UR1", r1), ("UT1", t1), ("URU", ru), ("UTU", tu)] {
            let want = row[col(name)];
            // the reference's own energy defect, for conservative slabs
            let pair = if name.ends_with('1') {
                ["UR1", "UT1"]
            } else {
                ["URU", "UTU"]
            };
            let defect = if a == 1.0 {
                (row[col(pair[0])] + row[col(pair[1])] - 1.0).abs()
            } else {
                0.0
            };
            let scale = want.abs().max(1e-5 / 0.005);
            let err = (got - want).abs() / scale;
            let t = tol(name, n, g) + defect / scale;
            if defect == 0.0 && tol(name, n, g) == 0.005 {
                worst = worst.max(err); // the worst among the entries held to 0.5%
            }
            if err > t {
                failures.push(format!(
                    "a={a} tau={tau} g={g} n={n} {name}: {got:.6} vs {want:.6} ({:+.3}%)",
                    100.0 * (got / want - 1.0)
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{path}:\n{}", failures.join("\n"));
    worst
}

#[test]
fn smooth_faces_match_iadpython_at_converged_points() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/iad_smooth.csv");
    let worst = compare(path, |_, _, _| 0.005);
    println!(
        "iad_smooth.csv: worst relative difference (entries held to 0.5%) {:.4}%",
        100.0 * worst
    );
}

#[test]
fn smooth_faces_match_the_reference_file() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/reference/slab_rt_dev.csv");
    let worst = compare(path, |name, n, g| {
        if (name == "URU" && n > 1.0) || (name == "UR1" && g == 0.85) {
            0.01
        } else {
            0.005
        }
    });
    println!(
        "slab_rt_dev.csv: worst relative difference (entries held to 0.5%) {:.4}%",
        100.0 * worst
    );
}
