//! The bridge to the Paper BSDF of `paperbsdf-core` (Papas, de Mesa, Jensen,
//! EGSR 2014): building it from parameters and looking up named presets
//! (`paperbsdf_core::presets`).

use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::{Bsdf, PaperParams, ParamError};
use std::sync::Arc;

/// Builds the Paper BSDF for `p` (validating the parameters).
pub fn paper_bsdf(p: &PaperParams) -> Result<Arc<dyn Bsdf>, ParamError> {
    Ok(Arc::new(PaperBsdf::new(p)?))
}

/// The parameters of a named preset, if there is one.
pub fn preset(name: &str) -> Option<PaperParams> {
    paperbsdf_core::presets::preset(name)
}

/// The names of the available presets (for error messages).
pub fn preset_names() -> Vec<String> {
    paperbsdf_core::presets::PRESET_NAMES
        .iter()
        .map(|s| s.to_string())
        .collect()
}
