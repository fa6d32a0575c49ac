//! Shared helpers of the simulator's tests: reading the independent reference files in
//! the repository's `data/reference` (`$PAPERBSDF_REFERENCE` overrides), produced by
//! Mitsuba 3 and iadpython.
//!
//! Known defect of that data: the `theta_i = 75` rows of devA.csv and devB.csv are not
//! reciprocal (Mitsuba's directional light at grazing incidence on a rough face; see
//! `../mitsuba_slab.rs` and `../../tools/mitsuba_reciprocity.py`). [`read_inplane_fixed`]
//! replaces them by the reciprocal remeasurement in `devA_grazing.csv`, `devB_grazing.csv`.
//!
//! The references were made with Walter's single-scattering faces (Mitsuba's
//! `roughdielectric`) or smooth faces, so the parameters read here have
//! `face_scattering = "single"` whatever the file says.

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

/// Parameters from a JSON file of the reference data, with Walter's single-scattering
/// faces (`face_scattering = "single"`, as the references were made).
pub fn params(name: &str) -> PaperParams {
    let text = read_text(name);
    let mut p: PaperParams = serde_json::from_str(&text).unwrap();
    p.face_scattering = paperbsdf_core::FaceScattering::Single;
    p
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

/// The rows of `{name}.csv` with its `theta_i = 75` rows replaced by those of
/// `{name}_grazing.csv` (the reciprocal remeasurement). Returns the rows and,
/// for each, whether it comes from the grazing file with `theta_o = +-80`, where
/// the light of the remeasurement is itself grazing and the value remains doubtful.
pub fn read_inplane_fixed(name: &str) -> Vec<(RefRow, bool)> {
    let mut rows: Vec<(RefRow, bool)> = read_inplane(&format!("{name}.csv"))
        .into_iter()
        .filter(|r| r.theta_i != 75.0)
        .map(|r| (r, false))
        .collect();
    let grazing = read_inplane(&format!("{name}_grazing.csv"));
    assert!(
        grazing.len() == 18 && grazing.iter().all(|r| r.theta_i == 75.0),
        "{name}_grazing.csv: expected the 18 rows at theta_i = 75"
    );
    rows.extend(grazing.into_iter().map(|r| {
        let doubtful = r.theta_o.abs() == 80.0;
        (r, doubtful)
    }));
    rows
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
        face_scattering: paperbsdf_core::FaceScattering::Single,
    }
}
