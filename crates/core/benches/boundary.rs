//! Speed of the rough dielectric boundary: eval, sample, pdf, and the cost of
//! building a surface's integrals (`SurfaceIntegrals::new`, which must stay
//! below 50 microseconds: it runs in every fit iteration and per texel).
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use paperbsdf_core::boundary::SurfaceIntegrals;
use paperbsdf_core::{Bsdf, DVec3, Distribution, RoughDielectric};

fn bench(c: &mut Criterion) {
    let wo = DVec3::new(0.3, 0.1, 0.9).normalize();
    let wi = DVec3::new(-0.4, 0.2, -0.8).normalize();
    for dist in [Distribution::Ggx, Distribution::Beckmann] {
        let b = RoughDielectric::new(dist, 1.5, 0.3).unwrap();
        // Directions through an opaque reference, not `black_box(value)`: see
        // benches/paper.rs (a per-iteration store the callee cannot forward).
        let d = (wi, wo);
        c.bench_function(&format!("rough_dielectric/{dist}/eval"), |bn| {
            bn.iter(|| {
                let d = black_box(&d);
                black_box(&b).eval(d.0, d.1)
            })
        });
        c.bench_function(&format!("rough_dielectric/{dist}/pdf"), |bn| {
            bn.iter(|| {
                let d = black_box(&d);
                black_box(&b).pdf(d.0, d.1)
            })
        });
        let mut k = 0u64;
        c.bench_function(&format!("rough_dielectric/{dist}/sample"), |bn| {
            bn.iter(|| {
                k = k.wrapping_add(0x9E37_79B9_7F4A_7C15);
                let u0 = (k >> 11) as f64 / (1u64 << 53) as f64;
                let u1 = (u0 * 7.31).fract();
                let u2 = (u0 * 13.7).fract();
                black_box(&b).sample(black_box(&d).1, u0, [u1, u2])
            })
        });
        let mut eta = 1.0;
        c.bench_function(&format!("surface_integrals_build/{dist}"), |bn| {
            bn.iter(|| {
                eta = if eta > 4.9 { 1.01 } else { eta + 0.013 };
                let b = RoughDielectric::new(dist, eta, 0.37).unwrap();
                SurfaceIntegrals::new(black_box(&b))
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
