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
//! doubling; adding of general (unequal-grid) layers; faces of equal index:
//! smooth Fresnel faces, index-matched faces, and rough faces of either
//! distribution (GGX, Beckmann) projected from core's Walter et al. rough
//! dielectric onto the grids and Fourier orders ([`interface`]: a graded
//! Gauss-Legendre rule in azimuth, symmetric normalisation to core's
//! directional albedo) with, for `face_scattering = "multiple"`, core's
//! separable energy compensation; [`SlabSpec::from_params`] for the physical
//! sheet of a `PaperParams` (one colour channel); totals for collimated light
//! at a node and for diffuse light, from either side; the BSDF between nodes.
//! Measured (tests/): reciprocity to 2e-14 in every order, `R + T = 1` to
//! 1e-10 for conservative sheets with `"multiple"` faces, totals of rough
//! sheets within 2e-3 of the simulator (tau 2 and 30, 0 to 75 degrees, both
//! face modes), 32 nodes within 6e-4 of 64.
//!
//! **What is missing for issue 13.** Faces of unequal index (the coated
//! sheet of docs/design.md 4.1: its smooth coating/base boundary under the
//! rough front, as `core::sheet` and the simulator have it); lobes narrower
//! than the grid (roughness below about 0.1, e.g. the glossy preset's
//! m_f = 0.04, needs more nodes or an analytic treatment of the lit face's
//! reflection); the analytic parts (surface reflection of the lit face,
//! unscattered transmission, exact single scattering) with the orders that
//! carry first scattering subtracted; interpolation of the matrices to
//! arbitrary directions (incidence off the nodes) and the BSDF's eval and
//! sample; RGB channels in one solve; the model registry and CLI; the speed
//! targets (a solve with two distinct rough faces takes 0.6 s at 32 nodes,
//! mostly the faces' projection and normalisation); the 2% accuracy of the
//! BSDF values themselves (only totals are checked against the simulator).

pub mod bsdf;
pub mod error;
pub mod interface;
pub mod layer;
pub mod phase;
pub mod quad;
pub mod slab;

pub use bsdf::{SlabBsdf, SlabOptions};
pub use error::SlabError;
pub use interface::{face_interface, smooth_boundary, Compensation, ProjectedFace, Projection};
pub use layer::{Layer, SymmetricLayer};
pub use quad::Grid;
pub use slab::{Coating, Discretisation, Face, Medium, Prepared, Side, SlabSpec, Solution};
