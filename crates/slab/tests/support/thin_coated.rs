//! The thin coated sheet that tests and examples of more than one crate
//! share (the slab tests' `support::thin_coated_sheet`, the CLI's
//! `tests/cli_refine.rs`, `examples/slab_build.rs`; included by `#[path]`,
//! so it holds text only and needs no dependency): a thin sheet of optical
//! thickness 1.8, a GGX 0.3 front of index 1.5 over a base of 1.4 with a
//! GGX 0.15 back, `face_scattering` "multiple" (the default). Fitted papers
//! have a front and a base of different indices (docs/fit_table.md), and
//! thin ones light through.

/// The sheet's parameters as JSON (docs/design.md section 3).
pub const THIN_COATED_SHEET_JSON: &str = r#"{"d":0.03,"sigma_a":0.5,"sigma_s":60,"g_f":0.6,"g_b":-0.3,"w_b":0.2,"eta_f":1.5,"eta_b":1.4,"m_f":0.3,"m_b":0.15,"dist_f":"ggx","dist_b":"ggx"}"#;
