//! # paperbsdf-io
//!
//! Reading and writing the project's files in the conventions of docs/design.md:
//! parameter files (JSON, TOML or inline JSON) with errors that name the file,
//! line and parameter; CSV files of direction pairs and of BSDF measurements
//! ([`measurement`]), with errors that name the file, line and column; atomic
//! output (a temp file renamed into place, so a failed run leaves no
//! half-written result).

#![warn(missing_docs)]

pub mod angles;
pub mod atomic;
pub mod dirs;
pub mod error;
pub mod measurement;
pub mod models;
pub mod params;
pub mod rgl;
pub mod text;

pub use atomic::{check_output_path, write_atomic};
pub use error::DataError;
pub use params::{load_params, read_source_full, Loaded, Source};
pub use rgl::MeasuredBsdf;
