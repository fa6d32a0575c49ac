//! Speed of the model `slab` (issue 13's targets: one build <= 1 s for
//! paper-like sheets, eval <= 200 ns, sample <= 300 ns): eval in reflection
//! and transmission, eval at grazing angles near the mirror direction (the
//! most Fourier orders), pdf, sample, at directions off the nodes, and the build
//! (`SlabBsdf::new`: the faces' projection, one adding-doubling solve per
//! distinct colour channel and one without scattering, the tables and the
//! sampling densities) for matte (RGB absorption: three channels), luster
//! (two distinct faces, one channel), glossy (the slowest preset: a coated
//! Beckmann 0.04 front whose walk has 640 orders) and the worst case, an
//! RGB thin sheet with unequal faces; eval, pdf and sample also for
//! the worst cases of the per-call work: glossy (a coated front, Beckmann
//! 0.04, whose lobe is sampled more often) and a thin tissue sheet (the
//! spread's, docs/accuracy.md: tau 1.2, mostly transmission).
//! Run with `cargo bench -p paperbsdf-slab --bench slab`.
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use paperbsdf_core::presets;
use paperbsdf_core::{Bsdf, DVec3};
use paperbsdf_slab::SlabBsdf;

// The cases of docs/accuracy.md, as the accuracy example has them (thin tissue).
#[path = "../../sim/examples/support/cases.rs"]
mod cases;
// The worst case of the builds (tests/support/build_sheets.rs).
#[path = "../tests/support/build_sheets.rs"]
mod build_sheets;

fn bench(c: &mut Criterion) {
    for name in ["matte", "luster", "glossy", "thin-tissue"] {
        let p = match name {
            "thin-tissue" => {
                cases::cases()
                    .into_iter()
                    .find(|(n, _)| n == name)
                    .expect("the accuracy cases have thin tissue")
                    .1
            }
            _ => presets::preset(name).unwrap(),
        };
        let b = SlabBsdf::new(&p).unwrap();
        let wo = DVec3::new(0.3, 0.1, 0.9).normalize();
        let wi_r = DVec3::new(-0.4, 0.2, 0.8).normalize();
        let wi_t = DVec3::new(-0.4, 0.2, -0.8).normalize();
        // Directions through an opaque reference (see core's benches/paper.rs).
        let (dr, dt) = ((wi_r, wo), (wi_t, wo));
        c.bench_function(&format!("slab/{name}/eval_reflection"), |bn| {
            bn.iter(|| {
                let d = black_box(&dr);
                black_box(&b).eval(d.0, d.1)
            })
        });
        c.bench_function(&format!("slab/{name}/eval_transmission"), |bn| {
            bn.iter(|| {
                let d = black_box(&dt);
                black_box(&b).eval(d.0, d.1)
            })
        });
        // Both directions 5-20 degrees from the normal, off the nodes: the
        // orders follow the sine law there (`SIN_LAW_BAND`), each corner
        // against its own `rho^m cos(m phi)` instead of the shared cosines.
        let dn = (
            DVec3::new(-0.12, 0.05, -0.99).normalize(),
            DVec3::new(0.2, 0.1, 0.97).normalize(),
        );
        c.bench_function(&format!("slab/{name}/eval_near_normal"), |bn| {
            bn.iter(|| {
                let d = black_box(&dn);
                black_box(&b).eval(d.0, d.1)
            })
        });
        // Grazing, near the mirror direction (off the nodes): the node pairs
        // there keep the most Fourier orders (the lit face's walk, to
        // `SlabOptions::walk_orders`), the worst case of `eval`.
        let wo_g = DVec3::new(0.985, 0.05, 0.16).normalize();
        let wi_g = DVec3::new(-0.975, 0.1, 0.21).normalize();
        let dg = (wi_g, wo_g);
        c.bench_function(&format!("slab/{name}/eval_grazing"), |bn| {
            bn.iter(|| {
                let d = black_box(&dg);
                black_box(&b).eval(d.0, d.1)
            })
        });
        c.bench_function(&format!("slab/{name}/pdf"), |bn| {
            bn.iter(|| {
                let d = black_box(&dr);
                black_box(&b).pdf(d.0, d.1)
            })
        });
        let mut k = 0u64;
        c.bench_function(&format!("slab/{name}/sample"), |bn| {
            bn.iter(|| {
                k = k.wrapping_add(0x9E37_79B9_7F4A_7C15);
                let u = [
                    (k >> 11) as f64 / (1u64 << 53) as f64,
                    ((k.wrapping_mul(3)) >> 11) as f64 / (1u64 << 53) as f64,
                    ((k.wrapping_mul(7)) >> 11) as f64 / (1u64 << 53) as f64,
                ];
                black_box(&b).sample(black_box(wo), u[0], [u[1], u[2]])
            })
        });
    }
    let mut g = c.benchmark_group("slab_build");
    g.sample_size(10);
    let builds = ["matte", "luster", "glossy"]
        .map(|name| (name, presets::preset(name).unwrap()))
        .into_iter()
        .chain([("rgb-thin-unequal", build_sheets::rgb_thin_unequal())]);
    for (name, p) in builds {
        g.bench_function(name, |bn| bn.iter(|| SlabBsdf::new(black_box(&p)).unwrap()));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
