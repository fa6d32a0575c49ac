//! On the bundled simulated sets (data/*.csv, made by the ground-truth
//! simulator from the parameters in each file's `# params:` header, see
//! data/README.md), the parameters that the fit reports as determined come back
//! within a stated tolerance of the generating ones.
//!
//! Tolerance: 3 standard errors of the fit's own linearised uncertainty
//! (paperbsdf_fit::report), i.e. a 3-sigma interval. That uncertainty takes the
//! residual scatter as noise, and the scatter here is mostly the model's own
//! approximation error (2-5% against the simulator, docs/accuracy.md), so the
//! interval covers both the simulation noise and the model error as far as
//! they look like noise; a systematic bias larger than that is what the test
//! is there to find.

use paperbsdf_fit::models::candidates;
use paperbsdf_fit::{fit, read_measurement, FitOptions};

const K_SIGMA: f64 = 3.0;

fn check(name: &str) {
    let path = format!("{}/../../data/{name}.csv", env!("CARGO_MANIFEST_DIR"));
    let m = read_measurement(&path).unwrap();
    let truth = m.params_header.clone().expect("params header");
    let dist = |k: &str| paperbsdf_core::Distribution::parse(truth[k].as_str().unwrap()).unwrap();
    // the generating distribution (both faces), so that the roughness means the same thing
    assert_eq!(dist("dist_f"), dist("dist_b"));
    let cands = candidates("paper", m.thickness, false, Some(&[dist("dist_f")])).unwrap();
    let out = fit(&m.points, 1, &cands, &FitOptions::default()).unwrap();
    let id = out.identifiability.as_ref().unwrap();
    let mut determined = 0;
    let mut failures = Vec::new();
    for p in &id.params {
        let t = truth[p.name.as_str()].as_f64().unwrap();
        println!(
            "{name}: {:<8} fit {:>10.4} +- {:<9.3e} truth {:>8.4} ({:+.1} sigma) {}",
            p.name,
            p.value,
            p.stderr,
            t,
            (p.value - t) / p.stderr,
            if p.determined {
                "determined"
            } else if p.on_bound {
                "on bound"
            } else {
                ""
            }
        );
        if p.determined {
            determined += 1;
            if (p.value - t).abs() > K_SIGMA * p.stderr {
                failures.push(format!(
                    "{} = {} is {:.1} sigma from the generating {t}",
                    p.name,
                    p.value,
                    (p.value - t).abs() / p.stderr
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{name}: {}", failures.join("; "));
    assert!(
        determined >= 2,
        "{name}: the data determine only {determined} parameters"
    );
}

/// FAILS today, and is kept (ignored) because it documents a real defect: on
/// matte.csv the fit reports sigma_s as determined at about 41 +- 2 /mm where
/// the data were simulated with 140 /mm (and sigma_a on its lower bound).
/// With the energy-conserving faces in both the data and the model (issue 14,
/// data regenerated) it still fails, differently: m_f 0.449 +- 0.001 (truth
/// 0.45), eta_f 1.494 +- 0.014 (1.5) and w_b, g_b come back, but sigma_s
/// 58 +- 1 (140), sigma_a 0.65 (0.4), g_f 0.47 (0.8), eta_b 1.07 (1.5) and
/// m_b 0.11 (0.4) trade against each other to absorb the model error. The
/// linearised uncertainty covers noise, not the bias that the model's
/// approximation error (multiple scattering, docs/accuracy.md) puts into the
/// parameters; a prior or a fit against the simulator itself is needed.
/// Run with `cargo test -p paperbsdf-fit --test simulated_recovery -- --ignored --nocapture`.
#[test]
#[ignore = "known defect: model bias moves determined parameters far beyond their uncertainty (see doc comment)"]
fn matte_determined_parameters_are_recovered() {
    check("matte");
}
