//! # paperbsdf-core
//!
//! The Paper BSDF of Papas, de Mesa and Jensen (EGSR 2014) and its building
//! blocks, in the conventions of docs/design.md (section 2): local frame
//! with the front face's macro normal `+z`, `f(wi, wo)` without cosine, `wi`
//! toward the light, `wo` toward the viewer, lengths in millimetres.
//!
//! This crate has no heavy dependencies (glam, libm, serde derive, thiserror) so
//! that any renderer can use it.
//!
//! ## Using the Paper BSDF
//!
//! Build a [`PaperBsdf`] from parameters (a preset, a struct, or JSON through
//! serde), then evaluate, sample and query the density in the local frame:
//!
//! ```
//! use paperbsdf_core::{presets, Bsdf, DVec3, PaperBsdf};
//!
//! let params = presets::preset("matte").expect("a preset");
//! let bsdf = PaperBsdf::new(&params).expect("valid parameters");
//!
//! // Light 30 degrees from the normal on the +x side; viewer straight above (reflection).
//! let t = 30f64.to_radians();
//! let wi = DVec3::new(t.sin(), 0.0, t.cos());
//! let wo = DVec3::Z;
//! let f = bsdf.eval(wi, wo); // RGB, 1/sr, without the cosine
//! assert!(f.0.iter().all(|&c| c > 0.0 && c.is_finite()));
//! // The viewer below the sheet sees the light that crossed it (transmission).
//! let ft = bsdf.eval(wi, -DVec3::Z);
//! assert!(ft.0[0] > 0.0 && ft.0[0] < f.0[0]);
//!
//! // Importance sampling for a path tracer: draw wi for wo from three uniform numbers.
//! if let Some(s) = bsdf.sample(wo, 0.37, [0.21, 0.84]) {
//!     // f |cos wi| / pdf multiplies the path throughput; pdf agrees with Bsdf::pdf.
//!     let w = s.weight();
//!     assert!(w.0.iter().all(|&c| c >= 0.0 && c.is_finite()));
//!     if s.pdf > 0.0 && !s.flags.is_specular() {
//!         assert!((bsdf.pdf(s.wi, wo) - s.pdf).abs() <= 1e-6 * s.pdf);
//!     }
//! }
//! ```
//!
//! The crate's README and `examples/renderer.rs` (`cargo run -p paperbsdf-core
//! --example renderer`) show how to put it into a renderer's shading frame.

#![warn(missing_docs)]

pub mod boundary;
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
pub use paper::{Component, PaperBsdf};
pub use params::{Colour, FaceScattering, PaperParams, ParamError};
pub use sheet::Sheet;
pub use spectrum::Rgb;
