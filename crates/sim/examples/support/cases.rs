//! The cases of docs/accuracy.md, shared by the examples that measure the
//! models on them (`crates/sim/examples/accuracy.rs`, and
//! `crates/slab/examples/convergence.rs` through `#[path]`): the three
//! presets, devA and devB (read from data/reference), and the synthetic
//! sheets (`crates/sim/tools/recheck_rows.py` lists the same in Python).

use paperbsdf_core::{Colour, Distribution, PaperParams};

/// A sheet of the spread: the presets' phase function and indices, GGX back face.
fn paper(name: &str, d: f64, sigma_a: f64, sigma_s: f64, m_f: f64, m_b: f64, dist_f: Distribution) -> PaperParams {
    PaperParams {
        name: Some(name.into()),
        d,
        sigma_a: Colour::Scalar(sigma_a),
        sigma_s: Colour::Scalar(sigma_s),
        g_f: 0.8,
        g_b: -0.3,
        w_b: 0.2,
        eta_f: 1.5,
        eta_b: 1.5,
        m_f,
        m_b,
        dist_f,
        dist_b: Distribution::Ggx,
        face_scattering: Default::default(),
    }
}

/// The accuracy cases by name: the three presets, devA and devB
/// (data/reference), and a spread of sheets from thin to thick and smooth to rough.
pub fn cases() -> Vec<(String, PaperParams)> {
    let dev = |f: &str| -> PaperParams {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/reference/").to_string() + f;
        serde_json::from_str(&std::fs::read_to_string(&path).expect("reference parameters")).expect("valid JSON")
    };
    let mut v: Vec<(String, PaperParams)> = paperbsdf_core::presets::PRESET_NAMES
        .iter()
        .map(|n| {
            (
                format!("preset-{n}"),
                paperbsdf_core::presets::preset(n).expect("preset"),
            )
        })
        .collect();
    v.push(("devA".into(), dev("devA.json")));
    v.push(("devB".into(), dev("devB.json")));
    v.push((
        "thin-tissue".into(),
        paper(
            "thin tissue: d 0.03, tau 1.2, m 0.3",
            0.03,
            0.3,
            40.0,
            0.3,
            0.3,
            Distribution::Ggx,
        ),
    ));
    v.push((
        "weak-scatter".into(),
        paper(
            "weakly scattering: d 0.1, tau 3, m 0.3",
            0.1,
            0.5,
            30.0,
            0.3,
            0.3,
            Distribution::Ggx,
        ),
    ));
    v.push((
        "thick-board".into(),
        paper(
            "thick board: d 0.3, tau 60, m 0.3",
            0.3,
            0.5,
            200.0,
            0.3,
            0.3,
            Distribution::Ggx,
        ),
    ));
    v.push((
        "smooth-front".into(),
        paper(
            "smooth front: m_f 0.05 beckmann, d 0.1, tau 15",
            0.1,
            0.5,
            150.0,
            0.05,
            0.3,
            Distribution::Beckmann,
        ),
    ));
    v.push((
        "very-rough".into(),
        paper(
            "very rough: m 0.9, d 0.1, tau 15",
            0.1,
            0.5,
            150.0,
            0.9,
            0.9,
            Distribution::Ggx,
        ),
    ));
    v
}
