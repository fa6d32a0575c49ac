//! Builds the model `slab` for the presets, the sheets of docs/accuracy.md
//! that are not presets, and the worst case for the build (an RGB thin sheet
//! with unequal faces: each colour channel has its own optical thickness and
//! so its own analytic unscattered term, and its GGX 0.1 front's walk takes
//! 384 orders) and a thin coated sheet (`thin-coated`), and prints the build time (the fastest of three), the
//! memory per sheet and the directional albedos (R + T from both sides at
//! 0, 60 and 85 degrees), for the speed and energy numbers of the
//! documentation.
//!
//! `cargo run --release -p paperbsdf-slab --example slab_build [--nodes N] [NAME...]`
//! (`--nodes N`: `N` nodes and `N / 2` in the cone of total reflection
//! instead of the default 32 and 16, as `paperbsdf eval --slab-nodes N`).

use paperbsdf_core::bsdf::albedo_from;
use paperbsdf_core::presets::preset;
use paperbsdf_core::{DVec3, PaperParams};
use paperbsdf_slab::{SlabBsdf, SlabOptions};
use std::time::Instant;

#[path = "../tests/support/build_sheets.rs"]
mod build_sheets;
#[path = "../../sim/examples/support/cases.rs"]
mod cases;
#[path = "../tests/support/thin_coated.rs"]
mod thin_coated;

fn main() {
    let mut only: Vec<String> = std::env::args().skip(1).collect();
    let mut options = SlabOptions::default();
    if let Some(k) = only.iter().position(|a| a == "--nodes") {
        match only.get(k + 1).and_then(|v| v.parse::<usize>().ok()) {
            Some(n) if n >= 2 => {
                options.nodes = n;
                options.tir_nodes = n / 2;
            }
            _ => {
                eprintln!("--nodes needs a whole number of nodes, at least 2");
                std::process::exit(2);
            }
        }
        only.drain(k..k + 2);
    }
    let mut sheets: Vec<(String, PaperParams)> = ["matte", "luster", "glossy"]
        .iter()
        .map(|n| (n.to_string(), preset(n).expect("preset")))
        .collect();
    sheets.extend(cases::cases().into_iter().filter(|(n, _)| !n.starts_with("preset-")));
    sheets.push(("rgb-thin-unequal".into(), build_sheets::rgb_thin_unequal()));
    // The thin coated sheet of the tests (tests/support/thin_coated.rs):
    // its unscattered term crosses the coating/base boundary (since
    // 2026-12-07).
    sheets.push((
        "thin-coated".into(),
        PaperParams {
            name: Some("thin coated sheet, GGX 0.3 front of 1.5 over a base of 1.4, GGX 0.15 back".into()),
            ..serde_json::from_str(thin_coated::THIN_COATED_SHEET_JSON).expect("the shared sheet is valid JSON")
        },
    ));
    for (name, p) in sheets.iter().filter(|(n, _)| only.is_empty() || only.contains(n)) {
        let mut best = f64::MAX;
        let mut built = None;
        for _ in 0..3 {
            let t0 = Instant::now();
            let b = SlabBsdf::with_options(p, &options).expect("build");
            best = best.min(t0.elapsed().as_secs_f64());
            built = Some(b);
        }
        let b = built.expect("three builds");
        print!(
            "{name}: build {best:.3} s, {:.1} MB, {} orders at most;",
            b.memory_bytes() as f64 / 1e6,
            b.most_orders()
        );
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
