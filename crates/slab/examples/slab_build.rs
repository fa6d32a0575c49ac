//! Builds the model `slab` for the presets and the hard sheets of
//! docs/accuracy.md that it supports, and prints the build time, the memory
//! per sheet and the directional albedos (R + T from both sides at 0, 60
//! and 85 degrees), for the speed and energy numbers of the documentation.
//!
//! `cargo run --release -p paperbsdf-slab --example slab_build`

use paperbsdf_core::bsdf::albedo_from;
use paperbsdf_core::presets::preset;
use paperbsdf_core::DVec3;
use paperbsdf_slab::SlabBsdf;
use std::time::Instant;

fn main() {
    for name in ["matte", "luster", "glossy"] {
        let p = preset(name).expect("preset");
        let t0 = Instant::now();
        let b = SlabBsdf::new(&p).expect("build");
        let dt = t0.elapsed().as_secs_f64();
        print!("{name}: build {dt:.3} s, {:.1} MB;", b.memory_bytes() as f64 / 1e6);
        for side in [1.0, -1.0] {
            for theta in [0.0f64, 60.0, 85.0] {
                let t = theta.to_radians();
                let w = DVec3::new(t.sin(), 0.0, side * t.cos());
                let (r, tr) = albedo_from(&b, w, 256);
                print!(
                    " {theta}{}: R {:.4} T {:.4};",
                    if side > 0.0 { "f" } else { "b" },
                    r.mean(),
                    tr.mean()
                );
            }
        }
        println!();
    }
}
