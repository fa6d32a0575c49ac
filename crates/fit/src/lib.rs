//! # paperbsdf-fit
//!
//! Fitting BSDF models to in-plane (or general) BSDF measurements, as in
//! sections 5 to 7 of the Paper BSDF supplement and docs/design.md section 5:
//!
//! * [`measurement`]: the measurement files' reader of [`paperbsdf_io::measurement`],
//!   re-exported (errors name the file, line and column);
//! * [`model`]: what the fitter needs of a model ([`model::FitModel`]);
//! * [`models`]: the Paper BSDF and the comparison models as fit models;
//! * [`objective`]: the log-space RMS error and its weighting;
//! * [`optimize`]: bounded Levenberg-Marquardt in the unit cube;
//! * [`dataset`]: several files fitted together, thickness from headers;
//! * [`measured`]: sampling a measured `.bsdf` file, goniometer filters, measured albedo;
//! * [`report`]: what the data determine (each parameter's interval within the model's
//!   own error, from profile refits; noise standard errors; bounds) and degenerate-data checks;
//! * [`refine`]: a `paper` fit refined with the model `slab` (the same sheet
//!   solved by adding-doubling, `paperbsdf_slab`);
//! * [`error`]: the crate's error type [`FitError`];
//! * [`fitter`]: global multi-start search plus local refinement, scoring of
//!   fitted and extrapolation points.

#![warn(missing_docs)]

pub mod dataset;
pub mod error;
pub mod fitter;
pub mod measured;
pub mod measurement;
pub mod model;
pub mod models;
pub mod objective;
pub mod optimize;
pub mod refine;
pub mod report;

pub use error::FitError;
pub use fitter::{fit, FitOptions, FitOutcome, GroupError};
pub use measurement::{parse_measurement, read_measurement, Kind, Measurement, MeasurementError, Point};
pub use model::{fix_params, parse_fix, ComponentModel, FitModel, ParamSpec, Scale, Subset};
pub use refine::{refine_with_slab, RefineOptions, Refinement};
