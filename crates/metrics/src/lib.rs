//! # paperbsdf-metrics
//!
//! What paper makers measure, predicted from the Paper BSDF (or any model of
//! the project, through its public BSDF interface) and from the ground-truth
//! simulator: ISO 2471 and TAPPI T425 opacity, ISO 2470-1 brightness (from
//! the blue channel), specular gloss (TAPPI T480/T653, ASTM D523), ISO 9416
//! Kubelka-Munk coefficients and the scatter distance of the supplement's
//! section 1; and the way back, Paper BSDF parameters from a datasheet.
//! Definitions, geometries and sources are in `docs/paper_metrics.md` and in
//! each module's doc.

#![warn(missing_docs)]

pub mod datasheet;
pub mod edge;
pub mod gloss;
pub mod instrument;
pub mod measure;
pub mod pad;

pub use datasheet::{fit_datasheet, Datasheet, DatasheetError, DatasheetFit};
pub use measure::{measure_model, measure_truth, MeasureError, Measurements, Selection, TruthConfig, METRIC_NAMES};
