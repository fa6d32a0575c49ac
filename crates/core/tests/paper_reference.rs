//! The Paper BSDF against the brute-force slab of `reference/` (Mitsuba 3's
//! volumetric path tracer, docs/design.md section 6): the model is an
//! approximation, so this pins its measured accuracy rather than agreement.
//! At the time of writing the root-mean-square of `ln((f_model + e) /
//! (f_ref + e))` with `e = 1e-3` over all in-plane points was 0.124 (devA,
//! matte-like) and 0.089 (devB, glossy-like); the test fails if a change makes
//! it worse than 0.16 or 0.12.

#[path = "common.rs"]
mod common;

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::{Bsdf, PaperParams};

fn rms_log_error(dev: &str) -> f64 {
    let txt = common::read_text(&format!("{dev}.json"));
    let mut p: PaperParams = serde_json::from_str(&txt).unwrap();
    // The references were made with Walter's faces (Mitsuba's roughdielectric).
    p.face_scattering = paperbsdf_core::FaceScattering::Single;
    let b = PaperBsdf::new(&p).unwrap();
    let rows = common::read_csv(&format!("{dev}.csv"));
    assert!(rows.len() > 50);
    let mut s = 0.0;
    for r in &rows {
        let ti: f64 = r["theta_i_deg"].parse().unwrap();
        let to: f64 = r["theta_o_deg"].parse().unwrap();
        let f: f64 = r["f"].parse().unwrap();
        let (wi, wo) = in_plane_directions(ti, to, r["kind"] == "T");
        let m = b.eval(wi, wo).0[0];
        s += ((m + 1e-3) / (f + 1e-3)).ln().powi(2);
    }
    (s / rows.len() as f64).sqrt()
}

#[test]
fn accuracy_against_brute_force() {
    let (a, b) = (rms_log_error("devA"), rms_log_error("devB"));
    eprintln!("rms log error: devA {a:.3}, devB {b:.3}");
    assert!(a < 0.16, "devA: {a}");
    assert!(b < 0.12, "devB: {b}");
}
