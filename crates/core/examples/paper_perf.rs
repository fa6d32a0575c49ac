//! Per-thread CPU time of the Paper BSDF's operations (construction, eval,
//! pdf, sample) with the RGB parameters of `benches/paper.rs`, robust to a
//! loaded machine: reads the thread's on-CPU nanoseconds from
//! `/proc/thread-self/schedstat` (Linux) next to the wall clock.
//! Run with `cargo run --release -p paperbsdf-core --example paper_perf`.
use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::{presets, Bsdf, Colour, DVec3};
use std::hint::black_box;
use std::time::Instant;

/// On-CPU nanoseconds of this thread (0 where unavailable).
fn cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|v| v.parse().ok()))
        .unwrap_or(0)
}

/// Best of 5 runs of `n` calls: (wall ns, CPU ns) per call.
fn time<F: FnMut(u64)>(n: u64, mut f: F) -> (f64, f64) {
    let (mut bw, mut bc) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..5 {
        let (t0, c0) = (Instant::now(), cpu_ns());
        for k in 0..n {
            f(k);
        }
        let (w, c) = (t0.elapsed().as_nanos() as f64, (cpu_ns() - c0) as f64);
        bw = bw.min(w / n as f64);
        bc = bc.min(c / n as f64);
    }
    (bw, bc)
}

fn main() {
    for name in ["matte", "glossy"] {
        let mut p = presets::preset(name).unwrap();
        p.sigma_s = Colour::Rgb([450.0, 430.0, 400.0]);
        p.sigma_a = Colour::Rgb([0.12, 0.10, 0.07]);
        let b = PaperBsdf::new(&p).unwrap();
        let wo = DVec3::new(0.3, 0.1, 0.9).normalize();
        let wi_r = DVec3::new(-0.4, 0.2, 0.8).normalize();
        let wi_t = DVec3::new(-0.4, 0.2, -0.8).normalize();
        let n = 1_000_000;
        let report = |what: &str, (w, c): (f64, f64)| println!("{name:7} {what:18} wall {w:10.1} ns   cpu {c:10.1} ns");
        report(
            "build",
            time(200, |_| {
                black_box(PaperBsdf::new(black_box(&p)).unwrap());
            }),
        );
        report(
            "  boundary tables",
            time(2000, |_| {
                let bd = paperbsdf_core::RoughDielectric::new(p.dist_f, black_box(p.eta_f), p.m_f).unwrap();
                black_box(paperbsdf_core::boundary::SurfaceIntegrals::new(&bd));
            }),
        );
        report(
            "  multipole R_d T_d",
            time(2000, |_| {
                let mp = paperbsdf_core::paper::multipole::Multipole::new(black_box(300.0), 0.1, p.d, 0.5, 0.5);
                black_box(mp.map(|m| m.rd_td()));
            }),
        );
        for c in paperbsdf_core::paper::Component::ALL {
            for (tag, wi) in [("R", wi_r), ("T", wi_t)] {
                let what = format!("  {c} {tag}");
                report(
                    &what,
                    time(n / 4, |_| {
                        black_box(black_box(&b).eval_components(black_box(wi), black_box(wo), c.into()));
                    }),
                );
            }
        }
        report(
            "eval_reflection",
            time(n, |_| {
                black_box(black_box(&b).eval(black_box(wi_r), black_box(wo)));
            }),
        );
        report(
            "eval_transmission",
            time(n, |_| {
                black_box(black_box(&b).eval(black_box(wi_t), black_box(wo)));
            }),
        );
        report(
            "pdf",
            time(n, |_| {
                black_box(black_box(&b).pdf(black_box(wi_r), black_box(wo)));
            }),
        );
        report(
            "sample",
            time(n, |k| {
                let k = k.wrapping_mul(0x9E37_79B9_7F4A_7C15);
                let u0 = (k >> 11) as f64 / (1u64 << 53) as f64;
                black_box(black_box(&b).sample(black_box(wo), u0, [(u0 * 7.31).fract(), (u0 * 13.7).fract()]));
            }),
        );
    }
}
