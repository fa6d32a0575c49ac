//! Three example papers as [`PaperParams`]: matte office paper, luster photo
//! paper and glossy photo paper (the three samples of the paper's Figure 3).
//!
//! The numbers are physically plausible estimates, not fits to the paper's
//! measurements (which are not available here); where each comes from is
//! noted beside it. Coefficients in 1/mm, lengths in mm. A rough guide to the
//! scattering values: in the diffusion limit a white slab transmits about
//! `T_d = (l + z_b)/(d + 2 z_b)` with `l = 1/sigma_t'`, `z_b = 2 A/(3 sigma_t')`
//! and `A ~ 3` for a rough face of index 1.5, so office paper's transmittance
//! of 10 to 20 % (ISO opacity about 90 %) at `d = 0.1 mm` needs
//! `sigma_s'` of one to two hundred per mm. The values were then checked by
//! evaluating the model (tests/paper_presets.rs).

use crate::microfacet::Distribution;
use crate::params::{Colour, PaperParams};

/// Names accepted by [`preset`].
pub const PRESET_NAMES: [&str; 3] = ["matte", "luster", "glossy"];

/// The preset of that name (one of [`PRESET_NAMES`]; also accepted: `office`,
/// `matte-office`, `luster-photo`, `glossy-photo`), or `None`.
pub fn preset(name: &str) -> Option<PaperParams> {
    match name.to_ascii_lowercase().as_str() {
        "matte" | "office" | "matte-office" => Some(matte_office()),
        "luster" | "luster-photo" => Some(luster_photo()),
        "glossy" | "glossy-photo" => Some(glossy_photo()),
        _ => None,
    }
}

/// Matte office paper (80 g/m^2 copy paper).
pub fn matte_office() -> PaperParams {
    PaperParams {
        name: Some("matte office paper".into()),
        // 80 g/m^2 copy paper is 0.10 to 0.11 mm thick (caliper of ISO 534).
        d: 0.1,
        // Bleached cellulose absorbs very little; optical brighteners absorb a
        // little more red than blue, giving the bluish white of office paper.
        // sigma_a / sigma_s' ~ 5e-4 gives R_inf ~ 0.9 (ISO brightness ~90 %).
        sigma_a: Colour::Rgb([0.12, 0.10, 0.07]),
        // sigma_s' = 0.44 * 300 ~ 130 /mm: with these faces the model gives
        // R ~ 0.73 and T ~ 0.13 near normal incidence (opacity ~85-90 %).
        sigma_s: Colour::Scalar(300.0),
        // Fibres of ~20 um scatter strongly forward; a weak backward lobe gives
        // the retroreflection of the supplement's matte plots (section 5).
        g_f: 0.8,
        g_b: -0.4,
        w_b: 0.2,
        // Cellulose has an index of about 1.5 (1.53 to 1.56 for fibre walls).
        eta_f: 1.5,
        eta_b: 1.5,
        // Uncoated paper is rough at the fibre scale; the supplement finds GGX
        // fits matte paper better than Beckmann (section 5). GGX's long tails
        // give a broad sheen already at alpha 0.15; much rougher single-scattering
        // microfacet faces lose a large part of the diffuse light inside
        // (shadowing: about 10 % per internal hit at alpha 0.2, 30 % at 0.5),
        // which would make the sheet far darker than paper.
        m_f: 0.15,
        m_b: 0.15,
        dist_f: Distribution::Ggx,
        dist_b: Distribution::Ggx,
        face_scattering: Default::default(),
    }
}

/// Luster (semi-gloss) resin-coated photo paper.
pub fn luster_photo() -> PaperParams {
    PaperParams {
        name: Some("luster photo paper".into()),
        // Resin-coated photo papers are 0.25 to 0.27 mm thick (250 to 270 g/m^2).
        d: 0.25,
        // White base with a TiO2-filled coating: low absorption, neutral.
        sigma_a: Colour::Scalar(0.15),
        // More opaque than office paper (TiO2 pigment, 2.5 times thicker):
        // sigma_s' ~ 0.5 * 300 = 150 /mm gives R ~ 0.86, T ~ 0.02.
        sigma_s: Colour::Scalar(300.0),
        g_f: 0.7,
        g_b: -0.3,
        w_b: 0.3,
        // Polyethylene / gelatin coating, index ~1.5.
        eta_f: 1.5,
        // Back: the paper side, cellulose ~1.5.
        eta_b: 1.5,
        // Luster finish: a broad off-specular peak; the supplement models the
        // photo papers' front with Beckmann (section 5); alpha ~0.15 is a
        // semi-gloss sheen, and the back is a rough GGX paper surface.
        m_f: 0.15,
        m_b: 0.3,
        dist_f: Distribution::Beckmann,
        dist_b: Distribution::Ggx,
        face_scattering: Default::default(),
    }
}

/// Glossy resin-coated photo paper.
pub fn glossy_photo() -> PaperParams {
    PaperParams {
        name: Some("glossy photo paper".into()),
        // As luster paper: 0.25 mm.
        d: 0.25,
        sigma_a: Colour::Scalar(0.15),
        sigma_s: Colour::Scalar(300.0),
        g_f: 0.7,
        g_b: -0.3,
        w_b: 0.3,
        // Glossy polymer top coat, index ~1.55.
        eta_f: 1.55,
        eta_b: 1.5,
        // Glossy finish: a sharp specular peak, alpha ~0.04 (Beckmann, supplement section 5).
        m_f: 0.04,
        m_b: 0.3,
        dist_f: Distribution::Beckmann,
        dist_b: Distribution::Ggx,
        face_scattering: Default::default(),
    }
}
