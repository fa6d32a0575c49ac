//! The bridge to the Paper BSDF of `paperbsdf-core` (Papas, de Mesa, Jensen,
//! EGSR 2014): building it from parameters and looking up named presets
//! (`paperbsdf_core::presets`); and to the model `slab` (`paperbsdf_slab`),
//! the same sheet solved numerically.

use paperbsdf_core::paper::PaperBsdf;
use paperbsdf_core::{Bsdf, PaperParams, ParamError};
use std::sync::Arc;

/// Builds the Paper BSDF for `p` (validating the parameters).
pub fn paper_bsdf(p: &PaperParams) -> Result<Arc<dyn Bsdf>, ParamError> {
    Ok(Arc::new(PaperBsdf::new(p)?))
}

/// Builds the model `slab` for `p`: the same sheet solved by adding-doubling
/// (`paperbsdf_slab::SlabBsdf`); its errors as parameter errors (the
/// parameter's name and range, or `model` for what the solver does not support).
pub fn slab_bsdf(p: &PaperParams) -> Result<Arc<dyn Bsdf>, ParamError> {
    slab_bsdf_with(p, &paperbsdf_slab::SlabOptions::default())
}

/// [`slab_bsdf`] with the solver's discretisation `options` (a material's
/// `slab_nodes`).
pub fn slab_bsdf_with(p: &PaperParams, options: &paperbsdf_slab::SlabOptions) -> Result<Arc<dyn Bsdf>, ParamError> {
    match paperbsdf_slab::SlabBsdf::with_options(p, options) {
        Ok(b) => Ok(Arc::new(b)),
        Err(paperbsdf_slab::SlabError::Param(e)) => Err(e),
        Err(e) => Err(ParamError::Invalid {
            name: "model".to_string(),
            message: format!("`slab`: {e}"),
        }),
    }
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
