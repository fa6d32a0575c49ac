//! Would a better interpolation between the nodes take out the node change
//! of grazing reflection with multiple-scattering faces (docs/slab.md, "luster and
//! devB at 80 degrees")? The table's part of `eval` (less the analytic
//! surface lobe) on 32 nodes, re-interpolated two ways and compared with
//! 128 nodes:
//! - *envelope*: times `h(mu_i) h(mu_o)` with `h = geo(E) / lerp(E)`
//!   between two nodes, `E_k = sqrt(t(theta_k, theta_k))` the table's part
//!   on the mirror diagonal at node `k`: geometric instead of linear
//!   interpolation of the diagonal's steep rise, in a separable form that
//!   the crossing shapes could carry;
//! - *geometric*: the triangle's three corners (node pairs, read with
//!   `eval` at the nodes) combined with the same weights geometrically.
//!
//! No rebalance of the energy (both factors are at most 1). Neither
//! reaches the 0.2% target (docs/slab.md gives the numbers of 2026-12-07): the
//! walk's peak needs more nodes, not another interpolation.
//!
//! `cargo run --release -p paperbsdf-slab --example grazing_envelope`

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::models::{Component, ComponentModel};
use paperbsdf_core::{Bsdf, FaceScattering, PaperParams};
use paperbsdf_slab::SlabBsdf;

#[path = "../../sim/examples/support/cases.rs"]
mod cases;
#[path = "../tests/support/mod.rs"]
mod support;

fn table(b: &SlabBsdf, ti: f64, to: f64) -> (f64, f64) {
    let (wi, wo) = in_plane_directions(ti, to, false);
    let v = b.eval(wi, wo).mean();
    (v, v - b.eval_component(wi, wo, Component::Surface).mean())
}

fn main() {
    let cases = cases::cases();
    let get = |n: &str| cases.iter().find(|c| c.0 == n).expect("case").1.clone();
    for (name, points) in [
        (
            "devB",
            (0..=30)
                .map(|k| 70.0 + 0.5 * k as f64)
                .map(|t| (t, -t))
                .collect::<Vec<_>>(),
        ),
        ("preset-luster", (0..=20).map(|k| (71.0, -60.0 - k as f64)).collect()),
        ("preset-matte", (0..=20).map(|k| (62.0, -60.0 - k as f64)).collect()),
    ] {
        let p = PaperParams {
            face_scattering: FaceScattering::Multiple,
            ..get(name)
        };
        let coarse = SlabBsdf::new(&p).expect("build");
        let fine = support::with_nodes_times(&p, 4);
        let mu = coarse.nodes().to_vec();
        let e: Vec<f64> = mu
            .iter()
            .map(|m| {
                let t = m.acos().to_degrees();
                table(&coarse, t, -t).1.max(1e-300).sqrt()
            })
            .collect();
        let h = |theta: f64| {
            let m = theta.to_radians().cos();
            match mu.iter().position(|&x| x > m) {
                Some(k) if k > 0 => {
                    let f = (m - mu[k - 1]) / (mu[k] - mu[k - 1]);
                    let (a, b) = (e[k - 1], e[k]);
                    a.powf(1.0 - f) * b.powf(f) / ((1.0 - f) * a + f * b)
                }
                _ => 1.0,
            }
        };
        // Interval and fraction of `theta` among the nodes (ascending `mu`).
        let at = |theta: f64| {
            let m = theta.to_radians().cos();
            let k = mu.iter().position(|&x| x > m).unwrap_or(mu.len() - 1).max(1);
            (k - 1, ((m - mu[k - 1]) / (mu[k] - mu[k - 1])).clamp(0.0, 1.0))
        };
        let theta_of = |k: usize| mu[k].acos().to_degrees();
        // The triangle's corners combined geometrically instead of linearly.
        let geometric = |ti: f64, to: f64, t32: f64| {
            let ((j, tj), (o, t_o)) = (at(ti), at(to.abs()));
            let (corners, w) = if t_o >= tj {
                ([(0, 0), (1, 0), (1, 1)], [1.0 - t_o, t_o - tj, tj])
            } else {
                ([(0, 0), (0, 1), (1, 1)], [1.0 - tj, tj - t_o, t_o])
            };
            let c = corners.map(|(a, b)| table(&coarse, theta_of(j + b), -theta_of(o + a)).1);
            let lin: f64 = (0..3).map(|k| w[k] * c[k]).sum();
            let geo: f64 = (0..3).map(|k| c[k].max(1e-300).powf(w[k])).product();
            t32 * geo / lin
        };
        println!("{name}: whole and table's part, 32 nodes linear, with the envelope and geometric, against 128");
        let (mut worst_lin, mut worst_env, mut worst_geo) = (0.0f64, 0.0f64, 0.0f64);
        for (ti, to) in points {
            let (v32, t32) = table(&coarse, ti, to);
            let (v128, t128) = table(&fine, ti, to);
            let t_env = t32 * h(ti) * h(to.abs());
            let v_env = v32 - t32 + t_env;
            let t_geo = geometric(ti, to, t32);
            let v_geo = v32 - t32 + t_geo;
            let (el, ee, eg) = (
                100.0 * (v32 / v128 - 1.0),
                100.0 * (v_env / v128 - 1.0),
                100.0 * (v_geo / v128 - 1.0),
            );
            worst_lin = worst_lin.max(el.abs());
            worst_env = worst_env.max(ee.abs());
            worst_geo = worst_geo.max(eg.abs());
            println!(
                "  ({ti:.1} R {to:.1}): whole linear {el:+.2}% envelope {ee:+.2}% geometric {eg:+.2}%   table {t128:.4}: linear {:+.2}% envelope {:+.2}% geometric {:+.2}%",
                100.0 * (t32 / t128 - 1.0),
                100.0 * (t_env / t128 - 1.0),
                100.0 * (t_geo / t128 - 1.0)
            );
        }
        println!("  largest change of the whole: linear {worst_lin:.2}%, envelope {worst_env:.2}%, geometric {worst_geo:.2}%");
    }
}
