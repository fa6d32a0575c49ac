//! Time to a 1% standard error on one in-plane BSDF value (devA, theta_i = 30, R at theta_o = 0).
//! `speed [devA|devB] [walks] [single|multiple] [adaptive]`: the faces of the parameter
//! file (the default, `multiple`, when it does not say) unless `single` or `multiple` is given.
use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_sim::*;
/// CPU time (user + system) of this process in seconds, from /proc/self/stat.
fn cpu_seconds() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = s.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let ticks = f.get(11).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0)
        + f.get(12).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    ticks / 100.0
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map(String::as_str).unwrap_or("devA");
    let n: u64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(32768);
    let text = std::fs::read_to_string(format!("data/reference/{name}.json")).unwrap();
    let mut p: paperbsdf_core::PaperParams = serde_json::from_str(&text).unwrap();
    for a in args.iter().skip(3) {
        if let Ok(fs) = a.parse::<paperbsdf_core::FaceScattering>() {
            p.face_scattering = fs;
        }
    }
    println!("face_scattering = {}", p.face_scattering.name());
    let slab = Slab::from_params(&p).unwrap();
    let (wi, wo) = in_plane_directions(30.0, 0.0, false);
    let cfg = SimConfig {
        samples: n,
        batches: 128,
        seed: 5,
        ..Default::default()
    };
    let t0 = std::time::Instant::now();
    let c0 = cpu_seconds();
    let r = simulate_bsdf(&slab, wi, &[wo], &cfg).unwrap();
    let dt = t0.elapsed().as_secs_f64();
    let cpu = cpu_seconds() - c0;
    let rel = r.f[0].stderr.0[0] / r.f[0].mean.0[0];
    let k = (rel / 0.01).powi(2);
    println!("{name} R(30,0) = {:.5} +- {:.5} ({:.2}%) with {} walks: wall {:.3} s, cpu {:.3} s; to 1%: wall {:.3} s, cpu {:.3} s", r.f[0].mean.0[0], r.f[0].stderr.0[0], 100.0 * rel, r.samples, dt, cpu, dt * k, cpu * k);
    let reps = slab.distinct_channels();
    let channels = (0..3).filter(|&c| reps[c] == c).count() as u64;
    println!(
        "collisions per walk: {:.1}",
        r.collisions as f64 / (r.samples * channels) as f64
    );
    if !args.iter().skip(3).any(|a| a == "adaptive") {
        return;
    }
    let cfg = SimConfig {
        rel_stderr: Some(0.01),
        samples: 4096,
        ..cfg
    };
    let t0 = std::time::Instant::now();
    let r = simulate_bsdf(&slab, wi, &[wo], &cfg).unwrap();
    println!(
        "adaptive --rel-stderr 0.01: {:.5} +- {:.5} with {} walks in {:.3} s",
        r.f[0].mean.0[0],
        r.f[0].stderr.0[0],
        r.samples,
        t0.elapsed().as_secs_f64()
    );
}
