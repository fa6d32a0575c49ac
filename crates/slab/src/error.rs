//! The solver's typed errors.

use paperbsdf_core::ParamError;

/// What can go wrong when building or solving a slab.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SlabError {
    /// A physical parameter outside its range (the message names the
    /// parameter, its value and the allowed range).
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A discretisation setting outside its range.
    #[error("discretisation setting `{name}` = {value} is outside its allowed range {range}")]
    Discretisation {
        /// The setting's name (a field of [`crate::Discretisation`]).
        name: &'static str,
        /// The offending value.
        value: f64,
        /// The allowed range, as text.
        range: &'static str,
    },
    /// Two layers whose facing grids differ cannot be added.
    #[error("cannot add layers: the upper layer's bottom grid has {upper} nodes, the lower layer's top grid {lower}")]
    GridMismatch {
        /// Nodes of the upper layer's bottom side.
        upper: usize,
        /// Nodes of the lower layer's top side.
        lower: usize,
    },
    /// The interreflection matrix `I - R_a R_b` of an adding step is singular
    /// (two perfectly reflecting, lossless layers facing each other).
    #[error("the interreflection matrix of {step} is singular (two lossless reflectors facing each other)")]
    Singular {
        /// Which step failed.
        step: &'static str,
    },
    /// A rough face whose projection on the grid cannot be scaled to the
    /// face's own albedo (known for faces closest to index-matched: `eta`
    /// 1.001 with `m >= 0.1`, 1.01 with `m >= 0.8`; none from 1.02 on).
    #[error(
        "the model `slab` cannot represent the rough face of index {eta} ({dist}, m = {m}): its projection on the grid \
         did not converge to the face's albedo; `slab` does not support faces this close to index-matched yet \
         (eta 1.001 with m from 0.1 on, eta 1.01 with m from 0.8 on; more nodes let some of them through: 64 or 128 with `--slab-nodes`, `slab_nodes` or `SlabOptions::nodes`); \
         the model `paper` does"
    )]
    UnresolvedFace {
        /// The face's relative index.
        eta: f64,
        /// Its roughness.
        m: f64,
        /// Its microfacet distribution's name.
        dist: &'static str,
    },
    /// A configuration the solver does not handle yet.
    #[error("not supported yet: {0}")]
    Unsupported(&'static str),
}

/// Checks that `value` lies in the open interval `(min, max)`; the message names `name`.
pub(crate) fn check_open(name: &str, value: f64, min: f64, max: f64) -> Result<(), SlabError> {
    if value.is_nan() || value <= min || value >= max {
        return Err(ParamError::Invalid {
            name: name.to_string(),
            message: format!("{value} is outside its allowed open range ({min}, {max})"),
        }
        .into());
    }
    Ok(())
}
