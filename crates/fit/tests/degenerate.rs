//! Degenerate data (issue 16, "Degenerate data in `fit`"): a single row,
//! all-zero values and absurd values (1e300) used to "fit" with parameters on
//! the box bounds and an RMS log error of 692. Each must now be refused with a
//! reason; a fit that ends on a bound must warn.

use paperbsdf_fit::models::candidates;
use paperbsdf_fit::{fit, parse_measurement, FitError, FitOptions};

fn quick() -> FitOptions {
    FitOptions {
        global_samples: 16,
        local_starts: 4,
        hop_rounds: 0,
        ..Default::default()
    }
}

fn run(csv: &str, model: &str) -> Result<paperbsdf_fit::FitOutcome, FitError> {
    let m = parse_measurement(csv, "t.csv").unwrap();
    let c = candidates(model, Some(0.1), m.is_rgb, None).unwrap();
    fit(&m.points, if m.is_rgb { 3 } else { 1 }, &c, &quick())
}

#[test]
fn single_row_is_refused() {
    let e = run("kind,theta_i_deg,theta_o_deg,f\nR,30,-30,0.5\n", "paper").unwrap_err();
    assert!(matches!(e, FitError::Degenerate(_)), "{e}");
    let s = e.to_string();
    assert!(s.contains("1 value(s) cannot determine") && s.contains("--fix"), "{s}");
}

#[test]
fn all_zero_values_are_refused() {
    let mut csv = "kind,theta_i_deg,theta_o_deg,f\n".to_string();
    for t in (-80..=80).step_by(10) {
        csv.push_str(&format!("R,30,{t},0\nT,30,{t},0\n"));
    }
    let e = run(&csv, "paper").unwrap_err();
    assert!(e.to_string().contains("every measured value is zero"), "{e}");
}

#[test]
fn absurd_values_are_refused() {
    let mut csv = "kind,theta_i_deg,theta_o_deg,f\n".to_string();
    for t in (-80..=80).step_by(10) {
        csv.push_str(&format!("R,30,{t},1e300\nT,30,{t},1e300\n"));
    }
    let e = run(&csv, "lambert-glass").unwrap_err();
    assert!(matches!(e, FitError::Meaningless { .. }), "{e}");
    assert!(e.to_string().contains("cannot represent these data"), "{e}");
}

/// Lambertian reflection and no transmission at all: the Lambert + rough glass
/// model's transmission fraction must go to its lower bound 0, and the fit must say so.
#[test]
fn fit_on_a_bound_warns() {
    let mut csv = "kind,theta_i_deg,theta_o_deg,f\n".to_string();
    for ti in [0, 30, 60] {
        for t in (-80..=80).step_by(10) {
            csv.push_str(&format!("R,{ti},{t},{}\nT,{ti},{t},0\n", 0.6 / std::f64::consts::PI));
        }
    }
    let out = run(&csv, "lambert-glass").unwrap();
    let id = out.identifiability.as_ref().expect("report");
    let on_bound: Vec<&str> = id
        .params
        .iter()
        .filter(|p| p.on_bound)
        .map(|p| p.name.as_str())
        .collect();
    assert!(!on_bound.is_empty(), "{:?}", id.params);
    for n in &on_bound {
        assert!(
            out.warnings.iter().any(|w| w.contains(n) && w.contains("bound")),
            "{n}: {:?}",
            out.warnings
        );
    }
}
