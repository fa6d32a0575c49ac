//! `paperbsdf fit --refine slab` end to end: a `paper` fit refined with the
//! model `slab` on data that `slab` made (`paperbsdf eval --model slab`, a
//! thin sheet, where `paper` misses by percents). FIT.json is the slab fit
//! (model, parameters, errors, the paper fit under `refinement`), `eval` reads
//! it back, and bad input is one clean error. Two parameters are free (the
//! others held with --fix) to keep the test to a few solves. With
//! `--slab-nodes` every solve has those nodes, FIT.json records them, and
//! `eval` and `plot` solve the fit with them.

mod support;

use support::{fails_with, run};

// The slab crate's thin coated sheet (text only, shared by `#[path]`).
#[path = "../../slab/tests/support/thin_coated.rs"]
mod thin_coated;

/// The sheet the data are made from.
const TRUTH: &str = thin_coated::THIN_COATED_SHEET_JSON;

/// Writes to `data` what `slab` (with `extra` arguments, e.g. `--slab-nodes
/// 16`) gives for TRUTH at 0, 30 and 60 degrees, every 10 degrees in the plane.
fn write_truth(data: &str, extra: &[&str]) {
    let mut csv = String::from("# thickness: 0.03\n");
    for ti in ["0", "30", "60"] {
        let mut args = vec![
            "eval",
            "--model",
            "slab",
            "--params",
            TRUTH,
            "--theta-i",
            ti,
            "--theta-o",
            "-80:80:10",
        ];
        args.extend(extra);
        let (ok, out, err) = run(&args);
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
}

/// `paperbsdf fit DATA --refine slab` (and `extra`) of `paper` with two
/// parameters free (`sigma_s`, `m_f`), FIT.json to `fit_json`: its stdout and the document.
fn refine(data: &str, fit_json: &str, extra: &[&str]) -> (String, serde_json::Value) {
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
    args.extend(extra);
    let (ok, out, err) = run(&args);
    assert!(ok, "{err}");
    assert!(
        out.contains("refining with slab") && out.contains("model: slab"),
        "{out}"
    );
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(fit_json).unwrap()).unwrap();
    (out, j)
}

/// The in-plane value that `eval` (with `extra`) gives for `params` at `theta_i`, `theta_o`.
fn eval_at(params: &str, theta_i: &str, theta_o: &str, extra: &[&str]) -> f64 {
    let mut args = vec![
        "eval",
        "--model",
        "slab",
        "--params",
        params,
        "--theta-i",
        theta_i,
        "--theta-o",
        theta_o,
    ];
    args.extend(extra);
    let (ok, out, err) = run(&args);
    assert!(ok, "{err}");
    out.lines().nth(1).unwrap().rsplit(',').next().unwrap().parse().unwrap()
}

#[test]
fn refine_slab_writes_a_slab_fit_that_eval_reads() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("thin.csv");
    let fit_json = dir.path().join("FIT.json");
    let (data, fit_json) = (data.to_str().unwrap(), fit_json.to_str().unwrap());
    write_truth(data, &[]);
    let (out, j) = refine(data, fit_json, &[]);
    assert!(out.contains("slab (32 nodes) at the paper optimum"), "{out}");
    assert_eq!(j["model"], "slab");
    assert_eq!(j["slab_nodes"], 32, "the default discretisation, recorded");
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
    let f = eval_at(fit_json, "30", "-40", &[]);
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

/// `--slab-nodes 16`: data made by `slab` with 16 nodes are fitted to their
/// own parameters (the refinement's solves have 16 nodes), FIT.json records
/// 16, and `eval` and `plot` of it solve with 16 unless told otherwise.
#[test]
fn refine_with_slab_nodes_records_them() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let (data, fit_json) = (path("thin16.csv"), path("FIT.json"));
    write_truth(&data, &["--slab-nodes", "16"]);
    let (out, j) = refine(&data, &fit_json, &["--slab-nodes", "16"]);
    assert!(out.contains("slab (16 nodes) at the paper optimum"), "{out}");
    assert_eq!(j["slab_nodes"], 16);
    let refined = j["rms_log_error"].as_f64().unwrap();
    assert!(refined < 1e-3, "refined {refined}");
    for (k, want) in [("sigma_s", 60.0), ("m_f", 0.3)] {
        let v = j["params"][k].as_f64().unwrap();
        assert!((v / want - 1.0).abs() < 1e-3, "{k} = {v}, made with {want}");
    }
    // `eval` of the fit: its 16 nodes, unless --slab-nodes says otherwise.
    // Lit at 60 degrees and seen at -80, 16 nodes differ from 32 by about
    // 0.5% (docs/slab.md "Convergence": the grazing pairs move most).
    let recorded = eval_at(&fit_json, "60", "-80", &[]);
    let with_16 = eval_at(&fit_json, "60", "-80", &["--slab-nodes", "16"]);
    let with_32 = eval_at(&fit_json, "60", "-80", &["--slab-nodes", "32"]);
    assert_eq!(recorded, with_16);
    assert!((recorded / with_32 - 1.0).abs() > 1e-5, "{recorded} vs {with_32}");
    // The same document without the key is a fit solved with the default.
    let mut j32 = j.clone();
    j32.as_object_mut().unwrap().remove("slab_nodes");
    let fit32 = path("FIT32.json");
    std::fs::write(&fit32, serde_json::to_string_pretty(&j32).unwrap()).unwrap();
    assert_eq!(eval_at(&fit32, "60", "-80", &[]), with_32);
    // `plot` draws the model it records: the figure of the 16-node fit is
    // not the default's, and that of a fit recording 32 is the default's.
    let mut j32_explicit = j.clone();
    j32_explicit["slab_nodes"] = 32.into();
    let fit32_explicit = path("FIT32e.json");
    std::fs::write(&fit32_explicit, serde_json::to_string_pretty(&j32_explicit).unwrap()).unwrap();
    let svg = |fit: &str, name: &str| {
        let out = path(name);
        let (ok, _, err) = run(&["plot", &data, "--fit", fit, "--out", &out]);
        assert!(ok, "{err}");
        std::fs::read_to_string(out).unwrap()
    };
    let (p16, p32, p32e) = (
        svg(&fit_json, "p16.svg"),
        svg(&fit32, "p32.svg"),
        svg(&fit32_explicit, "p32e.svg"),
    );
    // (Compared whole; the figures are long, so not printed.)
    assert!(p16 != p32, "plot solved the 16-node fit with 32 nodes");
    assert!(p32 == p32e, "a fit recording 32 nodes plots unlike the default");
    // A recorded value outside the range, or not a whole number, is an error
    // naming the file and the key; --slab-nodes without --refine slab too.
    for bad in [
        serde_json::json!(1),
        serde_json::json!(1000),
        serde_json::json!("many"),
        serde_json::json!(16.5),
    ] {
        let mut jb = j.clone();
        jb["slab_nodes"] = bad.clone();
        let fb = path("bad.json");
        std::fs::write(&fb, serde_json::to_string_pretty(&jb).unwrap()).unwrap();
        let msg = fails_with(
            &[
                "eval",
                "--model",
                "slab",
                "--params",
                &fb,
                "--theta-i",
                "0",
                "--theta-o",
                "0",
            ],
            &["bad.json", "`slab_nodes`", "[2, 256]"],
        );
        assert!(msg.contains(&bad.to_string()), "{msg}");
        fails_with(
            &["plot", &data, "--fit", &fb, "--out", &path("bad.svg")],
            &["bad.json", "`slab_nodes`", "[2, 256]"],
        );
    }
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
    fit_fails(
        &["--model", "paper", "--slab-nodes", "64"],
        &["--slab-nodes", "--refine slab"],
    );
    fit_fails(
        &["--model", "paper", "--refine", "slab", "--slab-nodes", "1"],
        &["--slab-nodes", "1 is outside the allowed range [2, 256]"],
    );
    let o = support::output(&["fit", data, "--model", "paper", "--refine", "glass"]);
    let err = support::text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("invalid value 'glass'") && err.contains("slab"), "{err}");
}
