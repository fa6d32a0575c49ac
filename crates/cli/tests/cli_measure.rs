//! `paperbsdf measure`, `edge` and `from-datasheet` end to end: JSON keys,
//! the round trip through a parameter file, and clear errors for bad input.

mod support;

use support::run;

fn assert_clean_error(stderr: &str, needle: &str) {
    support::assert_clean_error(stderr, &[needle]);
}

#[test]
fn measure_json_has_every_key() {
    let (ok, out, err) = run(&[
        "measure",
        "--params",
        "params/preset_matte.json",
        "--json",
        "--grammage",
        "80",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for k in [
        "opacity_iso2471",
        "opacity_tappi_t425",
        "r457",
        "gloss_75_tappi_t480",
        "gloss_20_tappi_t653",
        "gloss_20_astm_d523",
        "gloss_60_astm_d523",
        "gloss_85_astm_d523",
    ] {
        let x = v[k].as_f64().unwrap_or_else(|| panic!("{k} missing in {out}"));
        assert!(x.is_finite() && x >= 0.0, "{k} = {x}");
    }
    let op = v["opacity_iso2471"].as_f64().unwrap();
    assert!(op > 0.0 && op <= 100.0);
    assert!(v["kubelka_munk"]["s_m2_per_kg"].as_f64().unwrap() > 0.0);
    let sd = &v["scatter_distance_mm"];
    assert!(sd["width_blurred_mm"].as_f64().unwrap() > sd["width_mm"].as_f64().unwrap());
    // Another model through the same loader: no scatter distance, gloss still.
    let (ok, out, err) = run(&[
        "measure",
        "--model",
        "rough-dielectric",
        "--params",
        "params/rough_glass.json",
        "--json",
        "--metrics",
        "gloss_60_astm_d523,scatter_distance_mm",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v["gloss_60_astm_d523"].as_f64().unwrap() > 0.0);
    assert!(v["scatter_distance_mm"].is_null() && v["opacity_iso2471"].is_null());
}

#[test]
fn measure_bad_input() {
    let (ok, _, err) = run(&[
        "measure",
        "--params",
        "params/preset_matte.json",
        "--metrics",
        "opacity,gloss",
    ]);
    assert!(!ok);
    assert_clean_error(&err, "unknown metric `opacity`");
    assert!(err.contains("opacity_iso2471"), "lists the known names: {err}");
    let (ok, _, err) = run(&["measure", "--params", "params/preset_matte.json", "--grammage", "-80"]);
    assert!(!ok);
    assert_clean_error(&err, "--grammage -80");
    let (ok, _, err) = run(&["measure", "--params", r#"{"d":0.1}"#]);
    assert!(!ok);
    assert_clean_error(&err, "missing field");
    let (ok, _, err) = run(&[
        "measure",
        "--model",
        "lambert-glass",
        "--params",
        "params/rough_glass.json",
        "--truth",
    ]);
    assert!(!ok);
    assert_clean_error(&err, "--truth");
}

#[test]
fn from_datasheet_round_trip_and_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("office.json");
    let o = out.to_str().unwrap();
    let (ok, text, err) = run(&[
        "from-datasheet",
        "--grammage",
        "80",
        "--caliper",
        "0.1",
        "--opacity",
        "92",
        "--brightness",
        "70",
        "--out",
        o,
    ]);
    assert!(ok, "{err}");
    assert!(text.contains("opacity_iso2471") && text.contains("r457"), "{text}");
    let (ok, js, err) = run(&["measure", "--params", o, "--json", "--metrics", "opacity_iso2471,r457"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&js).unwrap();
    assert!((v["opacity_iso2471"].as_f64().unwrap() - 92.0).abs() <= 0.5, "{js}");
    assert!((v["r457"].as_f64().unwrap() - 70.0).abs() <= 0.5, "{js}");
    for (args, needle) in [
        (vec!["--opacity", "0"], "--opacity 0"),
        (vec!["--opacity", "120"], "--opacity 120"),
        (vec!["--grammage", "-5"], "--grammage -5"),
        (vec!["--caliper", "0"], "--caliper 0"),
        (vec!["--brightness", "104"], "fluorescent"),
        (vec!["--tint", "1,1"], "--tint"),
    ] {
        let mut a = vec!["from-datasheet", "--out", o];
        let mut base = vec![("--grammage", "80"), ("--caliper", "0.1"), ("--opacity", "92")];
        base.retain(|(k, _)| !args.contains(k));
        for (k, v) in &base {
            a.push(k);
            a.push(v);
        }
        a.extend(args.iter());
        let (ok, _, err) = run(&a);
        assert!(!ok, "{args:?} should fail");
        assert_clean_error(&err, needle);
    }
}

#[test]
fn edge_writes_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("edge.png");
    let (ok, text, err) = run(&[
        "edge",
        "--params",
        "params/preset_matte.json",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(text.contains("5-95% width"), "{text}");
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let (ok, _, err) = run(&[
        "edge",
        "--params",
        "params/preset_matte.json",
        "--out",
        "x.png",
        "--range",
        "0",
    ]);
    assert!(!ok);
    assert_clean_error(&err, "--range 0");
}
