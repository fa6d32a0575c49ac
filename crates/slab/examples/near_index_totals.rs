//! Total reflectance of a thin sheet (d 0.01 mm, `sigma_s` 200 /mm,
//! `sigma_a` 0.5 /mm, the matte preset's phase function) with both faces
//! alike, against the simulator: faces close to index-matched (Beckmann
//! eta 1.12 m 0.1, GGX 1.1 m 0.05, GGX 1.05 m 0.3) and two paper-like ones
//! (Beckmann 1.5 m 0.1, GGX 1.5 m 0.15), and with `--newton` instead the
//! seven faces the normalisation refused until Newton's method finished it
//! (2026-12-07: GGX 1.05 m 1.3 and 0.05, 1.03 and 1.01 m 0.3, 1.08 m 0.02,
//! Beckmann 1.1 m 0.05, 1.02 m 0.1), both face modes, lit on the front
//! at the outside nodes of 0, 43.5, 75.3 and 85.5 degrees (default 32
//! nodes; the simulator gets the node's exact direction). Prints `slab -
//! simulator` in units of the simulator's standard error and the RMS
//! difference over all of them (docs/slab.md, "Faces close to index-matched";
//! `crates/slab/src/interface.rs`, "Narrow transmission lobes").
//!
//! `cargo run --release -p paperbsdf-slab --example near_index_totals [--newton] [WALKS]`
//! (480,000 walks by default, about a minute on two cores; two with `--newton`).

#[path = "../tests/support/mod.rs"]
mod support;

use paperbsdf_core::{Colour, DVec3, Distribution, FaceScattering, PaperParams};
use paperbsdf_sim::Slab;
use paperbsdf_slab::{Discretisation, Side, SlabSpec};
use support::{simulated_totals, with_both_faces};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let newton = args.iter().any(|a| a == "--newton");
    let walks: u64 = args
        .iter()
        .find(|a| *a != "--newton")
        .map_or(480_000, |v| v.parse().expect("WALKS: a count of walks"));
    let faces: &[(f64, f64, Distribution)] = if newton {
        &[
            (1.05, 1.3, Distribution::Ggx),
            (1.05, 0.05, Distribution::Ggx),
            (1.03, 0.3, Distribution::Ggx),
            (1.01, 0.3, Distribution::Ggx),
            (1.08, 0.02, Distribution::Ggx),
            (1.1, 0.05, Distribution::Beckmann),
            (1.02, 0.1, Distribution::Beckmann),
        ]
    } else {
        &[
            (1.12, 0.1, Distribution::Beckmann),
            (1.1, 0.05, Distribution::Ggx),
            (1.05, 0.3, Distribution::Ggx),
            (1.5, 0.1, Distribution::Beckmann),
            (1.5, 0.15, Distribution::Ggx),
        ]
    };
    let (mut sum2, mut n) = (0.0, 0usize);
    for fs in [FaceScattering::Single, FaceScattering::Multiple] {
        for &(eta, m, dist) in faces {
            let thin = PaperParams {
                d: 0.01,
                sigma_s: Colour::Scalar(200.0),
                sigma_a: Colour::Scalar(0.5),
                face_scattering: fs,
                ..paperbsdf_core::presets::matte_office()
            };
            let p = with_both_faces(thin, eta, m, dist);
            let sol = match SlabSpec::from_params(&p, 0).and_then(|s| s.solve(&Discretisation::default())) {
                Ok(sol) => sol,
                Err(e) => {
                    println!("{fs:?} {dist:?} eta {eta} m {m}: {e}");
                    continue;
                }
            };
            let slab = Slab::from_params(&p).expect("the simulator's slab");
            let g = &sol.outside;
            for j in [g.len() - 1, 20, 10, 5] {
                let mu = g.mu[j];
                let wi = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let (r, _) = sol.totals_collimated(Side::Front, j);
                let (sr, se_r, _, _) = simulated_totals(&slab, wi, walks, 29 + j as u64);
                println!(
                    "{fs:?} {dist:?} eta {eta} m {m}, theta {:.1}: slab R {r:.4}, simulator {sr:.4} +- {se_r:.4}: {:+.4} ({:+.1} sigma)",
                    mu.acos().to_degrees(),
                    r - sr,
                    (r - sr) / se_r
                );
                sum2 += (r - sr).powi(2);
                n += 1;
            }
        }
    }
    println!(
        "RMS of slab - simulator over {n} totals: {:.2e}",
        (sum2 / n as f64).sqrt()
    );
}
