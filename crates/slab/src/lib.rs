//! Fourier-basis adding-doubling for the paper slab: the foundation of the
//! numerical model `slab` of issue 13.
//!
//! The sheet of docs/design.md (a slab of scattering medium with a two-lobe
//! Henyey-Greenstein phase function between two dielectric faces) is solved
//! as in Jakob, d'Eon, Jakob, Marschner, "A Comprehensive Framework for
//! Rendering Layered Materials" (SIGGRAPH 2014), with the classical
//! adding-doubling of van de Hulst (1980) and Prahl, van Gemert, Welch (1993):
//! directions are discretised by quadrature in `mu = |cos theta|` per
//! hemisphere ([`quad`]), azimuth by Fourier orders in the azimuth difference
//! ([`phase`]), each order is a set of reflection and transmission matrices
//! ([`layer`]); the medium starts as a thin layer and is doubled to its
//! optical thickness, the faces ([`interface`]) are added to it ([`slab`]).
//! Orders are independent and solved in parallel (rayon); dense LU by nalgebra.
//!
//! **What exists.** Gauss-Radau / split Gauss-Legendre grids; HG Fourier
//! coefficients with symmetric normalisation; the diamond starting layer and
//! doubling; adding of general (unequal-grid) layers; smooth Fresnel faces of
//! equal index (or index-matched); totals for collimated light at a node and
//! for diffuse light, from either side.
//!
//! **What is missing for issue 13.** Rough faces projected from core's rough
//! dielectric (GGX, Beckmann, with the energy compensation of
//! `face_scattering = "multiple"`); faces of unequal index (the coated sheet of
//! docs/design.md 4.1); the analytic parts (surface reflection of the lit face,
//! unscattered transmission, exact single scattering) with the orders that
//! carry first scattering subtracted; interpolation of the matrices to
//! arbitrary directions and the BSDF's eval and sample; RGB channels; the
//! model registry and CLI; the speed targets.

pub mod error;
pub mod interface;
pub mod layer;
pub mod phase;
pub mod quad;
pub mod slab;

pub use error::SlabError;
pub use layer::{Layer, SymmetricLayer};
pub use quad::Grid;
pub use slab::{Discretisation, Face, Medium, Side, SlabSpec, Solution};
