//! Fits measurement files with each model and prints errors and wall-clock
//! time (the measurement behind "one fit takes at most N seconds").
//! Run: `cargo run --release -p paperbsdf-fit --example fit_timing -- data/matte.csv [MODEL...]`
use paperbsdf_fit::dataset::load_dataset;
use paperbsdf_fit::models::candidates;
use paperbsdf_fit::{fit, FitOptions};

fn main() -> Result<(), paperbsdf_fit::FitError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (files, models): (Vec<String>, Vec<String>) = args.into_iter().partition(|a| a.ends_with(".csv"));
    let models = if models.is_empty() {
        vec!["paper".to_string(), "lambert-glass".into(), "reduced-multilayer".into()]
    } else {
        models
    };
    for f in &files {
        let ds = load_dataset(std::slice::from_ref(f), None)?;
        for m in &models {
            let c = candidates(m, ds.thickness, ds.channels == 3, None)?;
            let opts = FitOptions {
                fit_theta_i: Some(vec![0.0, 30.0, 60.0]),
                ..Default::default()
            };
            let t0 = std::time::Instant::now();
            let cpu0 = cpu_seconds();
            let o = fit(&ds.points, ds.channels, &c, &opts)?;
            println!(
                "{f} {m}: rms {:.4} extrap {:.4} points {}+{} evaluations {} wall {:.2} s cpu {:.2} s ({})",
                o.rms_log_error,
                o.extrapolation_rms_log_error.unwrap_or(f64::NAN),
                o.counts.0,
                o.counts.1,
                o.evaluations,
                t0.elapsed().as_secs_f64(),
                cpu_seconds() - cpu0,
                o.variant
            );
        }
    }
    Ok(())
}

/// CPU time of this process (user + system), from /proc (Linux); 0 elsewhere.
fn cpu_seconds() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let f: Vec<&str> = s.rsplit(')').next().unwrap_or("").split_whitespace().collect();
    let t = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (t(11) + t(12)) / 100.0
}
