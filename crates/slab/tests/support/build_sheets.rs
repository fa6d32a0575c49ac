//! The sheets whose builds are the slowest (examples/slab_build.rs prints
//! their times, benches/slab.rs measures them with criterion; included by
//! `#[path]`): the RGB thin sheet with unequal faces, the worst case of the
//! builds (three media, each solved twice, and the unscattered term through
//! two unequal rough faces: docs/slab.md, "Builds, 2026-12-08 (night)").

use paperbsdf_core::presets::preset;
use paperbsdf_core::{Colour, Distribution, PaperParams};

/// A thin RGB sheet (optical thickness 1.2 in green) with a GGX 0.1 front
/// and a Beckmann 0.25 back, the rest matte's.
pub fn rgb_thin_unequal() -> PaperParams {
    PaperParams {
        name: Some("RGB thin sheet, GGX 0.1 front, Beckmann 0.25 back".into()),
        d: 0.03,
        sigma_a: Colour::Rgb([0.2, 1.5, 4.0]),
        sigma_s: Colour::Rgb([40.0, 38.0, 35.0]),
        m_f: 0.1,
        m_b: 0.25,
        dist_f: Distribution::Ggx,
        dist_b: Distribution::Beckmann,
        ..preset("matte").expect("the matte preset")
    }
}
