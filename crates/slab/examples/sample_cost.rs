//! Calls `SlabBsdf::sample` (or `eval`, `pdf`) many times for a preset at
//! directions off the nodes (or `eval_grazing`: `eval` at the benchmark's
//! grazing pair; `sample_fixed`: `sample` for the benchmark's one viewer), for instruction counts that do not depend on
//! the machine's load (the criterion benchmark `benches/slab.rs` gives
//! seconds):
//!
//! `valgrind --tool=callgrind target/release/examples/sample_cost luster sample 200000`
//!
//! (build it first with `cargo build --release -p paperbsdf-slab --example sample_cost`;
//! the build of the sheet is counted too: subtract a run with 0 calls).
//! An optional fourth argument sets `SlabOptions::walk_orders` (e.g. 48,
//! the solution's orders: what `eval` costs without the walk's tail).
//! Arguments: `[preset] [sample|sample_fixed|eval|eval_grazing|pdf] [calls] [walk_orders]`.

use paperbsdf_core::presets::preset;
use paperbsdf_core::{Bsdf, DVec3};
use paperbsdf_slab::{SlabBsdf, SlabOptions};

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("luster", String::as_str);
    let what = args.get(1).map_or("sample", String::as_str);
    let calls: usize = match args.get(2) {
        Some(s) => s.parse().map_err(|e| format!("calls: {e} ('{s}')"))?,
        None => 200_000,
    };
    let p = preset(name).ok_or_else(|| format!("no preset '{name}'"))?;
    let mut opts = SlabOptions::default();
    if let Some(s) = args.get(3) {
        opts.walk_orders = s.parse().map_err(|e| format!("walk_orders: {e} ('{s}')"))?;
    }
    let b = SlabBsdf::with_options(&p, &opts).map_err(|e| e.to_string())?;
    // Directions off the nodes, both sides, from a fixed low-discrepancy sequence.
    let dir = |k: usize, a: f64| {
        let u = (0.5 + k as f64 * 0.618_033_988_749_894_9).fract();
        let v = (0.5 + k as f64 * a).fract();
        let z = if k.is_multiple_of(2) { u } else { -u };
        let s = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * std::f64::consts::PI * v;
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    };
    let mut acc = 0.0;
    for k in 0..calls {
        // Only where the call takes it: `eval_grazing`'s loop is then the call alone.
        let wo = || dir(k, 0.754_877_666);
        match what {
            "sample" => {
                let uc = (0.5 + k as f64 * 0.569_840_290_998).fract();
                let u = [(0.5 + k as f64 * 0.412_454_033_64).fract(), dir(k, 0.3).z.abs()];
                if let Some(s) = b.sample(wo(), uc, u) {
                    acc += s.pdf;
                }
            }
            // benches/slab.rs `sample`: one viewer, so its node's sampling
            // cells stay in the cache, as they do in the benchmark.
            "sample_fixed" => {
                let wo = DVec3::new(0.3, 0.1, 0.9).normalize();
                let uc = (0.5 + k as f64 * 0.569_840_290_998).fract();
                let u = [
                    (0.5 + k as f64 * 0.412_454_033_64).fract(),
                    (0.5 + k as f64 * 0.618_033_988_75).fract(),
                ];
                if let Some(s) = b.sample(std::hint::black_box(wo), uc, u) {
                    acc += s.pdf;
                }
            }
            "eval" => acc += b.eval(dir(k, 0.3), wo()).mean(),
            // benches/slab.rs `eval_grazing`: near the mirror direction at
            // 78 and 81 degrees, where the node pairs keep the most orders.
            "eval_grazing" => {
                let wo = DVec3::new(0.985, 0.05, 0.16).normalize();
                let wi = DVec3::new(-0.975, 0.1, 0.21).normalize();
                acc += b.eval(std::hint::black_box(wi), wo).mean();
            }
            "pdf" => acc += b.pdf(dir(k, 0.3), wo()),
            _ => {
                return Err(format!(
                    "unknown call '{what}' (sample, sample_fixed, eval, eval_grazing or pdf)"
                ))
            }
        }
    }
    println!("{name} {what} x {calls}: checksum {acc:.6e}");
    Ok(())
}
