//! The lit face's multiply scattered reflection against its own Fourier
//! orders (`SlabOptions::walk_orders`): luster's and matte's in-plane
//! reflection at the walk's forward peak and elsewhere, the build time and
//! the memory, for walk orders 48 (the sheet's own, Fejer-summed: the model
//! before 2026-12-05), 192, 256 (the default) and 512. What docs/slab.md and
//! src/interface.rs quote of the choice of 256.
//!
//! `cargo run --release -p paperbsdf-slab --example walk_orders`

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::presets::preset;
use paperbsdf_core::Bsdf;
use paperbsdf_slab::{SlabBsdf, SlabOptions};
use std::time::Instant;

fn main() {
    let points = [
        (75.0, -80.0),
        (75.0, -75.0),
        (75.0, -85.0),
        (85.0, -85.0),
        (60.0, -70.0),
        (30.0, -30.0),
    ];
    for name in ["luster", "matte"] {
        let p = preset(name).expect("preset");
        for walk_orders in [48usize, 192, 256, 512] {
            let o = SlabOptions {
                walk_orders,
                ..Default::default()
            };
            let t0 = Instant::now();
            let b = SlabBsdf::with_options(&p, &o).expect("build");
            let dt = t0.elapsed().as_secs_f64();
            print!(
                "{name} walk orders {walk_orders}: build {dt:.2} s, {:.1} MB;",
                b.memory_bytes() as f64 / 1e6
            );
            for (ti, to) in points {
                let (wi, wo) = in_plane_directions(ti, to, false);
                print!(" {ti} R {to}: {:.5}", b.eval(wi, wo).mean());
            }
            println!();
        }
    }
}
