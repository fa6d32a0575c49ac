//! The fit crate's one error type: what went wrong in setting up a fit (an
//! unknown model or parameter, a bad `--fix`, thickness or filter, data files
//! that do not go together, parameters a model refuses) and in the fit itself
//! (no points, degenerate data, no convergence, a meaningless result). Each
//! message says what is wrong and where (file, flag, parameter, allowed range);
//! the CLI and the Python package print them as they are.

use paperbsdf_core::models::ModelKind;
use paperbsdf_core::ParamError;
use paperbsdf_io::DataError;

/// Why a fit could not be set up or failed.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// Nothing to fit.
    #[error("no measurement points to fit{0}")]
    NoPoints(String),
    /// The local refinement did not converge within its budget.
    #[error("the fit did not converge: the best refinement ({variant}) stopped after {iterations} iterations without meeting the tolerance (RMS log error so far {rms:.4e}); raise the iteration limit")]
    NotConverged {
        /// Variant of the best refinement.
        variant: String,
        /// Iterations used.
        iterations: usize,
        /// Error reached.
        rms: f64,
    },
    /// The data cannot determine the parameters (too few values, no signal, no weight).
    #[error("the data cannot determine a fit: {0}")]
    Degenerate(String),
    /// The best fit misses the data so badly that its parameters mean nothing.
    #[error("the best fit ({variant}) misses the data by a factor {factor:.3e} on average (RMS log error {rms:.3}, above {limit}): the model cannot represent these data, so no parameters are written. Check the units (f without the cosine, 1/sr) and the values")]
    Meaningless {
        /// Variant of the best fit.
        variant: String,
        /// Its RMS log error.
        rms: f64,
        /// exp(rms).
        factor: f64,
        /// The limit [`crate::report::MEANINGLESS_RMS`].
        limit: f64,
    },
    /// The model could not be evaluated anywhere.
    #[error("the model could not be evaluated at any starting point: {0}")]
    NoValidStart(String),
    /// A model name the fitter does not know.
    #[error(
        "unknown model `{name}` for fitting; models that can be fitted: {}",
        ModelKind::list(ModelKind::fittable())
    )]
    UnknownModel {
        /// The name given.
        name: String,
    },
    /// A slab model without its thickness.
    #[error("model `{0}` needs the paper's thickness d: pass --thickness D (mm) or give the data a `# thickness: D` or `# params: {{\"d\": D, ...}}` header")]
    NeedsThickness(String),
    /// A thickness outside (0, inf) mm (from the data's header or the caller).
    #[error("thickness d = {0} is outside its allowed range (0, inf) mm")]
    Thickness(f64),
    /// `--thickness` outside (0, inf) mm.
    #[error("--thickness {0} is outside its allowed range (0, inf) mm")]
    ThicknessFlag(f64),
    /// Parameters the model refuses (the parameter and its allowed range).
    #[error(transparent)]
    Params(#[from] ParamError),
    /// A parameter object (a FIT.json's `params`) that is not the model's parameter set.
    #[error("params of `{model}`: {source}")]
    ParamsJson {
        /// The model.
        model: String,
        /// What the JSON reader found.
        source: serde_json::Error,
    },
    /// A measurement file that cannot be read (file, line, column).
    #[error(transparent)]
    Data(#[from] DataError),
    /// No measurement files.
    #[error("no measurement files given")]
    NoFiles,
    /// Files fitted together with different channel counts.
    #[error("{file}: has {channels} channel(s) but {first} has {first_channels}")]
    ChannelMismatch {
        /// The file that differs.
        file: String,
        /// Its channel count.
        channels: usize,
        /// The first file.
        first: String,
        /// The first file's channel count.
        first_channels: usize,
    },
    /// Files fitted together whose headers give different thicknesses.
    #[error("{file}: thickness {d} mm differs from {first_d} mm in {first}; pass --thickness")]
    ThicknessMismatch {
        /// The file that differs.
        file: String,
        /// Its thickness (mm).
        d: f64,
        /// The first file with a thickness.
        first: String,
        /// That file's thickness (mm).
        first_d: f64,
    },
    /// `--exclude-retro` outside [0, 180) degrees.
    #[error("--exclude-retro {0} is outside its allowed range [0, 180) degrees")]
    ExcludeRetro(f64),
    /// `--max-theta` outside (0, 90] degrees.
    #[error("--max-theta {0} is outside its allowed range (0, 90] degrees")]
    MaxTheta(f64),
    /// A free parameter the model does not have.
    #[error("model `{model}` has no parameter `{name}`")]
    UnknownParameter {
        /// The model.
        model: String,
        /// The name asked for.
        name: String,
    },
    /// A `--fix` argument that is not `NAME=VALUE`.
    #[error("--fix `{0}`: expected NAME=VALUE, e.g. --fix eta_f=1.5")]
    FixSyntax(String),
    /// A `--fix` value that is not a number.
    #[error("--fix `{arg}`: `{value}` is not a number")]
    FixNotNumber {
        /// The argument.
        arg: String,
        /// Its value part.
        value: String,
    },
    /// A `--fix` value that is not finite.
    #[error("--fix `{0}`: the value must be finite")]
    FixNotFinite(String),
    /// A `--fix` of a parameter the model does not fit.
    #[error("--fix {name}={value}: model `{model}` has no fitted parameter `{name}` (fitted parameters: {known}; the thickness is --thickness)")]
    FixUnknown {
        /// The name.
        name: String,
        /// The value.
        value: f64,
        /// The model.
        model: String,
        /// The fitted parameters, comma-separated.
        known: String,
    },
    /// Fixed values the model refuses.
    #[error("--fix: the model refuses the fixed values: {0}")]
    FixRefused(Box<FitError>),
    /// `--fix` of every parameter.
    #[error("--fix holds every parameter: nothing is left to fit")]
    FixAll,
    /// The `slab` model's solver refused a sheet for a reason other than a
    /// parameter range (a parameter outside its range is [`FitError::Params`]).
    #[error("the slab model's solver: {0}")]
    Slab(paperbsdf_slab::SlabError),
    /// A refinement with `slab` asked of a model whose parameters are not the sheet's.
    #[error("--refine slab refines a fit of `paper` or `reduced-multilayer` (the same sheet parameters); `{model}` has other parameters")]
    RefineFrom {
        /// The model of the fit that was to be refined.
        model: String,
    },
}

impl From<paperbsdf_slab::SlabError> for FitError {
    fn from(e: paperbsdf_slab::SlabError) -> FitError {
        match e {
            paperbsdf_slab::SlabError::Param(p) => FitError::Params(p),
            other => FitError::Slab(other),
        }
    }
}
