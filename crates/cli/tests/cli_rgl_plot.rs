//! `paperbsdf plot FILE.bsdf --fit FIT.json`: a measured RGL file drawn as data
//! (its in-plane slices, sampled as `paperbsdf convert` samples them) with the
//! curves of a fit to it, grey where extrapolated; and clean errors for bad
//! `.bsdf` files and misplaced options.

mod support;

use std::path::Path;
use support::{fails_with, output as run, text, ROOT};

const SATIN: &str = "data/reference/rgl/satin_rosaline_rgb.bsdf";

/// A quick (not converged) fit of the Lambert + rough glass model to the satin file.
fn quick_fit(dir: &Path) -> String {
    let fit = dir.join("fit.json").display().to_string();
    let o = run(&[
        "fit",
        SATIN,
        "--model",
        "lambert-glass",
        "--samples",
        "8",
        "--starts",
        "1",
        "--max-iter",
        "20",
        "--out",
        &fit,
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    fit
}

#[test]
fn plot_draws_a_bsdf_file_with_its_fit() {
    let dir = tempfile::tempdir().unwrap();
    let fit = quick_fit(dir.path());
    // PNG, the slices of the brief.
    let png = dir.path().join("satin.png");
    let o = run(&[
        "plot",
        SATIN,
        "--fit",
        &fit,
        "--theta-i",
        "0,30,60",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let img = image::load_from_memory(&bytes).unwrap().to_rgb8();
    // Three BRDF panels in a grid row (no BTDF: the file is reflection only).
    assert!(
        img.width() >= 3 * 200 && img.height() > 100,
        "{}x{}",
        img.width(),
        img.height()
    );
    // SVG, to read the panels: 0 and 30 are inside the fit's sampled incidences
    // (0 to 75 degrees), 85 is beyond them and is marked extrapolated; the
    // measurement and the model are both drawn.
    let svg = dir.path().join("satin.svg");
    let o = run(&[
        "plot",
        SATIN,
        "--fit",
        &fit,
        "--theta-i",
        "0,30,85",
        "--exclude-retro",
        "3",
        "--out",
        svg.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let s = std::fs::read_to_string(&svg).unwrap();
    for (t, extrapolated) in [(0, false), (30, false), (85, true)] {
        let caption = format!("BRDF θi = {t}°");
        let marked = format!("{caption} (extrapolated)");
        assert!(s.contains(&caption), "no panel `{caption}`");
        assert_eq!(
            s.contains(&marked),
            extrapolated,
            "panel {t}: extrapolated should be {extrapolated}"
        );
    }
    assert!(!s.contains("BTDF"), "a reflection-only file has no BTDF panel");
    for label in ["measured", "model"] {
        assert!(s.contains(label), "no `{label}` in the legend");
    }
}

#[test]
fn plot_of_a_bad_bsdf_file_is_a_clean_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png").display().to_string();
    // Not a tensor file.
    let bad = dir.path().join("notes.bsdf");
    std::fs::write(&bad, "these are notes, not a measurement\n").unwrap();
    let bad = bad.display().to_string();
    fails_with(&["plot", &bad, "--out", &out], &[&bad, "not a tensor file"]);
    // Truncated.
    let cut = dir.path().join("cut.bsdf");
    let full = std::fs::read(Path::new(ROOT).join(SATIN)).unwrap();
    std::fs::write(&cut, &full[..full.len() / 3]).unwrap();
    let cut = cut.display().to_string();
    fails_with(&["plot", &cut, "--out", &out], &[&cut]);
    // Missing.
    fails_with(
        &["plot", "data/reference/rgl/absent.bsdf", "--out", &out],
        &["absent.bsdf"],
    );
    // Bad slices and filters.
    fails_with(&["plot", SATIN, "--theta-i", "95", "--out", &out], &["--theta-i"]);
    fails_with(&["plot", SATIN, "--max-theta", "0", "--out", &out], &["--max-theta"]);
    // --theta-i chooses slices of a .bsdf file; a CSV has its own angles.
    fails_with(
        &["plot", "data/matte.csv", "--theta-i", "30", "--out", &out],
        &["--theta-i", ".bsdf"],
    );
    assert!(!Path::new(&out).exists(), "no figure is written on error");
}
