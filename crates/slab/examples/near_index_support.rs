//! Which faces close to index-matched `slab` builds and which it refuses
//! (`SlabError::UnresolvedFace`; docs/slab.md, "Faces close to index-matched"):
//! the matte preset with both faces of index `eta` and roughness `m`, both
//! distributions and both face modes, default discretisation; then the
//! corners of the fit's bounds (`eta` 1.05 and 3, `m` 0.01 and `pi / 2`,
//! `paperbsdf-fit`'s `paper` model). With `--more-nodes`, each face the
//! grid refuses is tried again with 64 and 128 nodes (the error's advice).
//!
//! `cargo run --release -p paperbsdf-slab --example near_index_support`
//! (about two minutes on two cores; `--more-nodes` adds a few).

#[path = "../tests/support/mod.rs"]
mod support;

use paperbsdf_core::{Distribution, FaceScattering, PaperParams};
use paperbsdf_slab::SlabBsdf;
use support::with_both_faces;

/// One line per face mode, distribution and `eta` of `etas`: whether the
/// matte preset with both faces so is built at each roughness of `ms`;
/// the refused faces, returned.
fn grid(etas: &[f64], ms: &[f64]) -> Vec<PaperParams> {
    let mut refused = Vec::new();
    let base = paperbsdf_core::presets::matte_office();
    for fs in [FaceScattering::Single, FaceScattering::Multiple] {
        for dist in [Distribution::Ggx, Distribution::Beckmann] {
            for &eta in etas {
                let mut line = format!("{:8} {:8} eta {eta:<5}:", fs.name(), dist.name());
                for &m in ms {
                    let p = with_both_faces(
                        PaperParams {
                            face_scattering: fs,
                            ..base.clone()
                        },
                        eta,
                        m,
                        dist,
                    );
                    let built = SlabBsdf::new(&p).is_ok();
                    line += &format!("  m {m} {}", if built { "built" } else { "REFUSED" });
                    if !built {
                        refused.push(p);
                    }
                }
                println!("{line}");
            }
        }
    }
    refused
}

fn main() {
    let more_nodes = std::env::args().any(|a| a == "--more-nodes");
    let refused = grid(
        &[1.001, 1.01, 1.02, 1.03, 1.05, 1.08, 1.1, 1.11, 1.12],
        &[0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.8, 1.2],
    );
    println!("the corners of the fit's bounds:");
    grid(&[1.05, 3.0], &[0.01, std::f64::consts::FRAC_PI_2]);
    if more_nodes {
        println!("the refused faces with more nodes:");
        for p in &refused {
            let mut line = format!(
                "{:8} {:8} eta {:<5} m {:<4}:",
                p.face_scattering.name(),
                p.dist_f.name(),
                p.eta_f,
                p.m_f
            );
            for k in [2usize, 4] {
                let opts = support::options_times(k);
                let built = SlabBsdf::with_options(p, &opts).is_ok();
                line += &format!("  {} nodes {}", opts.nodes, if built { "built" } else { "REFUSED" });
            }
            println!("{line}");
        }
    }
}
