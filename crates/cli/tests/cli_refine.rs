//! `paperbsdf fit --refine slab` end to end: a `paper` fit refined with the
//! model `slab` on data that `slab` made (`paperbsdf eval --model slab`, a
//! thin sheet, where `paper` misses by percents). FIT.json is the slab fit
//! (model, parameters, errors, the paper fit under `refinement`), `eval` reads
//! it back, and bad input is one clean error. Two parameters are free (the
//! others held with --fix) to keep the test to a few solves.

mod support;

use support::{fails_with, run};

const TRUTH: &str = r#"{"d":0.03,"sigma_a":0.5,"sigma_s":60,"g_f":0.6,"g_b":-0.3,"w_b":0.2,"eta_f":1.5,"eta_b":1.4,"m_f":0.3,"m_b":0.15,"dist_f":"ggx","dist_b":"ggx"}"#;

#[test]
fn refine_slab_writes_a_slab_fit_that_eval_reads() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("thin.csv");
    let fit_json = dir.path().join("FIT.json");
    let (data, fit_json) = (data.to_str().unwrap(), fit_json.to_str().unwrap());
    let mut csv = String::from("# thickness: 0.03\n");
    for ti in ["0", "30", "60"] {
        let (ok, out, err) = run(&[
            "eval",
            "--model",
            "slab",
            "--params",
            TRUTH,
            "--theta-i",
            ti,
            "--theta-o",
            "-80:80:10",
        ]);
        assert!(ok, "{err}");
        let mut lines = out.lines();
        let header = lines.next().unwrap();
        if ti == "0" {
            csv += header;
            csv.push('\n');
        }
        for l in lines {
            csv += l;
            csv.push('\n');
        }
    }
    std::fs::write(data, csv).unwrap();
    let mut args = vec![
        "fit",
        data,
        "--model",
        "paper",
        "--dists",
        "ggx",
        "--samples",
        "16",
        "--starts",
        "2",
        "--out",
        fit_json,
        "--refine",
        "slab",
    ];
    let fixes = [
        "sigma_a=0.5",
        "g_f=0.6",
        "g_b=-0.3",
        "w_b=0.2",
        "eta_f=1.5",
        "eta_b=1.4",
        "m_b=0.15",
    ];
    for f in &fixes {
        args.extend(["--fix", f]);
    }
    let (ok, out, err) = run(&args);
    assert!(ok, "{err}");
    assert!(
        out.contains("refining with slab") && out.contains("model: slab"),
        "{out}"
    );
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(fit_json).unwrap()).unwrap();
    assert_eq!(j["model"], "slab");
    assert_eq!(j["refined_from"], "paper");
    let (paper, start, refined) = (
        j["refinement"]["from_rms_log_error"].as_f64().unwrap(),
        j["refinement"]["start_rms_log_error"].as_f64().unwrap(),
        j["rms_log_error"].as_f64().unwrap(),
    );
    assert!(paper > 0.02, "paper fits slab's thin sheet to {paper}");
    assert!(
        refined <= start && refined < 1e-3,
        "paper {paper}, start {start}, refined {refined}"
    );
    assert!(j["refinement"]["converged"].as_bool().unwrap());
    assert!(j["refinement"]["solves"].as_u64().unwrap() >= 3);
    for (k, want) in [("sigma_s", 60.0), ("m_f", 0.3)] {
        let v = j["params"][k].as_f64().unwrap();
        assert!((v / want - 1.0).abs() < 1e-3, "{k} = {v}, made with {want}");
    }
    assert_eq!(j["params"]["m_b"].as_f64().unwrap(), 0.15, "held with --fix");
    assert!(j["fixed"]["m_b"].is_number());
    assert!(j["errors_by_plane"]["in_plane"]["rms_log_error"].as_f64().unwrap() < 1e-3);
    // The refined FIT.json evaluates as `slab`, and reproduces the data it was fitted to.
    let (ok, out, err) = run(&[
        "eval",
        "--model",
        "slab",
        "--params",
        fit_json,
        "--theta-i",
        "30",
        "--theta-o",
        "-40",
    ]);
    assert!(ok, "{err}");
    let f: f64 = out.lines().nth(1).unwrap().rsplit(',').next().unwrap().parse().unwrap();
    let data_text = std::fs::read_to_string(data).unwrap();
    let want: f64 = data_text
        .lines()
        .find(|l| l.starts_with("R,30,-40,"))
        .unwrap()
        .rsplit(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((f / want - 1.0).abs() < 2e-3, "{f} vs {want}");
    // Not as another model: the file says which model it fits.
    fails_with(
        &[
            "eval",
            "--model",
            "paper",
            "--params",
            fit_json,
            "--theta-i",
            "30",
            "--theta-o",
            "-40",
        ],
        &["fit of the model `slab`", "--model slab"],
    );
}

#[test]
fn refine_bad_input_is_a_clean_error() {
    let data = "data/matte.csv";
    let fit_fails = |extra: &[&str], parts: &[&str]| {
        let mut args = vec!["fit", data];
        args.extend(extra);
        fails_with(&args, parts)
    };
    fit_fails(
        &["--model", "lambert-glass", "--refine", "slab"],
        &["--refine slab", "lambert-glass"],
    );
    fit_fails(
        &["--model", "paper", "--refine", "slab", "--refine-max-iter", "0"],
        &["--refine-max-iter 0"],
    );
    fit_fails(
        &["--model", "paper", "--refine", "slab", "--model-error", "-1"],
        &["--model-error -1"],
    );
    let o = support::output(&["fit", data, "--model", "paper", "--refine", "glass"]);
    let err = support::text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("invalid value 'glass'") && err.contains("slab"), "{err}");
}
