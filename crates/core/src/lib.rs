//! # paperbsdf-core
//!
//! The Paper BSDF of Papas, de Mesa and Jensen (EGSR 2014) and its building
//! blocks, in the conventions of the project's DESIGN.md (section 2): local frame
//! with the front face's macro normal `+z`, `f(wi, wo)` without cosine, `wi`
//! toward the light, `wo` toward the viewer, lengths in millimetres.
//!
//! This crate has no heavy dependencies (glam, libm, serde derive, thiserror) so
//! that any renderer can use it.

#![warn(missing_docs)]

pub mod boundary;
pub mod boundary_tables;
pub mod bsdf;
pub mod dielectric;
pub mod fresnel;
pub mod geometry;
pub mod microfacet;
pub mod microsurface;
pub mod microsurface_tables;
pub mod models;
pub mod paper;
pub mod params;
pub mod phase;
pub mod presets;
pub mod quadrature;
pub mod sheet;
pub mod spectrum;

pub use bsdf::{Bsdf, BsdfFlags, BsdfSample, TransportMode};
pub use dielectric::{RoughDielectric, RoughDielectricParams};
pub use glam::DVec3;
pub use microfacet::{Distribution, Microfacet};
pub use params::{Colour, FaceScattering, PaperParams, ParamError};
pub use sheet::Sheet;
pub use spectrum::Rgb;
