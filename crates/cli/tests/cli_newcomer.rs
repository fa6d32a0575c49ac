//! The first hour of a new user (issue 17): a fit file feeds eval, simulate and
//! render as written; presets work by name; `list` and `--help` tell the
//! conventions; and the command-line papercuts are clear errors or defaults.

mod support;

use support::run_in;

fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(support::ROOT)
}

fn values(out: &str) -> Vec<f64> {
    out.lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect()
}

/// Measure -> fit -> eval -> simulate -> render with the fit file as `fit` writes it.
#[test]
fn fit_file_feeds_eval_simulate_and_render() {
    let dir = tempfile::tempdir().unwrap();
    let data = root().join("data/matte.csv");
    let fit = dir.path().join("fit.json");
    let (ok, _, err) = run_in(
        dir.path(),
        &[
            "fit",
            data.to_str().unwrap(),
            "--model",
            "paper",
            "--fit-theta-i",
            "0,30,60",
            "--samples",
            "16",
            "--starts",
            "2",
            "--out",
            "fit.json",
        ],
    );
    assert!(ok, "{err}");
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&fit).unwrap()).unwrap();
    let inline = j["params"].to_string();
    // eval with the fit file gives the same numbers as with its params inline
    let ev = |p: &str| {
        let (ok, out, err) = run_in(
            dir.path(),
            &[
                "eval",
                "--model",
                "paper",
                "--params",
                p,
                "--theta-i",
                "45",
                "--theta-o",
                "-60:60:30",
            ],
        );
        assert!(ok, "{p}: {err}");
        values(&out)
    };
    let a = ev("fit.json");
    assert_eq!(a, ev(&inline));
    assert_eq!(a.len(), 10);
    assert!(a.iter().all(|v| *v > 0.0 && v.is_finite()));
    // the wrong model for the fit is named
    let (ok, _, err) = run_in(
        dir.path(),
        &[
            "eval",
            "--model",
            "lambert-glass",
            "--params",
            "fit.json",
            "--theta-i",
            "0",
            "--theta-o",
            "0:0:1",
        ],
    );
    assert!(
        !ok && err.contains("fit.json") && err.contains("fit of the model `paper`"),
        "{err}"
    );
    // simulate reads it too
    let (ok, out, err) = run_in(
        dir.path(),
        &[
            "simulate",
            "--params",
            "fit.json",
            "--theta-i",
            "0",
            "--theta-o",
            "0:0:1",
            "--samples",
            "4096",
        ],
    );
    assert!(ok, "{err}");
    assert!(out.lines().any(|l| l.starts_with("R,0,0,")), "{out}");
    // a scene's `params = "fit.json"`
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        "[render]\nwidth = 16\nheight = 12\nspp = 2\n\n[camera]\norigin = [0, -3, 1]\ntarget = [0, 0, 0]\nfov = 40\n\n\
         [materials.sheet]\ntype = \"paper\"\nparams = \"fit.json\"\n\n\
         [[shapes]]\nname = \"sheet\"\ntype = \"rectangle\"\nmaterial = \"sheet\"\n\n\
         [[shapes]]\nname = \"lamp\"\ntype = \"rectangle\"\nemission = 5\ntransform = [{ rotate = [1, 0, 0], angle = 180 }, { translate = [0, 0, 2] }]\n",
    )
    .unwrap();
    let (ok, _, err) = run_in(dir.path(), &["render", "s.toml", "--out", "s.png"]);
    assert!(ok, "{err}");
    assert!(dir.path().join("s.png").exists() && dir.path().join("s.exr").exists());
}

/// Presets by name: eval, albedo and simulate; a typo lists the presets; a preset is not
/// taken for another model's parameters.
#[test]
fn presets_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let lib = paperbsdf_io::models::load_model(
        "paper",
        &serde_json::to_string(&paperbsdf_core::presets::glossy_photo()).unwrap(),
    )
    .unwrap();
    let (ok, out, err) = run_in(
        dir.path(),
        &[
            "eval",
            "--model",
            "paper",
            "--params",
            "glossy",
            "--theta-i",
            "30",
            "--theta-o",
            "-30:-30:1",
        ],
    );
    assert!(ok, "{err}");
    // A grey preset prints one value `f`, a coloured one `r,g,b` (as every model).
    let header = out.lines().next().unwrap();
    let rgb = lib.is_rgb();
    assert_eq!(
        header,
        if rgb {
            "kind,theta_i_deg,theta_o_deg,r,g,b"
        } else {
            "kind,theta_i_deg,theta_o_deg,f"
        }
    );
    let r_row: Vec<f64> = out
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .skip(3)
        .map(|v| v.parse().unwrap())
        .collect();
    let (wi, wo) = paperbsdf_core::geometry::in_plane_directions(30.0, -30.0, false);
    let want = lib.model().eval(wi, wo);
    assert_eq!(r_row.len(), if rgb { 3 } else { 1 });
    for (c, v) in r_row.iter().enumerate() {
        assert!((v - want.0[c]).abs() <= 1e-8 * want.0[c], "{r_row:?} {want:?}");
    }
    let (ok, _, err) = run_in(
        dir.path(),
        &[
            "albedo",
            "--model",
            "reduced-multilayer",
            "--params",
            "matte",
            "--theta-i",
            "0",
        ],
    );
    assert!(ok, "{err}");
    let (ok, out, err) = run_in(
        dir.path(),
        &[
            "simulate",
            "--params",
            "luster",
            "--theta-i",
            "0",
            "--totals",
            "--samples",
            "2048",
        ],
    );
    assert!(ok, "{err}");
    assert!(out.lines().count() >= 2, "{out}");
    let (ok, _, err) = run_in(
        dir.path(),
        &[
            "eval",
            "--model",
            "paper",
            "--params",
            "mate",
            "--theta-i",
            "0",
            "--theta-o",
            "0:0:1",
        ],
    );
    assert!(
        !ok && err.contains("mate") && err.contains("matte, luster, glossy"),
        "{err}"
    );
    let (ok, _, err) = run_in(
        dir.path(),
        &[
            "eval",
            "--model",
            "rough-dielectric",
            "--params",
            "matte",
            "--theta-i",
            "0",
            "--theta-o",
            "0:0:1",
        ],
    );
    assert!(
        !ok && err.contains("preset `matte`") && err.contains("rough-dielectric"),
        "{err}"
    );
}

#[test]
fn list_and_help_state_the_conventions() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = run_in(dir.path(), &["list"]);
    assert!(ok, "{err}");
    for w in [
        "paper",
        "reduced-multilayer",
        "lambert-glass",
        "rough-dielectric",
        "sigma_s",
        "k_d",
        "[0, pi/2]",
    ] {
        assert!(out.contains(w), "{w} missing from\n{out}");
    }
    for name in paperbsdf_core::presets::PRESET_NAMES {
        let line = out
            .lines()
            .find(|l| l.trim_start().starts_with(name))
            .unwrap_or_else(|| panic!("{name}\n{out}"));
        let json = line.trim_start()[name.len()..].trim();
        let p: paperbsdf_core::PaperParams = serde_json::from_str(json).unwrap();
        assert_eq!(p, paperbsdf_core::presets::preset(name).unwrap());
    }
    let (ok, out, _) = run_in(dir.path(), &["list", "presets"]);
    assert!(ok && !out.contains("rough-dielectric"), "{out}");
    let (ok, _, err) = run_in(dir.path(), &["list", "colours"]);
    assert!(
        !ok && err.contains("invalid value 'colours' for '[WHAT]'")
            && err.contains("[possible values: models, presets, all]"),
        "{err}"
    );
    let (ok, out, _) = run_in(dir.path(), &["--help"]);
    assert!(ok);
    for w in [
        "+z", "mm", "1/mm", "theta_o", "r,g,b", "sigma_a", "eta_f", "preset", "FIT.json",
    ] {
        assert!(out.contains(w), "{w} missing from --help:\n{out}");
    }
}

#[test]
fn papercuts() {
    let dir = tempfile::tempdir().unwrap();
    // a component the model does not have is an error, not zeros
    let (ok, out, err) = run_in(
        dir.path(),
        &[
            "eval",
            "--model",
            "rough-dielectric",
            "--params",
            r#"{"eta":1.5,"m":0.2,"dist":"ggx"}"#,
            "--theta-i",
            "30",
            "--theta-o",
            "0:0:1",
            "--component",
            "single",
        ],
    );
    assert!(!ok && out.is_empty(), "{out}");
    assert!(
        err.contains("single") && err.contains("rough-dielectric") && err.contains("surface"),
        "{err}"
    );
    // an unknown model is blamed on --model, before the parameters are read
    let (ok, _, err) = run_in(
        dir.path(),
        &[
            "eval",
            "--model",
            "lambert",
            "--params",
            "matte",
            "--theta-i",
            "0",
            "--theta-o",
            "0:0:1",
        ],
    );
    assert!(
        !ok && err.contains("--model") && err.contains("unknown model `lambert`"),
        "{err}"
    );
    assert!(err.contains("lambert-glass"), "{err}");
    // roughness range reads pi/2
    let (ok, _, err) = run_in(
        dir.path(),
        &[
            "eval",
            "--model",
            "rough-dielectric",
            "--params",
            r#"{"eta":1.5,"m":2,"dist":"ggx"}"#,
            "--theta-i",
            "0",
            "--theta-o",
            "0:0:1",
        ],
    );
    assert!(!ok && err.contains("[0, pi/2]") && !err.contains("1.5707963"), "{err}");
    // plot without --out writes STEM_plot.png in the current directory
    let data = root().join("data/glossy.csv");
    let (ok, out, err) = run_in(dir.path(), &["plot", data.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(out.contains("glossy_plot.png"), "{out}");
    assert_eq!(
        &std::fs::read(dir.path().join("glossy_plot.png")).unwrap()[1..4],
        b"PNG"
    );
    // PDF output, a layout and a panel size
    let (ok, _, err) = run_in(
        dir.path(),
        &[
            "plot",
            data.to_str().unwrap(),
            "--out",
            "g.pdf",
            "--layout",
            "row",
            "--panel-size",
            "200x150",
            "--log",
        ],
    );
    assert!(ok, "{err}");
    assert_eq!(&std::fs::read(dir.path().join("g.pdf")).unwrap()[..5], b"%PDF-");
    let (ok, _, err) = run_in(dir.path(), &["plot", data.to_str().unwrap(), "--layout", "diagonal"]);
    assert!(
        !ok && err.contains("invalid value 'diagonal' for '--layout <LAYOUT>'")
            && err.contains("[possible values: grid, row]"),
        "{err}"
    );
    let (ok, _, err) = run_in(dir.path(), &["plot", data.to_str().unwrap(), "--panel-size", "20x10"]);
    assert!(
        !ok && err.contains("--panel-size") && err.contains("120 to 2000"),
        "{err}"
    );
}
