//! Speed of the Paper BSDF with RGB parameters: eval, sample, pdf, and the cost
//! of building it (`PaperBsdf::new`, which runs once per material, per fit
//! iteration, or per texel). Targets (issue 14, the default energy-conserving
//! faces): eval <= 80 ns in reflection and transmission, sample <= 150 ns,
//! the face tables built in <= 100 us per face (`build` builds one face for
//! matte, whose faces are equal, and two for glossy).
//! Run with `cargo bench -p paperbsdf-core --bench paper`.
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::presets;
use paperbsdf_core::{Bsdf, DVec3};

fn bench(c: &mut Criterion) {
    for name in ["matte", "glossy"] {
        let p = presets::preset(name).unwrap();
        let mut p = p;
        p.sigma_s = paperbsdf_core::Colour::Rgb([450.0, 430.0, 400.0]);
        p.sigma_a = paperbsdf_core::Colour::Rgb([0.12, 0.10, 0.07]);
        let b = PaperBsdf::new(&p).unwrap();
        let wo = DVec3::new(0.3, 0.1, 0.9).normalize();
        let wi_r = DVec3::new(-0.4, 0.2, 0.8).normalize();
        let wi_t = DVec3::new(-0.4, 0.2, -0.8).normalize();
        // The directions are read through an opaque reference (`black_box(&d)`),
        // not passed as `black_box(value)`: the latter stores the vectors
        // anew in every iteration, and the callee's 16-byte loads of
        // them then wait for a failed store-to-load forwarding (about 20 ns
        // here), which measures the harness rather than the BSDF.
        let (dr, dt) = ((wi_r, wo), (wi_t, wo));
        c.bench_function(&format!("paper/{name}/eval_reflection"), |bn| {
            bn.iter(|| {
                let d = black_box(&dr);
                black_box(&b).eval(d.0, d.1)
            })
        });
        c.bench_function(&format!("paper/{name}/eval_transmission"), |bn| {
            bn.iter(|| {
                let d = black_box(&dt);
                black_box(&b).eval(d.0, d.1)
            })
        });
        c.bench_function(&format!("paper/{name}/pdf"), |bn| {
            bn.iter(|| {
                let d = black_box(&dr);
                black_box(&b).pdf(d.0, d.1)
            })
        });
        let mut k = 0u64;
        c.bench_function(&format!("paper/{name}/sample"), |bn| {
            bn.iter(|| {
                k = k.wrapping_add(0x9E37_79B9_7F4A_7C15);
                let u0 = (k >> 11) as f64 / (1u64 << 53) as f64;
                black_box(&b).sample(black_box(&dr).1, u0, [(u0 * 7.31).fract(), (u0 * 13.7).fract()])
            })
        });
        // A renderer-like workload: 1024 cosine-distributed viewer directions
        // with light directions on the same side (reflection) or the other
        // (transmission), cycled, so that the inputs come from memory and the
        // branches see varied directions (as at the vertices of a path tracer).
        let pairs: Vec<(DVec3, DVec3)> = (0..1024u32)
            .map(|k| {
                let r = |j: u32| ((k.wrapping_mul(2_654_435_761).wrapping_add(j * 40_503)) % 65_521) as f64 / 65_521.0;
                let wo = paperbsdf_core::geometry::sample_cosine_hemisphere([r(1), r(2)]);
                let wi = paperbsdf_core::geometry::sample_cosine_hemisphere([r(3), r(4)]);
                (wi, wo)
            })
            .collect();
        for (kind, sign) in [("reflection", 1.0), ("transmission", -1.0)] {
            let mut i = 0usize;
            c.bench_function(&format!("paper/{name}/eval_{kind}_varied"), |bn| {
                bn.iter(|| {
                    i = (i + 1) & 1023;
                    let (wi, wo) = pairs[i];
                    black_box(&b).eval(DVec3::new(wi.x, wi.y, sign * wi.z), wo)
                })
            });
        }
        let mut i = 0usize;
        let mut k = 0u64;
        c.bench_function(&format!("paper/{name}/sample_varied"), |bn| {
            bn.iter(|| {
                i = (i + 1) & 1023;
                k = k.wrapping_add(0x9E37_79B9_7F4A_7C15);
                let u0 = (k >> 11) as f64 / (1u64 << 53) as f64;
                black_box(&b).sample(pairs[i].1, u0, [(u0 * 7.31).fract(), (u0 * 13.7).fract()])
            })
        });
        c.bench_function(&format!("paper/{name}/build"), |bn| {
            bn.iter(|| PaperBsdf::new(black_box(&p)).unwrap())
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
