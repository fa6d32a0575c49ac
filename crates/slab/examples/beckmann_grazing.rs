//! The model's energy at grazing incidence for a thin sheet with Beckmann
//! faces close to index-matched (`eta` 1.1, `m` 0.05, `"single"`; d 0.01 mm,
//! `sigma_s` 200 /mm, `sigma_a` 0.5 /mm, the matte preset's phase function),
//! against the simulator: lit at the outside node nearest 85.5 degrees with
//! the default 32 nodes and nearest 86 degrees with 64 (the simulator gets
//! the node's exact direction, 480k walks). Printed: the solution's totals
//! at the node, the model's (`SlabBsdf::eval` integrated, `albedo_from`
//! with 512 x 512 draws), the simulator's, and `R + T` of the last two
//! (docs/slab.md, "Beckmann faces at grazing incidence": until the normalisation
//! took the albedo of `eval_mode`'s face, `interface::walter_albedo`, the
//! model's `R + T` was 2.1e-3 and 2.9e-3 short).
//!
//! `cargo run --release -p paperbsdf-slab --example beckmann_grazing`

#[path = "../tests/support/mod.rs"]
mod support;

use paperbsdf_core::bsdf::albedo_from;
use paperbsdf_core::{Colour, DVec3, Distribution, FaceScattering, PaperParams};
use paperbsdf_sim::Slab;
use paperbsdf_slab::{Discretisation, Side, SlabSpec};
use support::{simulated_totals, with_both_faces, with_nodes_times};

fn main() {
    let thin = PaperParams {
        d: 0.01,
        sigma_s: Colour::Scalar(200.0),
        sigma_a: Colour::Scalar(0.5),
        face_scattering: FaceScattering::Single,
        ..paperbsdf_core::presets::matte_office()
    };
    let p = with_both_faces(thin, 1.1, 0.05, Distribution::Beckmann);
    let slab = Slab::from_params(&p).expect("the simulator's slab");
    for (k, near) in [(1usize, 85.5f64), (2, 86.0)] {
        let model = with_nodes_times(&p, k);
        let base = Discretisation::default();
        let disc = Discretisation {
            nodes: k * base.nodes,
            tir_nodes: k * base.tir_nodes,
            ..base
        };
        let sol = SlabSpec::from_params(&p, 0)
            .and_then(|s| s.solve(&disc))
            .expect("the solution");
        let g = &sol.outside;
        let j = (0..g.len())
            .min_by(|&a, &b| {
                let off = |i: usize| (g.mu[i].acos().to_degrees() - near).abs();
                off(a).total_cmp(&off(b))
            })
            .expect("nodes");
        let mu = g.mu[j];
        let wi = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
        let (rs, ts) = sol.totals_collimated(Side::Front, j);
        let (r, t) = albedo_from(&model, wi, 512);
        let (r, t) = (r.mean(), t.mean());
        let (sr, se_r, st, se_t) = simulated_totals(&slab, wi, 480_000, 29 + j as u64);
        println!(
            "{} nodes, {:.1} degrees: solution R {rs:.4} T {ts:.4}; model R {r:.4} T {t:.4} (R + T {:.4}); simulator R {sr:.4} +- {se_r:.4} T {st:.4} +- {se_t:.4} (R + T {:.4})",
            g.len(),
            mu.acos().to_degrees(),
            r + t,
            sr + st
        );
    }
}
