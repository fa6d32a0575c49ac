//! Which faces close to index-matched `slab` builds and which it refuses
//! (`SlabError::UnresolvedFace`; README, "Faces close to index-matched"):
//! the matte preset with both faces of index `eta` and roughness `m`, both
//! distributions and both face modes, default discretisation; then the
//! corners of the fit's bounds (`eta` 1.05 and 3, `m` 0.01 and `pi / 2`,
//! `paperbsdf-fit`'s `paper` model).
//!
//! `cargo run --release -p paperbsdf-slab --example near_index_support`
//! (about two minutes on two cores).

#[path = "../tests/support/mod.rs"]
mod support;

use paperbsdf_core::{Distribution, FaceScattering, PaperParams};
use paperbsdf_slab::SlabBsdf;
use support::with_both_faces;

fn main() {
    let base = paperbsdf_core::presets::matte_office();
    for fs in [FaceScattering::Single, FaceScattering::Multiple] {
        for dist in [Distribution::Ggx, Distribution::Beckmann] {
            for eta in [1.001, 1.01, 1.02, 1.03, 1.05, 1.08, 1.1, 1.11, 1.12] {
                let mut line = format!("{:8} {:8} eta {eta:<5}:", fs.name(), dist.name());
                for m in [0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.8, 1.2] {
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
                }
                println!("{line}");
            }
        }
    }
    println!("the corners of the fit's bounds:");
    for fs in [FaceScattering::Single, FaceScattering::Multiple] {
        for dist in [Distribution::Ggx, Distribution::Beckmann] {
            for eta in [1.05, 3.0] {
                let mut line = format!("{:8} {:8} eta {eta:<5}:", fs.name(), dist.name());
                for m in [0.01, std::f64::consts::FRAC_PI_2] {
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
                }
                println!("{line}");
            }
        }
    }
}
