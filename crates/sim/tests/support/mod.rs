//! Shared helpers of the simulator's tests: reading the independent reference files in
//! the repository's `data/reference` (`$PAPERBSDF_REFERENCE` overrides), produced by
//! Mitsuba 3 and iadpython.
//!
//! Known defect of that data: devA's `R` rows at `theta_i = 75` are not reciprocal (see
//! `../mitsuba_slab.rs` and `../../tools/mitsuba_reciprocity.py`); the tests do not count them.

#![allow(dead_code)]

use paperbsdf_core::PaperParams;
use std::path::PathBuf;

/// Path of a file of the reference data (`data/reference` in the repository).
pub fn data(name: &str) -> PathBuf {
    std::env::var_os("PAPERBSDF_REFERENCE")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/reference"))
        .join(name)
}

/// The text of a reference file; a missing file panics with its full path.
pub fn read_text(name: &str) -> String {
    let path = data(name);
    std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("reference data {}: {e} (see data/reference/README.md)", path.display()))
}

/// Parameters from a JSON file of the reference data.
pub fn params(name: &str) -> PaperParams {
    let text = read_text(name);
    serde_json::from_str(&text).unwrap()
}

/// A row of a Mitsuba in-plane reference (devA.csv, devB.csv).
#[derive(Clone, Debug)]
pub struct RefRow {
    /// `R` or `T`.
    pub transmission: bool,
    /// Incident polar angle, degrees.
    pub theta_i: f64,
    /// Signed viewing angle, degrees.
    pub theta_o: f64,
    /// BSDF value without cosine.
    pub f: f64,
    /// Its standard error.
    pub stderr: f64,
}

/// Reads a Mitsuba in-plane reference CSV (`kind,theta_i_deg,theta_o_deg,f,stderr,samples`).
pub fn read_inplane(name: &str) -> Vec<RefRow> {
    let text = read_text(name);
    text.lines()
        .filter(|l| l.starts_with('R') || l.starts_with('T'))
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            RefRow {
                transmission: c[0] == "T",
                theta_i: c[1].parse().unwrap(),
                theta_o: c[2].parse().unwrap(),
                f: c[3].parse().unwrap(),
                stderr: c[4].parse().unwrap(),
            }
        })
        .collect()
}

/// A row of slab_rt_dev.csv (iadpython adding-doubling).
#[derive(Clone, Debug)]
pub struct AdRow {
    /// Single-scattering albedo.
    pub albedo: f64,
    /// Optical thickness `sigma_t d`.
    pub tau: f64,
    /// HG mean cosine.
    pub g: f64,
    /// Index of the slab.
    pub n: f64,
    /// Collimated normal incidence: total reflectance, total transmittance.
    pub ur1: f64,
    /// See `ur1`.
    pub ut1: f64,
    /// Diffuse incidence: total reflectance, total transmittance.
    pub uru: f64,
    /// See `uru`.
    pub utu: f64,
}

/// Reads slab_rt_dev.csv.
pub fn read_ad() -> Vec<AdRow> {
    let text = read_text("slab_rt_dev.csv");
    text.lines()
        .filter(|l| l.starts_with(|c: char| c.is_ascii_digit()))
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            AdRow {
                albedo: v[0],
                tau: v[1],
                g: v[2],
                n: v[3],
                ur1: v[4],
                ut1: v[5],
                uru: v[6],
                utu: v[7],
            }
        })
        .collect()
}

/// The slab of an adding-doubling row: thickness 1 mm, smooth faces of index
/// `n`, one HG lobe, `sigma_t = tau`.
pub fn ad_params(albedo: f64, tau: f64, g: f64, n: f64) -> PaperParams {
    use paperbsdf_core::{Colour, Distribution};
    PaperParams {
        name: None,
        d: 1.0,
        sigma_a: Colour::Scalar(tau * (1.0 - albedo)),
        sigma_s: Colour::Scalar(tau * albedo),
        g_f: g,
        g_b: g,
        w_b: 0.0,
        eta_f: n,
        eta_b: n,
        m_f: 0.0,
        m_b: 0.0,
        dist_f: Distribution::Ggx,
        dist_b: Distribution::Ggx,
        face_scattering: Default::default(),
    }
}
