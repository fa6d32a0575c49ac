//! What the coated front's round trip ([`paperbsdf_slab::coat_return`])
//! costs and how closely its table follows its integral: for the glossy
//! preset's and devB's fronts (Beckmann 0.04 and 0.08), the narrowest lobe
//! of tests/coat_return.rs (Beckmann 0.005) and a GGX 0.3 front, the time
//! to build the table and to balance it on the 32-node grid (two cores),
//! `eval`'s time per call near the lobe (one thread), and the table's
//! albedo against the integral's (32 x 32 points) at four cosines.
//!
//! `cargo run --release -p paperbsdf-slab --example coat_return`

use paperbsdf_core::{DVec3, Distribution, RoughDielectric};
use paperbsdf_slab::coat_return::CoatReturn;
use paperbsdf_slab::Grid;
use std::time::Instant;

fn main() {
    let fronts = [
        (
            "glossy: Beckmann 0.04, 1.55 over 1.5",
            Distribution::Beckmann,
            0.04,
            1.55,
            1.5,
        ),
        (
            "devB: Beckmann 0.08, 1.55 over 1.45",
            Distribution::Beckmann,
            0.08,
            1.55,
            1.45,
        ),
        ("Beckmann 0.005, 1.5 over 1.6", Distribution::Beckmann, 0.005, 1.5, 1.6),
        ("GGX 0.3, 1.4 over 1.6", Distribution::Ggx, 0.3, 1.4, 1.6),
    ];
    let g = Grid::outside(32);
    for (name, dist, m, eta_f, eta_b) in fronts {
        let front = RoughDielectric::new(dist, eta_f, m).expect("front");
        let t0 = Instant::now();
        let mut c = CoatReturn::new(front, eta_b / eta_f).expect("a rough coated front");
        let built = t0.elapsed();
        // Against its own albedo, so that the passes run as in a build.
        let target: Vec<f64> = g.mu.iter().map(|&mu| c.albedo_of(mu, |a, b| c.eval(a, b))).collect();
        let albedo: Vec<String> = [0.95, 0.8, 0.5, 0.25]
            .iter()
            .map(|&mu| {
                let t = c.albedo_of(mu, |a, b| c.eval(a, b));
                let e = c.albedo_of(mu, |a, b| c.exact(a, b, 32));
                format!("{mu} {:+.2}%", 100.0 * (t / e - 1.0))
            })
            .collect();
        let t1 = Instant::now();
        c.balance(&g.mu, &target);
        let balanced = t1.elapsed();
        // eval on pairs around the mirror direction, 30 to 75 degrees.
        let pairs: Vec<(DVec3, DVec3)> = (0..1000)
            .map(|k| {
                let a = 0.5 + 0.8 * (k as f64 / 1000.0);
                let b = a + 0.01 * ((k % 7) as f64 - 3.0) * m;
                let wi = DVec3::new(a.sin(), 0.0, a.cos());
                let wo = DVec3::new(-b.sin(), 0.01 * m * (k % 5) as f64, b.cos()).normalize();
                (wi, wo)
            })
            .collect();
        let calls = 2_000_000;
        let t2 = Instant::now();
        let mut sum = 0.0;
        for k in 0..calls {
            let (a, b) = pairs[k % pairs.len()];
            sum += c.eval(std::hint::black_box(a), std::hint::black_box(b));
        }
        let per_call = t2.elapsed().as_nanos() as f64 / calls as f64;
        println!(
            "{name}: table {:.0} ms, balance {:.0} ms, {} kB, eval {per_call:.1} ns (checksum {sum:.3e}); table albedo against the integral at mu {}",
            built.as_secs_f64() * 1e3,
            balanced.as_secs_f64() * 1e3,
            c.memory_bytes() / 1000,
            albedo.join(", ")
        );
    }
}
