//! Prints the directional albedo (R, T, R + T) of Paper BSDFs given as JSON
//! parameter strings on the command line, for light at 0..85 degrees from
//! both faces, by [`sampled_albedo`] with 1024 x 1024 stratified samples.
//! A quick look at energy; the tests are in `tests/paper_energy.rs`.
//!
//! `cargo run --release -p paperbsdf-core --example energy_probe -- '{"d":0.18,...}'`
use paperbsdf_core::bsdf::sampled_albedo;
use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::{DVec3, PaperParams};

fn main() {
    for arg in std::env::args().skip(1) {
        let p: PaperParams = match serde_json::from_str(&arg) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("error: {e}");
                std::process::exit(2);
            }
        };
        let b = match PaperBsdf::new(&p) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("error: {e}");
                std::process::exit(2);
            }
        };
        println!("{arg}");
        for side in [1.0, -1.0] {
            for deg in [0.0f64, 30.0, 60.0, 75.0, 85.0] {
                let t = deg.to_radians();
                let wo = DVec3::new(t.sin(), 0.0, side * t.cos());
                let (r, tr) = sampled_albedo(&b, wo, 1024);
                println!(
                    "  side {side:+} theta {deg:>4}: R {:.4} T {:.4} R+T {:.4}",
                    r.mean(),
                    tr.mean(),
                    (r + tr).max_channel()
                );
            }
        }
    }
}
