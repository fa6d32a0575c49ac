//! The non-absorbing thick sheet of issue 14 (sigma_a 0.001, sigma_s 3000, d 0.18,
//! eta 1.5, GGX faces of roughness m) in the simulator: R and T at normal
//! incidence for both face modes.
//! `cargo run --release -p paperbsdf-sim --example white [walks]`
use paperbsdf_core::{Colour, DVec3, Distribution, FaceScattering, PaperParams};
use paperbsdf_sim::{simulate_totals, Incidence, SimConfig, Slab};

fn main() {
    let walks: u64 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(16384);
    let cfg = SimConfig {
        samples: walks,
        batches: 32,
        seed: 14,
        progress: true,
        ..Default::default()
    };
    println!("| m | face_scattering | R (normal incidence) | T | R + T |");
    println!("|---|---|---|---|---|");
    for fs in [FaceScattering::Single, FaceScattering::Multiple] {
        for m in [0.05, 0.2, 0.48, 0.8] {
            let p = PaperParams {
                name: None,
                d: 0.18,
                sigma_a: Colour::Scalar(0.001),
                sigma_s: Colour::Scalar(3000.0),
                g_f: 0.0,
                g_b: 0.0,
                w_b: 0.0,
                eta_f: 1.5,
                eta_b: 1.5,
                m_f: m,
                m_b: m,
                dist_f: Distribution::Ggx,
                dist_b: Distribution::Ggx,
                face_scattering: fs,
            };
            let slab = Slab::from_params(&p).expect("valid parameters");
            let t = simulate_totals(&slab, Incidence::Collimated(DVec3::Z), &cfg).expect("valid run");
            let (r, tt) = (t.reflectance, t.transmittance);
            println!(
                "| {m} | {} | {:.4} +- {:.4} | {:.4} +- {:.4} | {:.4} |",
                fs.name(),
                r.mean.0[0],
                r.stderr.0[0],
                tt.mean.0[0],
                tt.stderr.0[0],
                r.mean.0[0] + tt.mean.0[0]
            );
        }
    }
}
