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
//! Orders are independent and solved in parallel (rayon); dense LU by
//! nalgebra, its triangular solves blocked into matrix products (`linalg`).
//!
//! **What exists.** Gauss-Radau / split Gauss-Legendre grids; HG Fourier
//! coefficients with symmetric normalisation; the diamond starting layer and
//! doubling; adding of general (unequal-grid) layers; smooth Fresnel faces,
//! index-matched faces, and rough faces of either distribution (GGX,
//! Beckmann) projected from core's Walter et al. rough dielectric onto the
//! grids and Fourier orders ([`interface`]: a graded Gauss-Legendre rule in
//! azimuth, symmetric normalisation to core's directional albedo) with, for
//! `face_scattering = "multiple"`, the orders >= 2 of the simulator's
//! microsurface walk solved on the same grids ([`face_walk`]; its long
//! series at grazing incidence projected by FFT, [`azimuth_fft`]);
//! faces of unequal index, i.e. the coated sheet of docs/design.md 4.1
//! (`eta_f != eta_b`: the rough air/coating front over a coating of zero
//! thickness and the smooth coating/base boundary, [`slab`]), on a coating
//! grid and a medium grid that keep the boundary diagonal ([`quad`],
//! [`Grid::denser`]; [`interface::smooth_boundary`]);
//! [`SlabSpec::from_params`] for the physical sheet of a `PaperParams` (one
//! colour channel), [`SlabSpec::prepare`] for the part of a solve shared by
//! the channels; totals for collimated light at a node and for diffuse
//! light, from either side; the BSDF between nodes. **The model `slab`**
//! ([`bsdf::SlabBsdf`], in core's registry as `ModelKind::Slab`, built by
//! `paperbsdf_io`): the lit face's reflection analytic (core's face), a
//! rough coated front's single round trip through its coating and a
//! sheet's unscattered transmission through two rough faces (and a coated
//! front's boundary, since 2026-12-07) analytic ([`two_crossings`]: tables
//! of the exact integrals, since 2026-12-06), the
//! delta lobes of smooth sheets in closed form, the rest interpolated from
//! the Fourier tables; `eval`, `sample`, `pdf` (chi-square tested),
//! components (`single`, the light scattered once, since 2026-12-07: the
//! solution's slope in the albedo, [`Prepared::solve_first_order`]).
//!
//! Measured (tests/): reciprocity to 2e-14 in every order (and of the
//! interpolated BSDF), `R + T = 1` to 1e-10 for conservative sheets with
//! `"multiple"` faces (coated ones to 8e-10; the BSDF with its analytic
//! face: 1.6e-5 from normal to 85 degrees, tests/slab_bsdf.rs), totals of rough sheets within 2e-3 of the simulator (tau 2
//! and 30, 0 to 75 degrees, both face modes; coated sheets with `eta_f` 1.55
//! over `eta_b` 1.45 and the reverse, from either side, within 2.7e-3,
//! tests/coated.rs), index-matched sheets within 2e-4 of PythonicDISORT,
//! smooth faces within 0.5% of iadpython, 32 nodes within 6e-4 of 64; a
//! smooth coated sheet without scattering equals its closed form (Fresnel
//! factors with the coating's interreflections summed) to 4e-14; BSDF values
//! against the simulator: docs/accuracy_slab.md.
//!
//! **What is missing for issue 13.** Lobes narrower than the grid, whose
//! values move by up to 10.4% when the nodes or the orders are doubled
//! (examples/convergence.rs), were made analytic on 2026-12-06: a coated
//! front's round trip through its coating (glossy 3.3% -> 0.01%, devB
//! near the normal 10.4% -> 0.03%) and an uncoated sheet's unscattered
//! transmission through two rough faces (thin tissue 9.6% -> 1.5%, weak
//! scatter 4.5% -> 0.9%) ([`two_crossings`]); near the normal the odd
//! Fourier orders follow `sin theta` between the nodes (later that day,
//! [`bsdf`]'s module doc: thin tissue 5-15 degrees from the normal 1.48%
//! -> 0.50%), and since that evening every order within 45 degrees of it
//! follows `sin^m theta` ([`bsdf::SIN_LAW_BAND`]: a thin sheet's
//! scattered transmission on the far flank of its forward lobe, `mu_o =
//! mu_i` with the viewer on the light's side, thin tissue 1.10% -> 0.34%
//! with twice the nodes, weak scatter 0.56% -> 0.45%, docs/slab.md
//! "Convergence"). Still missing: convergence below 0.2% with twice the
//! nodes at the default 32 (with 64 nodes, against 128, every accuracy
//! case is within 0.2% but devB's grazing ridge, 0.28%, at about 4 times
//! the build time; with 80 against 160 every case within 0.12%; since
//! 2026-12-07 `--slab-nodes`, `slab_nodes` choose them outside Rust) on
//! the thin sheets (thin tissue 0.34%, weak scatter 0.45%, its
//! straight-through direction at 30 degrees) and at grazing angles (devB's and
//! luster's walk ridge at grazing angles 0.99% and 0.78%); the
//! walk's forward reflection at grazing incidence on a smooth face beyond
//! 85 degrees (summed to its own 256 orders since 2026-12-05,
//! [`interface`]: at 75 degrees within 0.001% of twice the orders, 4.6-6.2%
//! before; at 85 R -85 luster 1.2%, where the pairs beyond 82 degrees take
//! part of Fejer's weights); exact single scattering as an analytic term
//! (since 2026-12-07 the first-order term is solved exactly on the grid,
//! [`Prepared::solve_first_order`], and is the component `single`, but it
//! is interpolated from a table like the rest: an index-matched sheet's
//! `single` is within 0.27% of the closed form at the nodes away from
//! grazing and 1.4% at the first node, tests/first_order.rs); the flank of the walk's forward peak
//! at grazing angles off a Beckmann 0.15 face, interpolated linearly in
//! `mu_o` between 32 nodes (luster at 75 R -65: 0.34% from twice the
//! nodes; at the nodes themselves within 0.04%).
//! The projected faces' R/T split from
//! inside is core's at every node; from outside (1e-3 off) it does not
//! reach the BSDF: the table is rescaled to the transmittance the analytic
//! face's own albedo leaves ([`bsdf`]). Faces smoother than the grid
//! resolves (GGX or Beckmann well below 0.1) keep their energy and their
//! split since 2026-12-05 (tests/smooth_faces.rs: a thin sheet with GGX
//! 0.01 faces had reflected 0.205 instead of 0.244 at normal incidence, and
//! R + T reached 1.17 at 30 degrees with GGX 0.001), and GGX faces'
//! kernels are integrated across their edges (where the micro-normal turns
//! horizontal) since the same day ([`interface`], "The refraction edge";
//! [`face_walk`], "Edges": the very rough sheet moved by up to 1.07% with
//! twice the nodes, 0.07-0.22% now). Builds
//! take 0.71 to 0.92 s for the presets (the coated glossy sheet the
//! slowest; the dense solves' triangular substitutions are blocked,
//! `linalg`, which made up for the edges' 35 ms per face); on the slower
//! machine of 2026-12-06 1.00 s at most, the worst case the RGB thin sheet
//! with unequal faces and glossy (docs/slab.md "Speed": reciprocity halves the
//! faces' evaluations, [`interface`], [`face_walk`]). `eval` at grazing
//! angles near the mirror direction, where node pairs keep up to 256
//! orders (the walk's forward peak), takes 125-152 ns with AVX2 and FMA
//! (benches/slab.rs `eval_grazing`, 2026-12-05 evening: those pairs'
//! series are read from samples of their sums in azimuth, [`bsdf`];
//! 132-211 ns back to back before that, 183-309 ns in the
//! slower machine state of the runs before, 280-720 ns before the Fourier
//! sum's changes, 1.0-1.95 us before its shared cosines); matte, three
//! channels, is the slowest and may pass 200 ns on a slowed machine;
//! mid angles 49-108 ns, `sample` 255-281 ns (in that slower state). Near `eta_f = eta_b` from
//! below (the base denser) the discretisation moves with the boundary's
//! critical cosine, by `O(sqrt(eta_b - eta_f))` (8e-5 in the totals at a
//! difference of 1e-6; tests/coated.rs).

pub mod azimuth_fft;
pub mod bsdf;
pub mod error;
pub mod face_walk;
pub mod interface;
pub mod layer;
mod linalg;
pub mod phase;
pub mod quad;
pub mod slab;
pub mod two_crossings;

pub use bsdf::{face_albedo, SlabBsdf, SlabOptions};
pub use error::SlabError;
pub use interface::{face_interface, smooth_boundary, Compensation, ProjectedFace, Projection};
pub use layer::{Layer, SymmetricLayer};
pub use quad::Grid;
pub use slab::{Coating, Discretisation, Face, Medium, Prepared, Side, SlabSpec, Solution};
