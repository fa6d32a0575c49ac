//! On the bundled simulated sets, the parameters that the fit reports as
//! determined come back within their stated tolerance of the generating ones
//! (issue 15).
//!
//! Sets: `data/matte.csv`, `luster.csv`, `glossy.csv` (the project's exact
//! Monte Carlo simulator, energy-conserving faces, all 350 values fitted) and
//! `data/reference/devA.csv`, `devB.csv` (Mitsuba 3 volumetric path tracing
//! with Walter's single-scattering `roughdielectric` faces, so fitted with
//! `face_scattering = single`; on the incident angles 0, 30, 60 as in the main
//! job, because Mitsuba's grazing rows are not reciprocal, data/reference/README.md).
//! Each is fitted with the default [`FitOptions`] and the generating
//! microfacet distributions (the variant is given, not searched: one variant
//! instead of four keeps the test within its time).
//!
//! **Tolerance**: the parameter's model-error interval as reported
//! (`paperbsdf_fit::report`): the values whose profile error stays within
//! `sqrt(E0^2 + eps^2)`, `E0` the fit's RMS log error and `eps` = 0.05 the
//! model's documented error. It must contain the generating value, with no
//! widening. This follows from one premise, which the test checks first on
//! each set: the model at the generating parameters misses the data by no more
//! than that level (the model's error plus the noise). If the premise fails,
//! the model is less accurate on that set than the report assumes, and the
//! report is wrong for that reason.
//!
//! **Non-triviality**: each set names the parameters that must come out
//! determined, for a physical reason. The front roughness `m_f` sets the
//! width of the lit face's specular lobe, which nothing else in the model can
//! mimic; the front index `eta_f` sets the height of that lobe through the
//! Fresnel factor, which stands out of the body reflection when the front is
//! smooth (luster m_f = 0.16, glossy 0.06, devB 0.08) but not on the rough
//! matte front (0.45), where the broad lobe overlaps the body and `eta_f`
//! trades against `eta_b` and the medium. devA (matte-like, rough front,
//! 54 values) names none: with the level at 0.055 even its `m_f` interval
//! spans 22% of the box. The old linearised report, which took the model
//! error for noise, fails this test: on matte it reported `sigma_s` 58 +- 1
//! /mm (truth 140), `eta_b` 1.07 +- 0.004 (1.5) and `m_b` 0.11 +- 0.009 (0.4)
//! as determined.
//!
//! **Time**: each fit with its report takes about 12 s of CPU (two cores:
//! 6 s or more of wall time). The three bundled sets run in every
//! `cargo test`; the two Mitsuba references are ignored by default to keep
//! the test within half a minute, and run with
//! `cargo test --release -p paperbsdf-fit --test simulated_recovery -- --ignored`.

use paperbsdf_core::{Distribution, FaceScattering};
use paperbsdf_fit::models::PaperFit;
use paperbsdf_fit::objective::rms_log_error;
use paperbsdf_fit::{fit, read_measurement, FitModel, FitOptions};

fn check(file: &str, faces: FaceScattering, fit_theta_i: Option<Vec<f64>>, expected: &[&str]) {
    let path = format!("{}/../../data/{file}.csv", env!("CARGO_MANIFEST_DIR"));
    let m = read_measurement(&path).unwrap();
    let truth = m.params_header.clone().expect("params header");
    let dist = |k: &str| Distribution::parse(truth[k].as_str().unwrap()).unwrap();
    let d = truth["d"].as_f64().unwrap();
    let model = || PaperFit::new(d, dist("dist_f"), dist("dist_b"), false, false).with_face_scattering(faces);
    let cands: Vec<Box<dyn FitModel>> = vec![Box::new(model())];
    let opts = FitOptions {
        fit_theta_i: fit_theta_i.clone(),
        ..FitOptions::default()
    };
    let t0 = std::time::Instant::now();
    let out = fit(&m.points, 1, &cands, &opts).unwrap();
    let id = out.identifiability.as_ref().unwrap();
    let name = file.rsplit('/').next().unwrap();
    println!(
        "{name}: fit RMS log error {:.4}, interval level {:.4} (eps {:.3}), {:.1} s, {} profile refits, {} evaluations in the report",
        out.rms_log_error,
        id.interval_level,
        id.model_error_scale,
        t0.elapsed().as_secs_f64(),
        id.profile_refits,
        id.evaluations
    );
    // The premise: the model at the generating parameters fits the fitted points within the level.
    let c = model();
    let xt: Vec<f64> = c
        .specs()
        .iter()
        .map(|s| truth[s.name.as_str()].as_f64().unwrap())
        .collect();
    let (fitted, _) = paperbsdf_fit::fitter::split_points(&m.points, fit_theta_i.as_deref());
    let e_truth = rms_log_error(c.build(&xt).unwrap().as_ref(), &fitted, 1).unwrap().0;
    println!("{name}: RMS log error of the model at the generating parameters {e_truth:.4}");
    assert!(
        e_truth <= id.interval_level,
        "{name}: the model at the generating parameters misses the data by {e_truth:.4}, more than the \
         report's level {:.4}: its model error scale is too small for these data",
        id.interval_level
    );
    let mut determined = Vec::new();
    let mut failures = Vec::new();
    for p in &id.params {
        let t = truth[p.name.as_str()].as_f64().unwrap();
        let inside = p.interval[0] <= t && t <= p.interval[1];
        println!(
            "{name}: {:<8} fit {:>9.4} in [{:>9.4}, {:>9.4}] ({:>3.0}% of box, {:?}) stderr {:<9.2e} truth {:>8.4} {} {}",
            p.name,
            p.value,
            p.interval[0],
            p.interval[1],
            100.0 * p.interval_width_unit,
            p.interval_method,
            p.stderr,
            t,
            if inside { "inside " } else { "OUTSIDE" },
            if p.on_bound {
                "on bound"
            } else if p.determined {
                "determined"
            } else {
                "not determined"
            }
        );
        if p.determined {
            determined.push(p.name.clone());
            if !inside {
                failures.push(format!(
                    "{} = {} determined in [{}, {}], the generating value {t} is outside",
                    p.name, p.value, p.interval[0], p.interval[1]
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{name}: {}", failures.join("; "));
    for e in expected {
        assert!(
            determined.iter().any(|n| n == e),
            "{name}: {e} is not determined (determined: {determined:?})"
        );
    }
}

#[test]
fn matte_determined_parameters_are_recovered() {
    check("matte", FaceScattering::Multiple, None, &["m_f"]);
}

#[test]
fn luster_determined_parameters_are_recovered() {
    check("luster", FaceScattering::Multiple, None, &["m_f", "eta_f"]);
}

#[test]
fn glossy_determined_parameters_are_recovered() {
    check("glossy", FaceScattering::Multiple, None, &["m_f", "eta_f"]);
}

#[test]
#[ignore = "slow (about 12 s of CPU per set): run with --ignored, see the module doc"]
fn dev_a_determined_parameters_are_recovered() {
    check(
        "reference/devA",
        FaceScattering::Single,
        Some(vec![0.0, 30.0, 60.0]),
        &[],
    );
}

#[test]
#[ignore = "slow (about 12 s of CPU per set): run with --ignored, see the module doc"]
fn dev_b_determined_parameters_are_recovered() {
    check(
        "reference/devB",
        FaceScattering::Single,
        Some(vec![0.0, 30.0, 60.0]),
        &["m_f", "eta_f"],
    );
}
