//! What the terms kept analytic through two rough crossings
//! ([`paperbsdf_slab::two_crossings`]) cost and how closely their tables
//! follow their integrals: a coated front's round trip for the glossy
//! preset's and devB's fronts (Beckmann 0.04 and 0.08), the narrowest lobe
//! of tests/two_crossings.rs (Beckmann 0.005) and a GGX 0.3 front; and the
//! unscattered transmission of thin tissue (GGX 0.3 faces, optical
//! thickness 1.2), of weak scatter (3), and between unequal faces (GGX 0.3
//! in, Beckmann 0.05 out, 0.5). Per term: the time to build the table and
//! to balance it on the 32-node grid (two cores; the unscattered terms with
//! the shaping between the cosines, here against flat crossing shapes),
//! `eval`'s time per call near the lobe (one thread), the table's albedo
//! against the integral's (32 x 32 points per sampler) at four cosines,
//! and the largest difference of the table's entries (the integral on
//! `TABLE_POINTS` per axis) and of 12 points from 64, relative to the larger
//! of the value and 5% of the lobe's peak, at the points of
//! tests/two_crossings.rs.
//!
//! `cargo run --release -p paperbsdf-slab --example two_crossings`

use paperbsdf_core::{DVec3, Distribution, RoughDielectric};
use paperbsdf_slab::two_crossings::{TwoCrossings, TABLE_POINTS};
use paperbsdf_slab::Grid;
use std::time::Instant;

#[path = "../tests/support/lobe_points.rs"]
mod lobe_points;
use lobe_points::{dir, POINTS};

fn main() {
    let face = |dist, eta, m| RoughDielectric::new(dist, eta, m).expect("face");
    use Distribution::{Beckmann, Ggx};
    let ggx3 = face(Ggx, 1.5, 0.3);
    let terms: Vec<(&str, TwoCrossings)> = vec![
        (
            "glossy's coat: Beckmann 0.04, 1.55 over 1.5",
            (face(Beckmann, 1.55, 0.04), 1.5 / 1.55),
        ),
        (
            "devB's coat: Beckmann 0.08, 1.55 over 1.45",
            (face(Beckmann, 1.55, 0.08), 1.45 / 1.55),
        ),
        (
            "coat: Beckmann 0.005, 1.5 over 1.6",
            (face(Beckmann, 1.5, 0.005), 1.6 / 1.5),
        ),
        ("coat: GGX 0.3, 1.4 over 1.6", (face(Ggx, 1.4, 0.3), 1.6 / 1.4)),
    ]
    .into_iter()
    .map(|(name, (front, eb))| {
        let t0 = Instant::now();
        let c = TwoCrossings::coat_return(front, eb).expect("a rough coated front");
        println!("{name}: table {:.0} ms", t0.elapsed().as_secs_f64() * 1e3);
        (name, c)
    })
    .chain(
        [
            ("thin tissue's unscattered: GGX 0.3 twice, tau 1.2", ggx3, ggx3, 1.2),
            ("weak scatter's unscattered: GGX 0.3 twice, tau 3", ggx3, ggx3, 3.0),
            (
                "unscattered: GGX 0.3 in, Beckmann 0.05 out, tau 0.5",
                ggx3,
                face(Beckmann, 1.5, 0.05),
                0.5,
            ),
        ]
        .into_iter()
        .map(|(name, a, b, tau)| {
            let t0 = Instant::now();
            let c = TwoCrossings::unscattered(a, b, tau).expect("two rough faces");
            println!("{name}: table {:.0} ms", t0.elapsed().as_secs_f64() * 1e3);
            (name, c)
        }),
    )
    .collect();
    let g = Grid::outside(32);
    let flat = |_: f64| 1.0;
    for (name, mut c) in terms {
        let coat = matches!(c.between(), paperbsdf_slab::two_crossings::Between::Mirror { .. });
        // The flanks: entries on TABLE_POINTS and on 12 points against 64.
        let mut worst = [0.0f64; 2];
        for (ti, to, po) in POINTS {
            let wi = dir(ti, 180.0);
            let wo = dir(to, po);
            let peak = c.exact(wi, DVec3::new(-wi.x, -wi.y, wi.z), 32);
            let r = c.exact(wi, wo, 64);
            for (w, n) in worst.iter_mut().zip([TABLE_POINTS, 12]) {
                *w = w.max((c.exact(wi, wo, n) - r).abs() / r.max(0.05 * peak));
            }
        }
        // Against its own albedo, so that the balance runs as in a build.
        let first: Vec<f64> = g.mu.iter().map(|&mu| c.albedo_of(mu, |a, b| c.eval(a, b))).collect();
        let second: Vec<f64> = g.mu.iter().map(|&mu| c.albedo_of(mu, |a, b| c.eval(b, a))).collect();
        let albedo: Vec<String> = [0.95, 0.8, 0.5, 0.25]
            .iter()
            .map(|&mu| {
                let t = c.albedo_of(mu, |a, b| c.eval(a, b));
                let e = c.albedo_of(mu, |a, b| c.exact(a, b, 32));
                format!("{mu} {:+.2}%", 100.0 * (t / e - 1.0))
            })
            .collect();
        let t1 = Instant::now();
        c.balance(&g.mu, &first, &second, (!coat).then_some([&flat, &flat]));
        let balanced = t1.elapsed();
        // eval on pairs around the lobe's centre, 30 to 75 degrees.
        let pairs: Vec<(DVec3, DVec3)> = (0..1000)
            .map(|k| {
                let a = 0.5 + 0.8 * (k as f64 / 1000.0);
                let b = a + 0.003 * ((k % 7) as f64 - 3.0);
                let wi = DVec3::new(a.sin(), 0.0, a.cos());
                let wo = DVec3::new(-b.sin(), 0.003 * (k % 5) as f64, b.cos()).normalize();
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
        // The build's rule against a finer one (6 points per table interval,
        // 256 in azimuth), on the balanced term, both ways, at the nodes and
        // at 80 and 88 degrees: what `eval`'s energy is off by where the
        // build balanced it.
        let fine = |mu: f64, reverse: bool| {
            let f = |a: DVec3, b: DVec3| if reverse { c.eval(b, a) } else { c.eval(a, b) };
            (c.albedo_of(mu, f), c.albedo_with(mu, 6, 256, f))
        };
        let mus =
            g.mu.iter()
                .copied()
                .chain([80f64.to_radians().cos(), 88f64.to_radians().cos()]);
        let rule = mus
            .flat_map(|mu| [fine(mu, false), fine(mu, true)])
            .map(|(own, f)| (own - f).abs())
            .fold(0.0f64, f64::max);
        println!(
            "{name}: balance {:.0} ms, {} kB, eval {per_call:.1} ns (checksum {sum:.3e}); table albedo against the integral at mu {}; entries against 64 points: {:.2}% ({TABLE_POINTS} points), {:.2}% (12); albedo by the build's rule against 6 x 256 points: {rule:.1e}",
            balanced.as_secs_f64() * 1e3,
            c.memory_bytes() / 1000,
            albedo.join(", "),
            100.0 * worst[0],
            100.0 * worst[1],
        );
    }
}
