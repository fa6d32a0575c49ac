//! # paperbsdf-sim: the ground truth
//!
//! A Monte Carlo simulation of the physical system the Paper BSDF approximates
//! (docs/design.md section 6): the sheet of [`paperbsdf_core::sheet::Sheet`], the
//! one description that model and simulator share: a laterally infinite slab of
//! a homogeneous scattering medium (`sigma_a`, `sigma_s`, two-lobe
//! Henyey-Greenstein phase function) of index `eta_b` between two rough
//! dielectric faces, the front one over a thin coating of index `eta_f` when
//! `eta_f != eta_b`, with air on both sides. The faces scatter once among their
//! microfacets (Walter et al. 2007, `face_scattering = "single"`, as Mitsuba's
//! `roughdielectric`) or any number of times (the microsurface walk of Heitz et
//! al. 2016, `"multiple"`, the default), see [`faces`]. The walk is in depth
//! only; every event is sampled exactly from the same building blocks as the
//! model (`paperbsdf_core`'s `RoughDielectric`, microsurface walk and phase
//! functions), so model and truth describe the same physical system.
//!
//! It estimates, with standard errors from independent batches:
//! - the BSDF value `f(wi, wo)` (without cosine) for any pair of directions, by
//!   next-event estimation through the exit face with multiple importance
//!   sampling (unbiased, no angular binning; see [`walk`]);
//! - the total reflectance and transmittance for collimated or diffuse light.
//!
//! It is checked against independent programs (Mitsuba 3's volumetric path
//! tracer, iadpython's adding-doubling, van de Hulst's tables) in `tests/`.

#![warn(missing_docs)]

pub mod estimate;
pub mod faces;
pub mod lateral;
pub mod slab;
pub mod walk;

pub use estimate::{simulate_bsdf, simulate_totals, BsdfRun, Estimate, Incidence, SimConfig, SimError, Totals};
pub use lateral::{simulate_exit_profile, ExitProfile, LateralConfig};
pub use slab::{Medium, Side, Slab};
