//! Would a quadratic interpolation on the triangles take out the node
//! change that the linear one leaves (docs/slab.md, "luster and devB at 80
//! degrees" and the thin sheets' forward lobe)? In-plane values of `eval`
//! at the 32 nodes (less the analytic surface lobe in reflection),
//! interpolated on each triangle of node pairs (the cell split along
//! `t_o = t_i`, as `eval` splits it) by quadratic Lagrange weights: the
//! three corners and the midpoints of the three edges, each midpoint the
//! cubic through the four nodes along its edge's line of nodes (in `mu`;
//! along the diagonal the line of pairs `(o + k, j + k)` in the mean of
//! the two `mu`; three or two nodes at the ends of the grid). Printed per
//! point: the change of the whole value against 128 nodes' `eval`, for
//! `eval` on 32 nodes, the same triangles with linear weights (this
//! example's own, as a check: equal to `eval` outside the sine law's band,
//! which it does not apply), and the quadratic ones.
//!
//! A probe, not a model: no rebalance of the energy, no sine law within
//! 45 degrees of the normal (so its numbers there are not `eval`'s), nine
//! node pairs per point where `eval` sums three. docs/slab.md gives the numbers
//! of 2026-12-07.
//!
//! `cargo run --release -p paperbsdf-slab --example quadratic_triangles [CASE...]`

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::models::{Component, ComponentModel};
use paperbsdf_core::{Bsdf, FaceScattering, PaperParams};
use paperbsdf_slab::SlabBsdf;

#[path = "../../sim/examples/support/cases.rs"]
mod cases;
#[path = "../tests/support/mod.rs"]
mod support;

/// The whole value and the table's part (less the surface lobe in reflection).
fn table(b: &SlabBsdf, ti: f64, to: f64, tr: bool) -> (f64, f64) {
    let (wi, wo) = in_plane_directions(ti, to, tr);
    let v = b.eval(wi, wo).mean();
    let s = if tr {
        0.0
    } else {
        b.eval_component(wi, wo, Component::Surface).mean()
    };
    (v, v - s)
}

/// The Lagrange polynomial through `(xs, ys)` at `x`.
fn lagrange(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    (0..xs.len())
        .map(|i| {
            let l: f64 = (0..xs.len())
                .filter(|&j| j != i)
                .map(|j| (x - xs[j]) / (xs[i] - xs[j]))
                .product();
            l * ys[i]
        })
        .sum()
}

/// The cubic (or lower, at the ends) through the points `k = -1..=2` of a
/// line of nodes that exist, at the middle of `k = 0` and `k = 1`.
fn midpoint(at: impl Fn(isize) -> Option<(f64, f64)>) -> f64 {
    let pts: Vec<(f64, f64)> = (-1..=2).filter_map(&at).collect();
    let (xs, ys): (Vec<f64>, Vec<f64>) = pts.into_iter().unzip();
    let (a, b) = (at(0).expect("edge start").0, at(1).expect("edge end").0);
    lagrange(&xs, &ys, 0.5 * (a + b))
}

type Set = (&'static str, FaceScattering, bool, Vec<(f64, f64)>);

fn main() {
    let cases = cases::cases();
    let only: Vec<String> = std::env::args().skip(1).collect();
    let get = |n: &str| cases.iter().find(|c| c.0 == n).expect("case").1.clone();
    let half = |a: f64, k: usize| a + 0.5 * k as f64;
    let sets: Vec<Set> = vec![
        (
            "devB",
            FaceScattering::Multiple,
            false,
            (0..=30).map(|k| (half(70.0, k), -half(70.0, k))).collect(),
        ),
        (
            "preset-luster",
            FaceScattering::Multiple,
            false,
            (0..=40).map(|k| (71.0, -half(60.0, k))).collect(),
        ),
        (
            "preset-matte",
            FaceScattering::Multiple,
            false,
            (0..=40).map(|k| (62.0, -half(60.0, k))).collect(),
        ),
        (
            "very-rough",
            FaceScattering::Single,
            true,
            (0..=40).map(|k| (half(60.0, k), -79.0)).collect(),
        ),
        (
            "weak-scatter",
            FaceScattering::Single,
            true,
            (0..=40).map(|k| (30.0, -half(20.0, k))).collect(),
        ),
    ];
    for (name, fs, tr, points) in sets {
        if !only.is_empty() && !only.iter().any(|a| a == name) {
            continue;
        }
        let p = PaperParams {
            face_scattering: fs,
            ..get(name)
        };
        let coarse = SlabBsdf::new(&p).expect("build");
        let fine = support::with_nodes_times(&p, 4);
        let mu = coarse.nodes().to_vec();
        let n = mu.len() as isize;
        let theta = |k: isize| mu[k as usize].acos().to_degrees();
        let inside = |k: isize| (0..n).contains(&k);
        // Interval and fraction of `theta` among the nodes (ascending `mu`).
        let at = |t: f64| {
            let m = t.to_radians().cos();
            let k = mu.iter().position(|&x| x > m).unwrap_or(mu.len() - 1).max(1);
            (k as isize - 1, ((m - mu[k - 1]) / (mu[k] - mu[k - 1])).clamp(0.0, 1.0))
        };
        let interpolate = |ti: f64, to: f64| -> (f64, f64) {
            let sign = if to < 0.0 { -1.0 } else { 1.0 };
            let f = |j: isize, o: isize| table(&coarse, theta(j), sign * theta(o), tr).1;
            let ((j, y), (o, x)) = (at(ti), at(to.abs()));
            let line = |dj: isize, do_: isize, j0: isize, o0: isize| {
                midpoint(|k| {
                    let (jj, oo) = (j0 + dj * k, o0 + do_ * k);
                    (inside(jj) && inside(oo)).then(|| {
                        let m = if dj == 0 {
                            mu[oo as usize]
                        } else if do_ == 0 {
                            mu[jj as usize]
                        } else {
                            0.5 * (mu[jj as usize] + mu[oo as usize])
                        };
                        (m, f(jj, oo))
                    })
                })
            };
            let (c00, c11, diag) = (f(j, o), f(j + 1, o + 1), line(1, 1, j, o));
            // The third corner and the two edges along the grid lines.
            let (l0, l1, l2, c, m01, m12) = if x >= y {
                (1.0 - x, x - y, y, f(j, o + 1), line(0, 1, j, o), line(1, 0, j, o + 1))
            } else {
                (1.0 - y, y - x, x, f(j + 1, o), line(1, 0, j, o), line(0, 1, j + 1, o))
            };
            let linear = l0 * c00 + l1 * c + l2 * c11;
            let quadratic = l0 * (2.0 * l0 - 1.0) * c00
                + l1 * (2.0 * l1 - 1.0) * c
                + l2 * (2.0 * l2 - 1.0) * c11
                + 4.0 * (l0 * l1 * m01 + l1 * l2 * m12 + l0 * l2 * diag);
            (linear, quadratic)
        };
        println!(
            "{name} ({}): change against 128 nodes: eval on 32, linear, quadratic",
            fs.name()
        );
        let (mut worst_eval, mut worst_lin, mut worst_quad) = (0.0f64, 0.0f64, 0.0f64);
        for (ti, to) in points {
            let (v32, t32) = table(&coarse, ti, to, tr);
            let (v128, _) = table(&fine, ti, to, tr);
            let (lin, quad) = interpolate(ti, to);
            let change = |v: f64| 100.0 * (v / v128 - 1.0);
            let (e, l, q) = (change(v32), change(v32 - t32 + lin), change(v32 - t32 + quad));
            worst_eval = worst_eval.max(e.abs());
            worst_lin = worst_lin.max(l.abs());
            worst_quad = worst_quad.max(q.abs());
            println!(
                "  ({ti:.1} {} {to:.1}): {v128:.4}  eval {e:+.2}%  linear {l:+.2}%  quadratic {q:+.2}%",
                if tr { "T" } else { "R" }
            );
        }
        println!("  largest: eval {worst_eval:.2}%, linear {worst_lin:.2}%, quadratic {worst_quad:.2}%");
    }
}
