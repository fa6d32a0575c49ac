//! The face lobe's albedo that `slab` balances its tables against
//! (`paperbsdf_slab::face_albedo`) against core's tabulated reflectance and
//! against its own rule with more panels, and its interpolation between the
//! nodes (the numbers of `FACE_ALBEDO_PANELS`' doc, `cubic_at`'s doc and
//! the module doc's "Energy" section):
//!
//! `cargo run --release -p paperbsdf-slab --example face_albedo`
//!
//! Per face (a front of eta 1.5, or 1.6 for the coated Beckmann 0.25 of
//! tests/slab_bsdf.rs) and cosine `mu`: core's `face_interface_reflectance`,
//! the rule at 16 and at [`FACE_ALBEDO_PANELS`] panels, each minus the rule
//! at 128 panels. Then, for the GGX 0.2 front, `SlabBsdf::face_reflectance`
//! (the cubic between the nodes) and linear interpolation of the same node
//! values, each minus the 128-panel rule, largest over 1-degree steps.

use paperbsdf_core::paper::Side;
use paperbsdf_core::{Colour, Distribution, FaceScattering, PaperBsdf, PaperParams};
use paperbsdf_slab::bsdf::FACE_ALBEDO_PANELS;
use paperbsdf_slab::{face_albedo, SlabBsdf};

fn sheet(eta_f: f64, m_f: f64, dist_f: Distribution, fs: FaceScattering) -> PaperParams {
    PaperParams {
        name: None,
        d: 0.05,
        sigma_a: Colour::Scalar(0.0),
        sigma_s: Colour::Scalar(60.0),
        g_f: 0.8,
        g_b: -0.4,
        w_b: 0.2,
        eta_f,
        m_f,
        dist_f,
        eta_b: 1.45,
        m_b: 0.3,
        dist_b: Distribution::Ggx,
        face_scattering: fs,
    }
}

fn main() -> Result<(), String> {
    const FINE: usize = 128;
    println!("face, mu: core - fine, 16 panels - fine, {FACE_ALBEDO_PANELS} panels - fine ({FINE} panels)");
    for (eta, m, d) in [
        (1.5, 0.1, Distribution::Ggx),
        (1.5, 0.2, Distribution::Ggx),
        (1.5, 0.8, Distribution::Ggx),
        (1.6, 0.25, Distribution::Beckmann),
        (1.5, 0.15, Distribution::Beckmann),
        (1.5, 0.04, Distribution::Beckmann),
    ] {
        let paper = PaperBsdf::new(&sheet(eta, m, d, FaceScattering::Single)).map_err(|e| e.to_string())?;
        for mu in [1.0, 0.9, 0.5, 0.2, 0.05, 0.01] {
            let fine = face_albedo(&paper, Side::Front, mu, FINE);
            println!(
                "{d:?} {m} eta {eta}, mu {mu}: {:+.2e} {:+.2e} {:+.2e}",
                paper.face_interface_reflectance(Side::Front, mu) - fine,
                face_albedo(&paper, Side::Front, mu, 16) - fine,
                face_albedo(&paper, Side::Front, mu, FACE_ALBEDO_PANELS) - fine
            );
        }
    }
    // Interpolation between the nodes, GGX 0.2 front (the first sheet of
    // tests/slab_bsdf.rs's energy test).
    let p = sheet(1.5, 0.2, Distribution::Ggx, FaceScattering::Multiple);
    let slab = SlabBsdf::new(&p).map_err(|e| e.to_string())?;
    let paper = PaperBsdf::new(&PaperParams {
        face_scattering: FaceScattering::Single,
        ..p
    })
    .map_err(|e| e.to_string())?;
    let nodes = slab.nodes();
    let at_nodes: Vec<f64> = nodes
        .iter()
        .map(|&mu| face_albedo(&paper, Side::Front, mu, FACE_ALBEDO_PANELS))
        .collect();
    let (mut cubic, mut linear) = ((0.0f64, 0.0), (0.0f64, 0.0));
    for deg in 0..=89 {
        let mu = (deg as f64).to_radians().cos();
        let fine = face_albedo(&paper, Side::Front, mu, FINE);
        let i = nodes.partition_point(|&x| x <= mu).clamp(1, nodes.len() - 1) - 1;
        let t = ((mu - nodes[i]) / (nodes[i + 1] - nodes[i])).clamp(0.0, 1.0);
        let lin = at_nodes[i] * (1.0 - t) + at_nodes[i + 1] * t;
        let c = (slab.face_reflectance(Side::Front, mu) - fine).abs();
        if c > cubic.0 {
            cubic = (c, deg as f64);
        }
        let l = (lin - fine).abs();
        if l > linear.0 {
            linear = (l, deg as f64);
        }
    }
    println!(
        "GGX 0.2 front between the nodes, largest |interpolated - fine| over 0..89 degrees: cubic {:.2e} (at {} degrees), linear {:.2e} (at {} degrees)",
        cubic.0, cubic.1, linear.0, linear.1
    );
    Ok(())
}
