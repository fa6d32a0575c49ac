//! Where the remaining node changes of examples/convergence.rs come from
//! (docs/slab.md, "Convergence"): the same in-plane `eval` on 32, 64 and 128
//! nodes (16, 32, 64 in the cone of total reflection) at the points that
//! move most, and beside them the checks that tell the causes apart:
//! - the coated sheets with a front smoother than the grid (glossy, devB)
//!   at and near normal incidence, and the same sheets uncoated (the base's
//!   index set to the coating's);
//! - thin tissue lit at 30 degrees, seen at the two nodes around 10 degrees
//!   (8.87 and 12.85 with 32 nodes) and at 10 degrees between them, around
//!   its straight-through peak, and 2.5 degrees either side of the normal;
//! - thin tissue lit at 2.5 degrees (inside the last interval of nodes),
//!   seen from -20 to 20 degrees;
//! - thin tissue's and weak scatter's transmission on the dense in-plane
//!   grid of examples/convergence.rs, 32 against 64 nodes: the largest
//!   change of the value, and of the value without the unscattered part
//!   (component `direct`), relative to the value: what an exact unscattered
//!   term would leave (2026-12-06: 10.6% and 1.1%, 4.7% and 0.7%);
//! - near grazing reflection with multiple-scattering faces (docs/slab.md, "luster
//!   and devB at 80 degrees"): devB on the mirror diagonal from 60 to 85
//!   degrees, luster lit at 71 and matte at 62 (between nodes) seen from
//!   -60 to -80: the whole value and the table's part (`eval` less the lit
//!   face's first reflection, component `surface`), 32 and 64 nodes
//!   against 128; and the same points on the face alone: the sheet made
//!   black and uncoated (`sigma_a` 2000 /mm, `sigma_s` 1e-3 /mm, `eta_b =
//!   eta_f`), where the table's part is only the lit face's walk (its
//!   light scattered twice or more on the microsurface and leaving
//!   outside), to tell the walk's share of the node change from the
//!   medium's.
//!
//! `cargo run --release -p paperbsdf-slab --example convergence_causes`

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::models::{Component, ComponentModel};
use paperbsdf_core::{Bsdf, Colour, FaceScattering, PaperParams};
use paperbsdf_slab::SlabBsdf;

// The cases of docs/accuracy.md, as the accuracy example has them.
#[path = "../../sim/examples/support/cases.rs"]
mod cases;
#[path = "../tests/support/mod.rs"]
mod support;

/// The sheet `p` built with `k` times the default nodes (and nodes in the
/// cone of total reflection) for each `k` of `times`.
fn with_nodes_times(p: &PaperParams, times: &[usize]) -> Vec<SlabBsdf> {
    times.iter().map(|&k| support::with_nodes_times(p, k)).collect()
}

/// `eval` (mean over channels) on 32, 64 and 128 nodes at `(theta_i, theta_o, transmit)`.
fn row(p: &PaperParams, points: &[(f64, f64, bool)]) {
    let bsdfs = with_nodes_times(p, &[1, 2, 4]);
    for &(ti, to, tr) in points {
        let (wi, wo) = in_plane_directions(ti, to, tr);
        let v: Vec<f64> = bsdfs.iter().map(|b| b.eval(wi, wo).mean()).collect();
        println!(
            "  ({ti:.2} {} {to:.2}): 32 {:.5}  64 {:.5}  128 {:.5}   32/64 {:+.2}%  64/128 {:+.2}%",
            if tr { "T" } else { "R" },
            v[0],
            v[1],
            v[2],
            100.0 * (v[0] / v[1] - 1.0),
            100.0 * (v[1] / v[2] - 1.0)
        );
    }
}

/// Reflection (multiple-scattering faces) at `(theta_i, theta_o)`: the
/// whole value on 32, 64 and 128 nodes, and the changes of the whole and
/// of the table's part (`eval` less component `surface`, the lit face's
/// first reflection, which is analytic) from 32 and 64 nodes to 128.
fn table_part(p: &PaperParams, points: &[(f64, f64)]) {
    let p = PaperParams {
        face_scattering: FaceScattering::Multiple,
        ..p.clone()
    };
    let bsdfs = with_nodes_times(&p, &[1, 2, 4]);
    for &(ti, to) in points {
        let (wi, wo) = in_plane_directions(ti, to, false);
        let v: Vec<f64> = bsdfs.iter().map(|b| b.eval(wi, wo).mean()).collect();
        let t: Vec<f64> = bsdfs
            .iter()
            .zip(&v)
            .map(|(b, v)| v - b.eval_component(wi, wo, Component::Surface).mean())
            .collect();
        println!(
            "  ({ti:.1} R {to:.1}): 32 {:.4}  64 {:.4}  128 {:.4}   whole 32 {:+.2}% 64 {:+.2}%   table {:.4}: 32 {:+.2}% 64 {:+.2}%",
            v[0],
            v[1],
            v[2],
            100.0 * (v[0] / v[2] - 1.0),
            100.0 * (v[1] / v[2] - 1.0),
            t[2],
            100.0 * (t[0] / t[2] - 1.0),
            100.0 * (t[1] / t[2] - 1.0)
        );
    }
}

/// Transmission (light on the front) on the dense in-plane grid, 32 against
/// 64 nodes: the largest relative change of the value and of the value
/// less its unscattered part, both relative to the value (values above
/// 1e-3 of the largest).
fn scattered_alone(name: &str, p: &PaperParams) {
    let b = with_nodes_times(p, &[1, 2]);
    let mut rows = Vec::new();
    for ti in (0..=160).map(|k| 0.5 * k as f64) {
        for to in (-160..=160).map(|k| 0.5 * k as f64) {
            let (wi, wo) = in_plane_directions(ti, to, true);
            let [(t0, s0), (t1, s1)] = [&b[0], &b[1]].map(|b| {
                let t = b.eval(wi, wo).mean();
                (t, t - b.eval_component(wi, wo, Component::Direct).mean())
            });
            rows.push((ti, to, t0, t1, s0, s1));
        }
    }
    let largest = rows.iter().map(|r| r.3).fold(0.0, f64::max);
    let (mut total, mut scattered) = ((0.0f64, 0.0, 0.0), (0.0f64, 0.0, 0.0));
    for &(ti, to, t0, t1, s0, s1) in rows.iter().filter(|r| r.3 >= 1e-3 * largest) {
        let e = (t0 / t1 - 1.0).abs();
        if e > total.0 {
            total = (e, ti, to);
        }
        let e = ((s0 - s1) / t1).abs();
        if e > scattered.0 {
            scattered = (e, ti, to);
        }
    }
    println!(
        "{name}, transmission, 32 against 64 nodes: the value by {:.2}% (at {} T {}), without its unscattered part by {:.2}% of the value (at {} T {})",
        100.0 * total.0,
        total.1,
        total.2,
        100.0 * scattered.0,
        scattered.1,
        scattered.2
    );
}

fn main() {
    let cases = cases::cases();
    let get = |n: &str| cases.iter().find(|c| c.0 == n).expect("case").1.clone();
    for name in ["preset-glossy", "devB"] {
        let p = get(name);
        let pts = [(0.0, 0.0, false), (2.5, 2.5, false)];
        println!("{name}, coated (eta_f {} over eta_b {}):", p.eta_f, p.eta_b);
        row(&p, &pts);
        println!("{name}, uncoated (eta_b = eta_f):");
        row(&PaperParams { eta_b: p.eta_f, ..p }, &pts);
    }
    let t = get("thin-tissue");
    let nodes = SlabBsdf::new(&t).expect("build").nodes().to_vec();
    let n = nodes.len();
    let (a, b) = (nodes[n - 3].acos().to_degrees(), nodes[n - 4].acos().to_degrees());
    println!("thin-tissue lit at 30, seen at the nodes {a:.2} and {b:.2} and between them:");
    row(&t, &[(30.0, a, true), (30.0, 10.0, true), (30.0, b, true)]);
    println!("thin-tissue lit at 30, seen around the straight-through peak (-30) and near the normal:");
    let pts: Vec<(f64, f64, bool)> = [-34.0, -32.0, -30.0, -28.0, -26.0, -2.5, 2.5]
        .iter()
        .map(|&to| (30.0, to, true))
        .collect();
    row(&t, &pts);
    println!(
        "thin-tissue lit at 2.5 (the last interval of nodes ends at {:.2}):",
        nodes[n - 2].acos().to_degrees()
    );
    let pts: Vec<(f64, f64, bool)> = (-8..=8).map(|k| (2.5, 2.5 * k as f64, true)).collect();
    row(&t, &pts);
    for name in ["thin-tissue", "weak-scatter"] {
        scattered_alone(name, &get(name));
    }
    // The face alone: no light comes back from a black medium, and
    // `eta_b = eta_f` removes a coating's boundary.
    let black = |p: PaperParams| PaperParams {
        sigma_a: Colour::Scalar(2000.0),
        sigma_s: Colour::Scalar(1e-3),
        eta_b: p.eta_f,
        ..p
    };
    println!("devB on the mirror diagonal, multiple-scattering faces (the table's part: the walk's peak):");
    let pts: Vec<(f64, f64)> = (0..=50).map(|k| 60.0 + 0.5 * k as f64).map(|t| (t, -t)).collect();
    table_part(&get("devB"), &pts);
    println!("devB's face alone (black, uncoated) on the mirror diagonal (the table's part: the walk alone):");
    let pts: Vec<(f64, f64)> = (0..=10).map(|k| 70.0 + 1.5 * k as f64).map(|t| (t, -t)).collect();
    table_part(&black(get("devB")), &pts);
    for (name, ti) in [("preset-luster", 71.0), ("preset-matte", 62.0)] {
        println!("{name} lit at {ti}, between nodes, multiple-scattering faces:");
        let pts: Vec<(f64, f64)> = (0..=20).map(|k| (ti, -60.0 - k as f64)).collect();
        table_part(&get(name), &pts);
        println!("{name}'s face alone (black, uncoated) lit at {ti}:");
        let pts: Vec<(f64, f64)> = (0..=10).map(|k| (ti, -60.0 - 2.0 * k as f64)).collect();
        table_part(&black(get(name)), &pts);
    }
}
