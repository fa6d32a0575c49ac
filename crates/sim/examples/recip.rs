//! Reciprocity pairs f(wi, wo) vs f(wo, wi) of the simulator for devA and variants (the
//! configurations where Mitsuba's reference is not reciprocal):
//! `cargo run --release -p paperbsdf-sim --example recip -- WALKS` from the workspace root.
use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_sim::*;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: u64 = args[1].parse().unwrap();
    let text = std::fs::read_to_string("data/reference/devA.json").unwrap();
    let base: paperbsdf_core::PaperParams = serde_json::from_str(&text).unwrap();
    let cfg = SimConfig {
        samples: n,
        batches: 32,
        seed: 3,
        ..Default::default()
    };
    for v in ["devA", "nosc", "iso", "thin"] {
        let mut p = base.clone();
        match v {
            "nosc" => p.sigma_s = paperbsdf_core::Colour::Scalar(0.0),
            "iso" => {
                p.g_f = 0.0;
                p.g_b = 0.0;
            }
            "thin" => p.d = 0.01,
            _ => {}
        }
        let slab = Slab::from_params(&p).unwrap();
        for (a, b) in [(75.0, 0.0), (0.0, 75.0)] {
            let (wi, wo) = in_plane_directions(a, b, false);
            let r = simulate_bsdf(&slab, wi, &[wo], &cfg).unwrap();
            println!("{v} R({a},{b}) = {:.5} +- {:.5}", r.f[0].mean.0[0], r.f[0].stderr.0[0]);
        }
    }
}
