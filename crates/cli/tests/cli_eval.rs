//! `paperbsdf eval` and `paperbsdf albedo` end to end: output format, conventions
//! and the errors for bad input (which must name file, line and field, never panic).

// The reference data's location, shared with the io crate's tests.
#[path = "../../io/tests/common/mod.rs"]
mod common;
mod support;

use support::{assert_clean_error, fails_with, run};

#[test]
fn eval_dirs_appends_f_and_matches_library() {
    let (ok, out, err) = run(&[
        "eval",
        "--model",
        "rough-dielectric",
        "--params",
        "params/rough_glass.json",
        "--dirs",
        "params/dirs_example.csv",
    ]);
    assert!(ok, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "label,wi_x,wi_y,wi_z,wo_x,wo_y,wo_z,f");
    assert_eq!(lines.len(), 5);
    // The mirror configuration at 30 degrees: h = z, so f = F D G / (4 cos^2) with D(z) = 1/(pi a^2).
    let f: f64 = lines[1].rsplit(',').next().unwrap().parse().unwrap();
    let (a, c): (f64, f64) = (0.3, 30f64.to_radians().cos());
    let fres = paperbsdf_core::fresnel::fresnel_dielectric(c, 1.5);
    let lambda = 0.5 * ((1.0 + a * a * (1.0 - c * c) / (c * c)).sqrt() - 1.0);
    let g1 = 1.0 / (1.0 + lambda);
    let want = fres / (std::f64::consts::PI * a * a) * g1 * g1 / (4.0 * c * c);
    assert!((f - want).abs() < 1e-6 * want, "{f} vs closed form {want}");
}

#[test]
fn eval_in_plane_uses_design_conventions() {
    let (ok, out, err) = run(&[
        "eval",
        "--model",
        "rough-dielectric",
        "--params",
        r#"{"eta":1.5,"m":0.2,"dist":"ggx"}"#,
        "--theta-i",
        "30",
        "--theta-o",
        "-60:60:30",
    ]);
    assert!(ok, "{err}");
    let rows: Vec<Vec<String>> = out
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    assert_eq!(out.lines().next().unwrap(), "kind,theta_i_deg,theta_o_deg,f");
    assert_eq!(rows.len(), 10);
    let val = |k: &str, o: &str| -> f64 {
        rows.iter().find(|r| r[0] == k && r[2] == o).unwrap()[3]
            .parse()
            .unwrap()
    };
    // R peaks at the mirror direction theta_o = -30; T at the refracted direction, which for
    // a sheet seen from below lies on the side opposite the light (negative theta_o).
    assert!(val("R", "-30") > 10.0 * val("R", "30"));
    assert!(val("T", "-30") > val("T", "30"));
}

#[test]
fn albedo_front_and_back() {
    let (ok, out, err) = run(&[
        "albedo",
        "--model",
        "rough-dielectric",
        "--params",
        "params/rough_glass.json",
        "--theta-i",
        "0,60",
        "--side",
        "back",
    ]);
    assert!(ok, "{err}");
    assert_eq!(out.lines().next().unwrap(), "theta_i_deg,reflectance,transmittance");
    for l in out.lines().skip(1) {
        let v: Vec<f64> = l.split(',').map(|s| s.parse().unwrap()).collect();
        assert!(v[1] >= 0.0 && v[2] >= 0.0 && v[1] + v[2] <= 1.0 + 1e-3, "{l}");
    }
    // From inside at 60 degrees (beyond the critical angle 41.8 of eta 1.5) most light is reflected.
    let last: Vec<f64> = out
        .lines()
        .nth(2)
        .unwrap()
        .split(',')
        .map(|s| s.parse().unwrap())
        .collect();
    assert!(last[1] > 0.5, "{last:?}");
}

#[test]
fn bad_inputs_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        // out of range, TOML: names file, line, parameter, range
        (
            vec!["--params".into(), p("a.toml", "eta = 1.5\nm = 2.0\ndist = \"ggx\"\n")],
            vec!["a.toml:2", "`m`", "2", "pi/2"],
        ),
        // missing field
        (
            vec!["--params".into(), p("b.json", "{\"eta\": 1.5, \"dist\": \"ggx\"}")],
            vec!["b.json:1", "missing field `m`"],
        ),
        // unknown key
        (
            vec![
                "--params".into(),
                p("c.json", "{\"eta\": 1.5, \"m\": 0.1, \"dist\": \"ggx\", \"alpha\": 1}"),
            ],
            vec!["c.json", "unknown field `alpha`"],
        ),
        // bad distribution
        (
            vec![
                "--params".into(),
                p("d.json", "{\"eta\": 1.5, \"m\": 0.1, \"dist\": \"phong\"}"),
            ],
            vec!["d.json", "phong"],
        ),
        // malformed JSON
        (vec!["--params".into(), p("e.json", "{\"eta\": 1.5,")], vec!["e.json"]),
        // missing file
        (
            vec!["--params".into(), "/nonexistent/params.json".into()],
            vec!["/nonexistent/params.json"],
        ),
    ];
    for (extra, needles) in cases {
        let mut args: Vec<String> = vec!["eval".into(), "--model".into(), "rough-dielectric".into()];
        args.extend(extra);
        args.extend(["--theta-i".into(), "30".into(), "--theta-o".into(), "0:10:10".into()]);
        let a: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
        let (ok, _, err) = run(&a);
        assert!(!ok);
        assert_clean_error(&err, &[]);
        for n in needles {
            assert!(err.contains(n), "expected `{n}` in: {err}");
        }
    }
    let params = "params/rough_glass.json";
    let dirs_cases = [
        (
            "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,0,0,1\n0,0,1.1,0,0,1\n",
            vec!["f.csv:3", "wi_x,wi_y,wi_z", "unit"],
        ),
        (
            "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,NaN,0,1\n",
            vec!["f.csv:2", "wo_x", "finite"],
        ),
        (
            "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n0,0,1,zero,0,1\n",
            vec!["f.csv:2", "wo_x", "zero"],
        ),
        (
            "wi_x,wi_y,wo_x,wo_y,wo_z\n0,0,0,0,1\n",
            vec!["f.csv", "missing column `wi_z`"],
        ),
    ];
    for (text, needles) in dirs_cases {
        let f = p("f.csv", text);
        let (ok, _, err) = run(&["eval", "--model", "rough-dielectric", "--params", params, "--dirs", &f]);
        assert!(!ok);
        assert_clean_error(&err, &[]);
        for n in needles {
            assert!(err.contains(n), "expected `{n}` in: {err}");
        }
    }
    for (args, needle) in [
        (
            vec![
                "eval",
                "--model",
                "phong",
                "--params",
                params,
                "--dirs",
                "params/dirs_example.csv",
            ],
            "unknown model `phong`",
        ),
        (
            vec![
                "eval",
                "--model",
                "rough-dielectric",
                "--params",
                params,
                "--theta-i",
                "95",
                "--theta-o",
                "0:10:10",
            ],
            "--theta-i = 95",
        ),
        (
            vec![
                "eval",
                "--model",
                "rough-dielectric",
                "--params",
                params,
                "--theta-i",
                "30",
                "--theta-o",
                "0:10",
            ],
            "FROM:TO:STEP",
        ),
        (
            vec![
                "eval",
                "--model",
                "rough-dielectric",
                "--params",
                params,
                "--theta-i",
                "30",
                "--theta-o",
                "0:10:5",
                "--component",
                "foo",
            ],
            // clap's message: the flag and the allowed values
            "invalid value 'foo' for '--component <COMPONENT>'\n  [possible values: surface, single, multiple, direct, all]",
        ),
        (
            vec![
                "albedo",
                "--model",
                "rough-dielectric",
                "--params",
                params,
                "--theta-i",
                "30",
                "--side",
                "top",
            ],
            "invalid value 'top' for '--side <SIDE>'\n  [possible values: front, back]",
        ),
    ] {
        let (ok, _, err) = run(&args);
        assert!(!ok);
        assert_clean_error(&err, &[]);
        assert!(err.contains(needle), "expected `{needle}` in: {err}");
    }
}

#[test]
fn out_file_is_written_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("vals.csv");
    let (ok, _, err) = run(&[
        "eval",
        "--model",
        "rough-dielectric",
        "--params",
        "params/rough_glass.json",
        "--theta-i",
        "30",
        "--theta-o",
        "-10:10:10",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap().lines().count(), 7);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// The slab models through the CLI: components sum to `all`, RGB parameters give
/// r,g,b columns, and the paper parameter file's errors name the key.
#[test]
fn paper_models_and_components() {
    let dev_a_path = common::reference("devA.json");
    let dev_a = dev_a_path.to_str().unwrap();
    let get = |model: &str, params: &str, comp: &str| -> Vec<Vec<f64>> {
        let (ok, out, err) = run(&[
            "eval",
            "--model",
            model,
            "--params",
            params,
            "--theta-i",
            "0,45",
            "--theta-o",
            "-80:80:40",
            "--component",
            comp,
        ]);
        assert!(ok, "{model} {comp}: {err}");
        out.lines()
            .skip(1)
            .map(|l| l.split(',').skip(3).map(|v| v.parse().unwrap()).collect())
            .collect()
    };
    // `slab`'s single is its first-order part (since 2026-12-07; 0 before).
    for model in ["paper", "reduced-multilayer", "slab"] {
        let all = get(model, dev_a, "all");
        let parts: Vec<Vec<Vec<f64>>> = ["surface", "single", "multiple", "direct"]
            .iter()
            .map(|c| get(model, dev_a, c))
            .collect();
        for (k, row) in all.iter().enumerate() {
            let sum: f64 = parts.iter().map(|p| p[k][0]).sum();
            assert!(
                (sum - row[0]).abs() <= 1e-9 * row[0].abs().max(1e-12),
                "{model} row {k}: {sum} vs {}",
                row[0]
            );
            assert!(row[0] >= 0.0 && row[0].is_finite());
        }
        assert!(parts[1].iter().any(|r| r[0] > 0.0), "{model}: no single scattering");
    }
    let lg = r#"{"k_d":[0.6,0.5,0.4],"k_t":0.2,"eta":1.5,"m":0.3,"dist":"ggx"}"#;
    let (ok, out, err) = run(&[
        "eval",
        "--model",
        "lambert-glass",
        "--params",
        lg,
        "--theta-i",
        "30",
        "--theta-o",
        "0:0:1",
    ]);
    assert!(ok, "{err}");
    assert_eq!(out.lines().next().unwrap(), "kind,theta_i_deg,theta_o_deg,r,g,b");
    let bad = std::fs::read_to_string(&dev_a_path)
        .unwrap()
        .replace("\"g_b\"", "\"gb\"");
    let (ok, _, err) = run(&[
        "eval",
        "--model",
        "paper",
        "--params",
        &bad,
        "--theta-i",
        "30",
        "--theta-o",
        "0:0:1",
    ]);
    assert!(!ok && err.contains("unknown field `gb`"), "{err}");
    let (ok, out, err) = run(&[
        "albedo",
        "--model",
        "paper",
        "--params",
        dev_a,
        "--theta-i",
        "0,60,89",
        "--side",
        "back",
    ]);
    assert!(ok, "{err}");
    for l in out.lines().skip(1) {
        let v: Vec<f64> = l.split(',').map(|s| s.parse().unwrap()).collect();
        assert!(v[1] > 0.0 && v[2] > 0.0 && v[1] + v[2] <= 1.0 + 1e-3, "{l}");
    }
}

/// `--slab-nodes` reaches the model `slab`'s solver: 64 nodes move the
/// matte sheet's in-plane values (reflection and transmission, 0 and 45
/// degrees, -80 to 80) by more than rounding (measured 9e-4 of the value at
/// 45 R -80) and by less than 1% (the node change of the accuracy cases,
/// docs/slab.md "Convergence": matte 0.33% at most on a dense grid, 0.97% the
/// largest of all). Out of range, or with another model, it is an error
/// naming the flag, not ignored.
#[test]
fn slab_nodes_reach_the_solver() {
    // The model and sheet of the calls below that build it.
    const SLAB_MATTE: [&str; 5] = ["--model", "slab", "--params", "matte", "--theta-i"];
    let get = |nodes: Option<&str>| -> Vec<f64> {
        let mut args = vec!["eval"];
        args.extend(SLAB_MATTE);
        args.extend(["0,45", "--theta-o", "-80:80:40"]);
        if let Some(n) = nodes {
            args.extend(["--slab-nodes", n]);
        }
        let (ok, out, err) = run(&args);
        assert!(ok, "{nodes:?}: {err}");
        out.lines()
            .skip(1)
            .flat_map(|l| {
                l.split(',')
                    .skip(3)
                    .map(|v| v.parse::<f64>().unwrap())
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    let (base, fine) = (get(None), get(Some("64")));
    assert_eq!(base.len(), fine.len());
    let change = base
        .iter()
        .zip(&fine)
        .map(|(a, b)| (a / b - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(change > 1e-5, "64 nodes gave the default's values: {change:e}");
    assert!(change < 0.01, "64 nodes moved the values by {change:e}");
    for bad in ["1", "257"] {
        let mut args = vec!["eval"];
        args.extend(SLAB_MATTE);
        args.extend(["0", "--theta-o", "0", "--slab-nodes", bad]);
        fails_with(&args, &["--slab-nodes", bad, "[2, 256]"]);
    }
    fails_with(
        &[
            "albedo",
            "--model",
            "paper",
            "--params",
            "matte",
            "--theta-i",
            "0",
            "--slab-nodes",
            "64",
        ],
        &["--slab-nodes", "`slab`", "`paper`"],
    );
    fails_with(
        &[
            "measure",
            "--model",
            "paper",
            "--params",
            "matte",
            "--truth",
            "--slab-nodes",
            "64",
        ],
        &["--slab-nodes", "--truth"],
    );
}
