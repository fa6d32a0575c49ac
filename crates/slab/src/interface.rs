//! Dielectric interfaces as layers: air (index 1, top side) over a medium of
//! relative index `eta` (bottom side).
//!
//! **Smooth (Fresnel) interface.** Mirror reflection and Snell refraction keep
//! the azimuth of the propagation direction, so the matrices are the same for
//! every Fourier order and diagonal on the grids of [`crate::quad`] (each
//! outside node refracts onto its Snell image inside):
//! - `R_top[k][k] = F(mu_k)`, the unpolarised Fresnel reflectance
//!   (`paperbsdf_core::fresnel`);
//! - `T_down[k'][k] = eta^2 (1 - F)`, `T_up[k][k'] = (1 - F) / eta^2`, where
//!   `k'` is the inside image of outside node `k`: **radiance scales by
//!   `eta^2` on entering the denser medium and by `1 / eta^2` on leaving it**
//!   (the `n^2` law of radiance, the same radiance-transport convention as
//!   `paperbsdf_core::dielectric`); so the flux `sum w mu L` is conserved,
//!   since `w' mu' = w mu / eta^2` on the image nodes;
//! - `R_bot = diag(F)` on the image nodes and `1` on the nodes of total
//!   internal reflection (`mu < mu_c`).
//!
//! With the reciprocity weights `w mu / eta^2` these matrices satisfy the
//! reciprocity relations of [`crate::layer`] exactly.
//!
//! **Smooth boundary between two media** ([`smooth_boundary`]): the same with
//! the less dense medium in the place of air and the relative index
//! `r = n_lower / n_upper` (above or below 1), e.g. a coated sheet's
//! coating/base boundary `eta_b / eta_f` (`paperbsdf_core::sheet`): pairs of
//! nodes that are each other's Snell images (grids of [`Grid::denser`]),
//! `F` of the pair, `T = r^2 (1 - F)` downward and `(1 - F) / r^2` upward,
//! total reflection of the denser side's nodes beyond the critical angle.
//! The reciprocity weights `w mu / n^2` of the two grids (absolute indices)
//! make it reciprocal exactly, since `w' mu' = w mu / r^2` on paired nodes.
//!
//! **Rough interface** (`face_scattering = "single"`): the BSDF is core's
//! Walter et al. (EGSR 2007) rough dielectric,
//! [`RoughDielectric::eval_mode`] in [`TransportMode::Radiance`], whose
//! refraction carries the same `n^2` radiance factor (Walter's eq. 21 with
//! `eta_o^2`), so its transmission into the medium integrates to the flux
//! transmittance and generalised reciprocity reads
//! `f(wi, wo) / n_o^2 = f(wo, wi) / n_i^2`. Each block is projected as
//! [`crate::layer`] defines a matrix entry,
//! `K_m[o][j] = w_j mu_j integral_0^(2 pi) f(mu_j -> mu_o, phi) cos(m phi) dphi`,
//! with `phi` the azimuth difference of the propagation directions (light
//! propagating along `(sin_j, 0, -+mu_j)`, i.e. `wi = (-sin_j, 0, +-mu_j)`
//! toward the light, leaving along `wo = (sin_o cos phi, sin_o sin phi, +-mu_o)`).
//! `f` is even in `phi` (the mirror `y -> -y` of both directions), so only the
//! cosine series exists and the integral is folded onto `[0, pi]`.
//! **Azimuth rule.** Every lobe of a rough face peaks at `phi = 0` (the
//! mirror and the refracted direction keep the azimuth), and between two
//! grazing directions its width in `phi` shrinks with them, to about
//! `m (mu_i + mu_o)` (e.g. 4e-4 for m = 0.15 at the smallest Radau node, where
//! a uniform rule of 256 points overestimated the grazing reflectance by
//! 2e-2). The rule is therefore composite Gauss-Legendre with `q`
//! ([`crate::Discretisation::azimuth_points`], default
//! [`DEFAULT_AZIMUTH_POINTS`] = 8) points per panel on `[0, pi]`:
//! `P = max(16, orders)` uniform panels ([`MIN_AZIMUTH_PANELS`]), the first
//! of which is split geometrically toward 0 into panels
//! `[0, d], [d, 2d], [2d, 4d], ...` with `d = (pi / P) 2^-14`
//! ([`AZIMUTH_GRADING_LEVELS`]): `q (P + 14)` points, 496 with the default
//! 48 orders (240 with 16).
//! Gauss-Legendre integrates the smooth parts to high order, and the panel
//! edges bound the error of the kink where the refraction lobe ends; doubling
//! `q` changes the totals of the sheets in the tests by less than 1e-6
//! (tests/rough_convergence.rs).
//!
//! **Quadrature in `mu` and normalisation.** The nodes in `mu` are the
//! grids' own, and a lobe is sampled at them: the refraction lobe ends with a
//! kink (where a microfacet turns its back to one of the directions) that
//! falls anywhere between nodes, and a lobe narrower than the node spacing
//! (roughness m = 0.15 at normal incidence) is under-resolved. With 32
//! outside nodes the raw order-0 albedos are off by up to 3e-2 (GGX m = 0.15)
//! against core's quadrature of the same face
//! (`paperbsdf_core::boundary::directional_albedo_n`, [`ALBEDO_POINTS`]
//! points per axis). As the phase function's ([`crate::phase`]), the
//! matrices are therefore rescaled symmetrically, `K[o][j] s_o s_j` in every
//! order and block (outside and inside nodes have their own factors; a
//! symmetric Sinkhorn iteration), so that every outside node's `R + T` and
//! every inside node's `T` is core's exactly, and the reflection from
//! inside, with factors of its own, so that every inside node's `R` is
//! core's too: the symmetric scalings keep reciprocity, and the factors
//! ([`ProjectedFace::scale`]) show how far the raw projection was. From
//! outside the split between `R` and `T` keeps an error (tests/rough_face.rs:
//! up to 1.1e-3 at 32 nodes), which the `slab` model does not use: it
//! replaces the lit face's reflection by the analytic lobe and what crosses
//! the face is rescaled to the transmittance that lobe leaves. Until
//! 2026-12-05 the split from inside kept an error too (5e-3 for GGX 0.5,
//! and for faces smoother than the nodes most of their reflection:
//! `normalise_face`). For Beckmann, core's
//! albedo uses the exact Smith `G1` of the incident direction where
//! `eval_mode` uses Walter's rational approximation (below 0.35% apart,
//! `paperbsdf_core::microsurface`); the normalisation follows the latter
//! ([`walter_albedo`], since 2026-12-07), the face the simulator samples.
//!
//! **The refraction edge.** Light from outside at `mu_out` refracts into the
//! medium only at directions with `eta mu_in > mu_out`: beyond, the
//! micro-normal that would refract it points below the horizon. Along that
//! line Walter's transmission does not fade out, it jumps to zero from `D`
//! of a horizontal micro-normal (for GGX `m^2 / pi`, a sizable share of
//! the lobe of a rough face; Beckmann's `D` vanishes there). The line lies
//! at `mu_in <= 1 / eta`: in the cone of total internal reflection for
//! `eta > sqrt 2` (`1 / eta < mu_c`), partly beyond it below.
//! Sampled at the nodes, a jump leaves a quadrature error of the order of
//! the node spacing times the jump, of either sign depending on where the
//! edge falls between two nodes: the transmission from outside was off by
//! up to 1.9e-2 (GGX m = 0.9) and 1.2e-2 (m = 0.5), alternating from node
//! to node, and the normalisation above, made to absorb it, had factors
//! alternating by up to 3.8% between neighbouring nodes, which moved the
//! sheets' BSDF at grazing angles by up to 1.1% when the nodes were doubled
//! (examples/convergence.rs, the very rough sheet, until 2026-12-05). The
//! node pairs whose cells the line crosses ([`refraction_edge_pairs`]; a
//! node's cell in `mu` has its flux weight `w mu` as measure) therefore
//! hold the cells' averages of Walter's transmission, integrated on the
//! part beyond the edge ([`EDGE_POINTS`] Gauss-Legendre points per axis;
//! in both transmission blocks, one being the other over `eta^2` by
//! reciprocity): the raw transmission is then within 1.3e-3 of core's at
//! every node (GGX m = 0.9; 5.3e-4 at 0.5; tests/rough_face.rs), and
//! neighbouring factors within 2e-3. Only GGX faces have the edge; it costs
//! about 25 ms per face (44 pairs with the default 32 nodes; timed inside
//! the build while writing this).
//!
//! **Narrow transmission lobes** (2026-12-07). A face's transmission from
//! outside node `b` peaks around `b`'s Snell image inside; a micro-normal
//! tilted by `delta` turns the refracted direction at normal incidence by
//! `(1 - 1/eta) delta`, so for faces close to index-matched or smooth the
//! lobe is narrower than the nodes' spacing (Beckmann eta 1.12, m = 0.1:
//! 1.0 degree wide at half maximum, against cells of about 2.8 degrees).
//! Sampled at the nodes it was a few node values that the normalisation
//! scaled to the right albedo but not to the right place: a thin sheet
//! with such faces reflected 4.5e-3 less than the simulator at 75.3
//! degrees (7.9 sigma), 4.9e-3 at 85.5, and the totals of five faces from
//! eta 1.05 to 1.5 at four angles were 1.68e-3 from the simulator (RMS,
//! 40 totals, sigma 4e-4 to 1.1e-3; examples/near_index_totals.rs). The
//! pairs within [`SNELL_IMAGE_CELLS`] nodes of each image
//! ([`snell_image_pairs`]) now take a share ([`snell_image_share`]) of
//! the cells' averages as the refraction edge's pairs do
//! ([`SNELL_IMAGE_POINTS`] points per axis): all of them where the lobe at
//! normal incidence is no wider than a nominal cell `pi / 2n`, none from
//! twice that on (the nodes resolve the lobe there, and averages over the
//! cells would blur it: with every face averaged, thin tissue's
//! transmission near the normal moved by 0.63% with twice the nodes
//! instead of 0.39%, and GGX m = 0.9's raw transmission from outside was
//! 3.1e-3 from core's, above tests/rough_face.rs's 3e-3 and the 1.3e-3
//! above), linear between so that the face stays
//! continuous in `eta` and `m`. The same totals are now 7.5e-4 from the
//! simulator (RMS; the largest 2.3e-3, 3.8 sigma, multiple-scattering
//! faces at 85.5 degrees), the simulator's noise. It also lets the
//! normalisation converge for faces it could not scale before (GGX eta
//! 1.05 with m 0.5 to 0.8, Beckmann 1.05 with 0.2 to 0.8, GGX 1.08 with
//! 0.05, Beckmann 1.08 with 0.1 to 0.3). About
//! 40-110 ms more per build (glossy 0.85-0.86 -> 0.93-0.96 s, `examples/slab_build`).

//! **Multiple scattering on the microsurface** (`face_scattering =
//! "multiple"`): the face the simulator has, the random walk on the Smith
//! microsurface (Heitz et al. 2016; `paperbsdf_core::microsurface`), whose
//! first order is Walter's face above and whose orders >= 2
//! [`crate::face_walk`] solves on the same grids and orders (a Markov chain
//! in direction, Nystrom on the nodes), scaled symmetrically so that each
//! node's albedo is exactly what Walter's projected face loses,
//! `L(mu) = 1 - R(mu) - T(mu)` (so each direction's `R + T` is 1 from both
//! sides), and added to every order with Fejer's weights `1 - m / M`
//! (`M` orders): at grazing angles the walk's light is narrower in azimuth
//! than 32 orders resolve, and the truncated series rang below zero, where
//! the model's `eval` clamps it (3e-3 of energy added at 85 degrees, tests/slab_bsdf.rs);
//! Fejer's sum of a non-negative series is non-negative and keeps order 0
//! (Lanczos' sigma factors, tried, left 7e-5). The price is a broadened
//! forward peak at grazing incidence on smooth faces (luster's Beckmann
//! 0.15 front at 75 degrees, 8% under the simulator at `theta_o = -80` with
//! 32 orders; the model's default is therefore 48, `crate::SlabOptions`).
//! That peak is narrower in azimuth than 48 orders resolve, so it was not
//! converged in the orders: doubling them moved the in-plane value at
//! `theta_o = -80` by 3.1% (crates/slab/examples/convergence.rs), hence the
//! walk's own orders below. Jackson's
//! kernel (non-negative too, RMS width `pi / M` where Fejer's tails give 14
//! degrees at 48 orders) was tried and not kept: better for lobes broader
//! than `pi / M`, worse for this one, as its main lobe is wider than
//! Fejer's.
//! Since 2026-12-05 the walk's reflection from outside, which reaches the
//! sheet's reflection unchanged by the layers below, is also returned to
//! [`Projection::walk_orders`] orders ([`ProjectedFace::walk_r_top`]): the
//! full chain's orders below `M`, above them a chain restricted to the
//! outside states at the grazing nodes ([`WALK_GRAZING_MU`],
//! [`crate::face_walk::outside_reflection`]; luster's orders 48 to 96 from
//! it are within 8e-6 of the full chain's). The `slab` model sums it to
//! 256 orders with [`walk_window`] flat to 128, with part of Fejer's
//! weights to 256 at the node pairs where the flat window rings below
//! zero (the least share that keeps it within tolerance; Fejer's whole
//! until 2026-12-06, a step along the mirror ridge) (faces
//! smoother than [`WALK_REFERENCE_ALPHA`] to more, [`walk_orders_for`])
//! (crates/slab/src/bsdf.rs). Luster's peak at 75 degrees, 4.6-6.2% under
//! the solve with twice the orders before, is now within 0.001% of it
//! (tests/walk_orders.rs). Windows between the two (flat to 16, 32 or 48
//! of 128 orders, then linear) were tried at the pairs that ring: every one
//! rang more than Fejer's by over 1e-5 of the pair's mean (a trial while
//! writing this, not kept as a command).
//! The walk integrates with half the azimuth points per panel of Walter's
//! projection (its kernels are integrated again over the intermediate
//! directions; luster at 75 degrees: the same RMS error to 1e-4, build 15%
//! faster).
//!
//! This replaces the Paper BSDF's separable compensation lobes
//! (`paperbsdf_core::paper::face` step 2: reflection
//! `(1 - k_o) L_o(mu_i) L_o(mu_o) / (pi Lbar_o)` and the like), whose shape
//! differs from the walk's at grazing angles (3-7% RMS in the sheets'
//! BSDF against the simulator, docs/accuracy_slab_recheck.md). The walk's
//! transmitted shares `k_o`, `k_i` ([`Compensation`]) agree with those of
//! core's Monte Carlo tables of the same walk to 0.5% (tests/rough_face.rs).
//! A face too smooth for the grid (GGX 0.04 on 32 nodes), whose discretised
//! walk misses some nodes altogether and cannot be scaled, gets the
//! separable lobes instead (`compensate`; it loses almost nothing).

use crate::azimuth_fft::RuleProjection;
use crate::error::SlabError;
use crate::layer::Layer;
use crate::quad::Grid;
use nalgebra::DMatrix;
use paperbsdf_core::boundary::{dir_at_mu, directional_albedo_rule};
use paperbsdf_core::dielectric::Interface;
use paperbsdf_core::fresnel::{cos_transmitted, fresnel_dielectric};
use paperbsdf_core::microsurface_tables::compensation_shares;
use paperbsdf_core::quadrature::gauss_legendre_01;
use paperbsdf_core::{DVec3, Distribution, FaceScattering, RoughDielectric, TransportMode};
use rayon::prelude::*;
use std::f64::consts::PI;

/// The smooth interface from the `outside` grid (air) to the `inside` grid
/// made from it by [`Grid::inside`] (module doc). Index-matched (`eta = 1`):
/// the identity. The pairing of the nodes is not checked here
/// ([`smooth_boundary`] checks it).
pub fn smooth_interface(outside: &Grid, inside: &Grid) -> Layer {
    if inside.eta == 1.0 {
        return Layer::identity(outside.len());
    }
    paired_boundary(outside, inside, true)
}

/// The smooth boundary between the medium of grid `upper` (top side) and
/// the medium of grid `lower` (bottom side), of relative index
/// `r = lower.eta / upper.eta` (either way: the coating/base boundary of a
/// coated sheet is `eta_b / eta_f`, below or above 1). As
/// [`smooth_interface`] (module doc) with the less dense medium in the place
/// of air: Fresnel's `F` of the pair, transmission `r^2 (1 - F)` downward and
/// `(1 - F) / r^2` upward (radiance scales with the square of the index), the
/// denser side's nodes without an image reflected totally. The denser grid
/// must pair every node of the other with its Snell image, as
/// [`Grid::denser`] makes it: its last nodes are those images, checked to
/// `1e-12`; otherwise [`SlabError::Unsupported`] (a smooth boundary is a
/// diagonal map only on such grids). Equal indices: the identity (the grids
/// must be equal).
pub fn smooth_boundary(upper: &Grid, lower: &Grid) -> Result<Layer, SlabError> {
    const NOT_PAIRED: &str = "a smooth boundary between grids that do not pair every node of the less dense \
         medium with its Snell image in the denser one (make the denser grid with Grid::denser)";
    if upper.eta == lower.eta {
        return if upper == lower {
            Ok(Layer::identity(upper.len()))
        } else {
            Err(SlabError::Unsupported(NOT_PAIRED))
        };
    }
    let less_on_top = lower.eta > upper.eta;
    let (less, dense) = if less_on_top { (upper, lower) } else { (lower, upper) };
    if dense.len() < less.len() {
        return Err(SlabError::Unsupported(NOT_PAIRED));
    }
    let r = dense.eta / less.eta;
    let off = dense.len() - less.len();
    for k in 0..less.len() {
        let image = cos_transmitted(less.mu[k], r).map_or(f64::NAN, f64::abs);
        // (NaN, a node of total reflection, fails too)
        if (image - dense.mu[off + k]).abs().is_nan() || (image - dense.mu[off + k]).abs() > 1e-12 {
            return Err(SlabError::Unsupported(NOT_PAIRED));
        }
    }
    Ok(paired_boundary(upper, lower, less_on_top))
}

/// The smooth boundary's layer on grids paired as [`Grid::denser`] pairs
/// them (unchecked), the less dense medium on top if `less_on_top`.
fn paired_boundary(upper: &Grid, lower: &Grid, less_on_top: bool) -> Layer {
    let (less, dense) = if less_on_top { (upper, lower) } else { (lower, upper) };
    let (nl, nd) = (less.len(), dense.len());
    let r = dense.eta / less.eta;
    let r2 = r * r;
    let off = nd - nl;
    // The blocks seen from the less dense side (l) and the denser side (d).
    let mut r_l = DMatrix::zeros(nl, nl);
    let mut r_d = DMatrix::identity(nd, nd);
    let mut t_ld = DMatrix::zeros(nd, nl);
    let mut t_dl = DMatrix::zeros(nl, nd);
    for k in 0..nl {
        let f = fresnel_dielectric(less.mu[k], r);
        r_l[(k, k)] = f;
        t_ld[(off + k, k)] = r2 * (1.0 - f);
        t_dl[(k, off + k)] = (1.0 - f) / r2;
        r_d[(off + k, off + k)] = f;
    }
    if less_on_top {
        Layer {
            r_top: r_l,
            t_down: t_ld,
            r_bot: r_d,
            t_up: t_dl,
        }
    } else {
        Layer {
            r_top: r_d,
            t_down: t_dl,
            r_bot: r_l,
            t_up: t_ld,
        }
    }
}

/// Default Gauss-Legendre points per panel of the azimuth rule
/// ([`crate::Discretisation::azimuth_points`]; module doc).
pub const DEFAULT_AZIMUTH_POINTS: usize = 8;

/// Levels of geometric refinement of the azimuth rule's first panel toward
/// `phi = 0` (module doc): its smallest panel is `2^-14` of a uniform one.
pub const AZIMUTH_GRADING_LEVELS: i32 = 14;

/// Smallest number of uniform panels of the azimuth rule on `[0, pi]`.
pub const MIN_AZIMUTH_PANELS: usize = 16;

/// The multiply scattered light of a `face_scattering = "multiple"` face
/// as projected on the grids (module doc): the transmitted shares of the
/// energy Walter's face loses and that energy at every node.
#[derive(Clone, Debug, PartialEq)]
pub struct Compensation {
    /// Whether the walk ([`crate::face_walk`]) carries it (`false`: the
    /// separable lobes of a face too smooth for the grid).
    pub walk: bool,
    /// `k_o`: transmitted share of the energy lost for light from outside
    /// (diffuse light, flux-weighted): the walk's, or for separable lobes
    /// core's walk tables' (`paperbsdf_core::microsurface_tables::lost_energy`).
    pub k_out: f64,
    /// `k_i`: transmitted share for light from inside (the walk's, or for
    /// separable lobes from reciprocity `k_o Lbar_o = eta^2 k_i Lbar_i`).
    pub k_in: f64,
    /// `[Lbar_o, Lbar_i]` of the part carried by separable lobes: all of it
    /// without the walk, the nodes it does not resolve with it
    /// ([`crate::face_walk::WalkFace::unresolved`]).
    pub separable: [f64; 2],
    /// `L_o` at the outside nodes: `1 - R - T` of Walter's projected face.
    pub lost_out: Vec<f64>,
    /// `L_i` at the inside nodes.
    pub lost_in: Vec<f64>,
    /// `Lbar_o = 2 sum_j w_j mu_j L_o(mu_j)` on the outside grid.
    pub lbar_out: f64,
    /// `Lbar_i`, the same on the inside grid.
    pub lbar_in: f64,
    /// The most negative `1 - R - T` that was clipped to 0 (0 if none): where
    /// the projected Walter face reflects and transmits more than it receives.
    pub clipped: f64,
}

/// A face projected on the grids: its layer per Fourier order and, for an
/// energy-conserving rough face, its compensation.
#[derive(Clone, Debug)]
pub struct ProjectedFace {
    /// The face's layer for orders `0..orders` (air on top, the medium below).
    pub orders: Vec<Layer>,
    /// What the multiple scattering of a `"multiple"` rough face carries,
    /// `None` otherwise.
    pub compensation: Option<Compensation>,
    /// The face's first reflection from outside per order: `r_top` of
    /// Walter's face alone (without the walk's orders >= 2; `r_top` itself
    /// for other faces), what the `slab` model keeps analytic.
    pub first_r_top: Vec<DMatrix<f64>>,
    /// The normalisation's factors `s` (outside nodes, then inside nodes;
    /// module doc), all 1 without normalisation: how far the raw projection
    /// was from core's albedo.
    pub scale: Vec<f64>,
    /// The walk's reflection from outside (orders >= 2 of the microsurface
    /// walk, normalised, without a window) per order `0..walk_orders`
    /// ([`Projection::walk_orders`]; module doc): `orders` of it are in
    /// [`ProjectedFace::orders`] with Fejer's weights, the caller may sum it
    /// to more (`r_top` enters the sheet's reflection on the face's side
    /// unchanged by the adding). Empty when there is none.
    pub walk_r_top: Vec<DMatrix<f64>>,
    /// Walter's transmission per order, `(t_down, t_up)` (normalised,
    /// without the walk's orders >= 2), kept where the walk was added to
    /// [`ProjectedFace::orders`]; empty where those are Walter's face's own
    /// ([`ProjectedFace::first_t`]).
    walk_free_t: Vec<(DMatrix<f64>, DMatrix<f64>)>,
}

impl ProjectedFace {
    /// The face's first transmission in order `m`, `(t_down, t_up)`: Walter's
    /// face alone (normalised, without the walk's orders >= 2; the layer's
    /// own for other faces). What a coated front's single round trip through
    /// its coating, and a sheet's unscattered transmission through two rough
    /// faces, hold on the grid ([`crate::two_crossings`]), which the `slab`
    /// model keeps analytic.
    pub fn first_t(&self, m: usize) -> (&DMatrix<f64>, &DMatrix<f64>) {
        match self.walk_free_t.get(m) {
            Some((down, up)) => (down, up),
            None => (&self.orders[m].t_down, &self.orders[m].t_up),
        }
    }
}

/// Checks the azimuth rule's points per panel: 2 to 64.
pub fn check_azimuth_points(azimuth_points: usize) -> Result<(), SlabError> {
    if !(2..=64).contains(&azimuth_points) {
        return Err(SlabError::Discretisation {
            name: "azimuth_points",
            value: azimuth_points as f64,
            range: "[2, 64] Gauss-Legendre points per panel",
        });
    }
    Ok(())
}

/// The azimuth rule on `[0, pi]` for `orders` Fourier orders with `q`
/// points per panel (module doc): `(phi_k, weight_k)`, the weights already
/// doubled for the fold of the circle onto `[0, pi]`.
pub fn azimuth_rule(orders: usize, q: usize) -> Vec<(f64, f64)> {
    let panels = MIN_AZIMUTH_PANELS.max(orders);
    let width = PI / panels as f64;
    let mut edges = vec![0.0];
    for k in (0..=AZIMUTH_GRADING_LEVELS).rev() {
        edges.push(width * 2f64.powi(-k));
    }
    for p in 2..=panels {
        edges.push(width * p as f64);
    }
    let (x, w) = gauss_legendre_01(q);
    let mut rule = Vec::with_capacity(q * (edges.len() - 1));
    for e in edges.windows(2) {
        let len = e[1] - e[0];
        for (xi, wi) in x.iter().zip(&w) {
            rule.push((e[0] + len * xi, 2.0 * len * wi));
        }
    }
    rule
}

/// Points per axis of core's visible-normal quadrature
/// (`paperbsdf_core::boundary::directional_albedo_n`) that gives the albedo
/// targets of the normalisation (module doc). Core's rule converges slowly
/// (kinks of the masking and of total internal reflection on the microfacets):
/// 128 points are within 4e-4 of its default 256 for m <= 0.5 (1.2e-3 at
/// m = 1), at a quarter of the cost.
pub const ALBEDO_POINTS: usize = 128;

/// Iterations of the symmetric Sinkhorn scaling after which the
/// normalisation goes on with Newton's method (`newton_scaling`): it gains
/// about a factor 60 per 100 iterations on a face whose raw albedo is off
/// by 100% (m = 0.1 on 20 nodes), and the faces of the presets, devA and
/// devB converge in 585 to 847 (a probe printing the count while writing
/// this, 2026-12-07, not kept), so for them nothing changes. Faces close
/// to index-matched crawl (GGX `eta` 1.05, `m` 0.3 took 15,647 iterations;
/// `m` 1.3 was 2.2e-6 from its targets after 20,000, the limit until
/// 2026-12-07, and refused): Newton's method takes them to rounding in a
/// few steps.
pub const MAX_NORMALISATION_ITERATIONS: usize = 2_000;

/// The normalisation's target: every node's albedo within this relative
/// error of core's. Resolved faces reach it in tens of iterations.
pub const NORMALISATION_TOLERANCE: f64 = 1e-12;

/// What the normalisation accepts when it has not reached
/// [`NORMALISATION_TOLERANCE`] with the Sinkhorn iteration and Newton's
/// method after it: before Newton's method (2026-12-07), faces close to
/// index-matched, whose transmission lobe is narrower than the nodes,
/// converged slowly (every node's albedo within 2.7e-10 of its target for
/// Beckmann eta 1.12, m = 0.1, 5e-10 for GGX eta 1.05, m = 0.3, after
/// 20,000 iterations; a probe printing the iteration's error while writing
/// this, not kept), and were refused until then for missing 1e-12 only;
/// with it the six refused faces probed then (GGX eta 1.05 with m 0.05 and
/// 1.3, 1.03 and 1.01 with 0.3, 1.08 with 0.02, Beckmann 1.1 with 0.05)
/// reach 1e-14.
/// An albedo error of 1e-9 is below every energy check of the
/// solver (R + T = 1 within 1e-9 of the quadrature, 1e-4 of the issue);
/// the totals of those sheets agree with the simulator
/// (tests/simulator.rs, `near_index_matched_faces_agree_with_the_simulator`).
pub const NORMALISATION_SLOW_TOLERANCE: f64 = 1e-9;

/// How a rough face is projected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Projection {
    /// Fourier orders `0..orders`, at least 1.
    pub orders: usize,
    /// Gauss-Legendre points per panel of the azimuth rule (module doc;
    /// [`check_azimuth_points`]).
    pub azimuth_points: usize,
    /// Whether Walter's matrices are scaled symmetrically to core's
    /// directional albedo at every node (module doc); `false` leaves the raw
    /// point-sampled projection (for measuring its error).
    pub normalise: bool,
    /// Fourier orders of the walk's reflection from outside, which the
    /// `slab` model keeps to more orders than the rest of the sheet (module
    /// doc, "Multiple scattering on the microsurface"); at most `orders`
    /// (or 0) for none.
    pub walk_orders: usize,
}

/// The face `bd` (air above, medium of index `bd.eta` below) on the grids
/// `outside` (air) and `inside` (index `bd.eta`): index-matched faces are the
/// identity (the grids must be equal), smooth ones [`smooth_boundary`] in
/// every order (`inside` must pair the outside nodes with their Snell images
/// as [`Grid::inside`] and [`Grid::denser`] make it, else
/// [`SlabError::Unsupported`]); rough ones, on any grids of those indices, the projection of `RoughDielectric::eval_mode`
/// (radiance transport) as `proj` says, plus the compensation when
/// `scattering` is [`FaceScattering::Multiple`] (module doc).
pub fn face_interface(
    bd: &RoughDielectric,
    scattering: FaceScattering,
    outside: &Grid,
    inside: &Grid,
    proj: &Projection,
) -> Result<ProjectedFace, SlabError> {
    let Projection {
        orders,
        azimuth_points,
        normalise,
        walk_orders,
    } = *proj;
    if orders == 0 {
        return Err(SlabError::Discretisation {
            name: "orders",
            value: 0.0,
            range: "[1, inf)",
        });
    }
    if outside.eta != 1.0 || inside.eta != bd.eta {
        return Err(SlabError::Unsupported(
            "a face projected on grids whose indices are not 1 outside and the face's index inside",
        ));
    }
    let single = |l: Layer| ProjectedFace {
        first_r_top: vec![l.r_top.clone(); orders],
        walk_free_t: Vec::new(),
        orders: vec![l; orders],
        compensation: None,
        scale: vec![1.0; outside.len() + inside.len()],
        walk_r_top: Vec::new(),
    };
    match bd.interface {
        Interface::IndexMatched => {
            if outside != inside {
                return Err(SlabError::Unsupported(
                    "an index-matched face between two different grids (they must be the same grid)",
                ));
            }
            Ok(single(Layer::identity(outside.len())))
        }
        Interface::Smooth => Ok(single(smooth_boundary(outside, inside)?)),
        Interface::Rough(_) => {
            check_azimuth_points(azimuth_points)?;
            let mut orders_l = walter_projection(bd, outside, inside, orders, azimuth_points);
            let scale = if normalise {
                normalise_face(bd, outside, inside, &mut orders_l)?
            } else {
                vec![1.0; outside.len() + inside.len()]
            };
            let first_r_top = orders_l.iter().map(|l| l.r_top.clone()).collect();
            let (compensation, walk_r_top, walk_free_t) = match scattering {
                FaceScattering::Single => (None, Vec::new(), Vec::new()),
                FaceScattering::Multiple => {
                    let walk_free_t = orders_l.iter().map(|l| (l.t_down.clone(), l.t_up.clone())).collect();
                    let (c, r) = add_walk(bd, outside, inside, &mut orders_l, azimuth_points, walk_orders)?;
                    (Some(c), r, walk_free_t)
                }
            };
            Ok(ProjectedFace {
                orders: orders_l,
                compensation,
                first_r_top,
                scale,
                walk_r_top,
                walk_free_t,
            })
        }
    }
}

/// The four blocks of Walter's face for every order (module doc's rule).
///
/// The light from inside (`t_up`) is not evaluated: by reciprocity
/// (Walter's transmission in radiance transport, `f(wi, wo) / eta_o^2 =
/// f(wo, wi) / eta_i^2`) it is `t_down`'s at the same pairs of directions
/// over `eta^2`, `W_in T_down = (W_out T_up)^T` with `W = w mu / eta^2` as
/// [`transmission_cell_averages`] has it (a third of the evaluations; the unit
/// test `light_from_inside_is_reciprocal` evaluates it directly).
fn walter_projection(bd: &RoughDielectric, outside: &Grid, inside: &Grid, orders: usize, n_phi: usize) -> Vec<Layer> {
    let rule = RuleProjection::new(orders, n_phi, 0);
    let r_top = walter_block(&rule, bd, outside, true, outside, true);
    let mut t_down = walter_block(&rule, bd, outside, true, inside, false);
    let r_bot = walter_block(&rule, bd, inside, false, inside, false);
    let e2 = bd.eta * bd.eta;
    let mut t_up: Vec<DMatrix<f64>> = t_down
        .iter()
        .map(|td| {
            DMatrix::from_fn(outside.len(), inside.len(), |o, j| {
                inside.w[j] * inside.mu[j] * td[(j, o)] / (outside.w[o] * outside.mu[o] * e2)
            })
        })
        .collect();
    transmission_cell_averages(bd, outside, inside, &rule, &mut t_down, &mut t_up);
    r_top
        .into_iter()
        .zip(t_down)
        .zip(r_bot.into_iter().zip(t_up))
        .map(|((r_top, t_down), (r_bot, t_up))| Layer {
            r_top,
            t_down,
            r_bot,
            t_up,
        })
        .collect()
}

/// One block of Walter's face per order on the azimuth rule `rule` (its
/// orders from 0; module doc's rule): from the nodes of `from` (above the
/// face if `from_top`) to those of `to` (going up if `to_up`), `w_j mu_j`
/// times the face's BSDF's Fourier coefficients.
///
/// A reflection block (`from` and `to` the same grid on the same side) is
/// reciprocal: `f(wi_j, wo_o(phi)) = f(wi_o, wo_j(phi))` (Walter's
/// reflection is symmetric in its two directions, and the face isotropic),
/// so only `j >= o` is evaluated and the rest mirrored (half the cost).
fn walter_block(
    rule: &RuleProjection,
    bd: &RoughDielectric,
    from: &Grid,
    from_top: bool,
    to: &Grid,
    to_up: bool,
) -> Vec<DMatrix<f64>> {
    let (nf, nt) = (from.len(), to.len());
    let mirror = from_top == to_up;
    // The masking of each node's direction, the same at every azimuth
    // (`RoughDielectric::eval_mode_masked`): computed again at each of
    // them it took about 10% of glossy's build on one thread (1.73 s
    // against 1.55 s, examples/slab_build with RAYON_NUM_THREADS=1).
    let g1 = |g: &Grid| -> Vec<f64> { g.mu.iter().map(|&mu| bd.g1_cos(mu)).collect() };
    let (g1_from, g1_to) = (g1(from), g1(to));
    let rows: Vec<DMatrix<f64>> = (0..nt)
        .into_par_iter()
        .map(|o| {
            let mu_o = to.mu[o];
            let s_o = (1.0 - mu_o * mu_o).max(0.0).sqrt();
            let z_o = if to_up { mu_o } else { -mu_o };
            let vals = DMatrix::from_fn(nf, rule.phis().len(), |j, k| {
                if mirror && j < o {
                    return 0.0;
                }
                let mu_j = from.mu[j];
                let s_j = (1.0 - mu_j * mu_j).max(0.0).sqrt();
                // toward the light: minus the propagation direction (s_j, 0, -+mu_j)
                let wi = DVec3::new(-s_j, 0.0, if from_top { mu_j } else { -mu_j });
                let (c, s) = rule.phis()[k];
                let wo = DVec3::new(s_o * c, s_o * s, z_o);
                bd.eval_mode_masked(wi, wo, TransportMode::Radiance, g1_from[j], g1_to[o])
            });
            rule.project(&vals)
        })
        .collect();
    (0..rule.coefficients())
        .map(|m| {
            DMatrix::from_fn(nt, nf, |o, j| {
                let f = if mirror && j < o {
                    rows[j][(o, m)]
                } else {
                    rows[o][(j, m)]
                };
                from.w[j] * from.mu[j] * f
            })
        })
        .collect()
}

/// Gauss-Legendre points per axis of the cell integrals across the
/// refraction edge (module doc): the integrand is smooth on the part of
/// the cell beyond the edge, and 4 points give the raw albedos of
/// tests/rough_face.rs to the 4 digits that 6 give.
pub const EDGE_POINTS: usize = 4;

/// Nodes on either side of an outside node's Snell image inside whose
/// pairs with it hold cell averages of the transmission (module doc,
/// "Narrow transmission lobes"): 3 took the totals of thin sheets with
/// faces close to index-matched to the simulator's noise (RMS 7.6e-4), 1
/// left 9.6e-4, 6 did no better (8.3e-4); variants of
/// examples/near_index_totals.rs with every face averaged, run while
/// writing this, not kept.
pub const SNELL_IMAGE_CELLS: usize = 3;

/// Gauss-Legendre points per axis of the cell averages at the Snell
/// image's pairs ([`SNELL_IMAGE_CELLS`]): 3 gave the totals that 4, 6 and
/// 10 give (RMS difference from the simulator 7.6e-4 for all four, 8.6e-4
/// with 2; the variants of [`SNELL_IMAGE_CELLS`]'s doc), at 9 evaluations
/// per pair and azimuth instead of 16.
pub const SNELL_IMAGE_POINTS: usize = 3;

/// The cells of a grid's first `n` nodes: `[lo, hi]` in `mu` with the
/// node's flux weight as its measure, `(hi^2 - lo^2) / 2 = w mu`, from
/// `mu = 0` up. In `mu^2` Snell's law is affine (`mu'^2 = 1 - (1 - mu^2) /
/// r^2`, and [`Grid::denser`]'s weights keep `w' mu' = w mu / r^2`), so the
/// cells of a denser grid's images are the images of the cells (a coated
/// sheet's grid, whose cone of total internal reflection holds the images
/// of the base's).
pub(crate) fn cells(g: &Grid, n: usize) -> Vec<(f64, f64)> {
    let mut lo: f64 = 0.0;
    g.w[..n]
        .iter()
        .zip(&g.mu)
        .map(|(w, mu)| {
            let hi = (lo * lo + 2.0 * w * mu).sqrt();
            let c = (lo, hi);
            lo = hi;
            c
        })
        .collect()
}

/// The node pairs `(a, b)` (inside node `a`, outside node `b`) whose cells
/// ([`Grid`] weights as flux measure, `(hi^2 - lo^2) / 2 = w mu`) the
/// refraction edge `mu_out = eta mu_in` of a rough face of index `eta`
/// crosses: the entries of the transmission blocks that Walter's
/// projection of a GGX face holds as cell averages (module doc, "The
/// refraction edge"). The inside grid is made by [`Grid::inside`] from
/// `outside` (or [`Grid::denser`], as a coating's).
pub fn refraction_edge_pairs(eta: f64, outside: &Grid, inside: &Grid) -> Vec<(usize, usize)> {
    let (c_in, c_out) = (cells(inside, inside.len()), cells(outside, outside.len()));
    (0..inside.len())
        .flat_map(|a| (0..outside.len()).map(move |b| (a, b)))
        .filter(|&(a, b)| eta * c_in[a].0 < c_out[b].1 && eta * c_in[a].1 > c_out[b].0)
        .collect()
}

/// Replaces, in both transmission blocks of Walter's projection, two sets
/// of node pairs by the cells' averages ([`cell_averages`]):
/// - the pairs whose cells the refraction edge crosses
///   ([`refraction_edge_pairs`]; module doc, "The refraction edge"), wholly,
///   with [`EDGE_POINTS`] points per axis; GGX faces only (Beckmann's `D`
///   vanishes at the edge);
/// - the other pairs around each node's Snell image
///   ([`snell_image_pairs`]; module doc, "Narrow transmission lobes"), by
///   the face's share ([`snell_image_share`]), with [`SNELL_IMAGE_POINTS`].
///
/// Pair `(a, b)` (inside node `a`, outside node `b`) gets `1 / (w_a mu_a
/// w_b mu_b)` times the integral of `f mu_in mu_out` over the two cells, by
/// Gauss-Legendre in `mu_out` and in `mu_in` on the part of the cell beyond
/// the edge, each order with the blocks' azimuth rule; the light from
/// inside at the same pairs of directions is that over `eta^2`
/// (reciprocity), so the blocks stay reciprocal.
fn transmission_cell_averages(
    bd: &RoughDielectric,
    outside: &Grid,
    inside: &Grid,
    rule: &RuleProjection,
    t_down: &mut [DMatrix<f64>],
    t_up: &mut [DMatrix<f64>],
) {
    let AveragedPairs { edge, image, share } = averaged_pairs(bd, outside, inside);
    let mut average = |pairs: &[(usize, usize)], share: f64, points: usize| {
        cell_averages(bd, outside, inside, rule, (pairs, share), points, t_down, t_up)
    };
    average(&image, share, SNELL_IMAGE_POINTS);
    average(&edge, 1.0, EDGE_POINTS);
}

/// The transmission pairs `(a, b)` (inside node `a`, outside node `b`)
/// that the projection of the face (`transmission_cell_averages`, private)
/// replaces by the cells' averages.
#[derive(Clone, Debug, PartialEq)]
pub struct AveragedPairs {
    /// Those the refraction edge crosses, wholly averaged (GGX faces only:
    /// Beckmann's `D` vanishes at the edge).
    pub edge: Vec<(usize, usize)>,
    /// The others around each node's Snell image, averaged by `share`
    /// (empty where it is 0).
    pub image: Vec<(usize, usize)>,
    /// [`snell_image_share`] of the face.
    pub share: f64,
}

/// Which transmission pairs of the rough face `bd` on the grids `outside`
/// and `inside` hold cell averages, and the share of the Snell image's.
pub fn averaged_pairs(bd: &RoughDielectric, outside: &Grid, inside: &Grid) -> AveragedPairs {
    // Beckmann's D vanishes (exponentially) at a horizontal micro-normal:
    // its transmission has no edge to integrate.
    let edge = if matches!(bd.interface, Interface::Rough(mf) if mf.dist == Distribution::Ggx) {
        refraction_edge_pairs(bd.eta, outside, inside)
    } else {
        Vec::new()
    };
    let share = snell_image_share(bd, outside.len());
    let image = if share > 0.0 {
        snell_image_pairs(outside, inside)
            .into_iter()
            .filter(|p| !edge.contains(p))
            .collect()
    } else {
        Vec::new()
    };
    AveragedPairs { edge, image, share }
}

/// The share of the cell averages at the Snell image's pairs (module doc,
/// "Narrow transmission lobes") for a face on `n` outside nodes: 1 where
/// the transmission lobe at normal incidence is at most as wide as a
/// nominal cell (`pi / 2n` in angle), 0 from twice that width on (there
/// the nodes resolve it and point values are the better quadrature:
/// averages over the cells blur a resolved lobe by the cells' width),
/// linear between, so the face's matrices are continuous in `eta` and
/// `m`. The lobe's full width at half maximum in the transmitted angle is
/// `2 k m (1 - 1/eta)`: a micro-normal tilted by `delta` turns the
/// refracted direction at normal incidence by `(1 - 1/eta) delta`
/// (Snell's law about the tilted normal, differentiated), and the slopes'
/// density falls to half at `tan = k m`, `k = sqrt(sqrt 2 - 1)` for GGX,
/// `sqrt(ln 2)` for Beckmann.
pub fn snell_image_share(bd: &RoughDielectric, n: usize) -> f64 {
    let Interface::Rough(mf) = bd.interface else {
        return 0.0;
    };
    let k = match mf.dist {
        Distribution::Ggx => (std::f64::consts::SQRT_2 - 1.0).sqrt(),
        Distribution::Beckmann => std::f64::consts::LN_2.sqrt(),
    };
    let width = 2.0 * k * bd.m * (1.0 - 1.0 / bd.eta);
    let cell = std::f64::consts::FRAC_PI_2 / n as f64;
    (2.0 - width / cell).clamp(0.0, 1.0)
}

/// The node pairs `(a, b)` (inside node `a`, outside node `b`) whose inside
/// node is within [`SNELL_IMAGE_CELLS`] nodes of the outside node's Snell
/// image ([`Grid::inside`]: the inside grid's last `outside.len()` nodes are
/// the images, in order), where the transmission lobe lies (module doc,
/// "Narrow transmission lobes").
pub fn snell_image_pairs(outside: &Grid, inside: &Grid) -> Vec<(usize, usize)> {
    let n_tir = inside.len() - outside.len();
    (0..outside.len())
        .flat_map(|b| {
            let image = n_tir + b;
            let lo = image.saturating_sub(SNELL_IMAGE_CELLS);
            let hi = (image + SNELL_IMAGE_CELLS).min(inside.len() - 1);
            (lo..=hi).map(move |a| (a, b))
        })
        .collect()
}

/// Replaces the entries of both transmission blocks at `crossed` (inside
/// node `a`, outside node `b`) by `share` times the cells' averages of Walter's
/// transmission ([`transmission_cell_averages`]'s doc), `points` Gauss-Legendre
/// points per axis, on the part of the cells beyond the refraction edge
/// (the whole cells where the edge does not cross them), plus `1 - share`
/// times the entries as they were (the nodes' values).
#[allow(clippy::too_many_arguments)]
fn cell_averages(
    bd: &RoughDielectric,
    outside: &Grid,
    inside: &Grid,
    rule: &RuleProjection,
    (crossed, share): (&[(usize, usize)], f64),
    points: usize,
    t_down: &mut [DMatrix<f64>],
    t_up: &mut [DMatrix<f64>],
) {
    let eta = bd.eta;
    let (c_in, c_out) = (cells(inside, inside.len()), cells(outside, outside.len()));
    let (x, wx) = gauss_legendre_01(points);
    let sin = |mu: f64| (1.0 - mu * mu).max(0.0).sqrt();
    let phis = rule.phis();
    let averages: Vec<(usize, usize, DMatrix<f64>)> = crossed
        .par_iter()
        .map(|&(a, b)| {
            let (lo_a, hi_a) = c_in[a];
            let (lo_b, hi_b) = c_out[b];
            let mut down = DMatrix::zeros(1, phis.len());
            for (xp, wp) in x.iter().zip(&wx) {
                let mu_out = lo_b + (hi_b - lo_b) * xp;
                let lo = lo_a.max(mu_out / eta);
                if lo >= hi_a {
                    continue;
                }
                let s_out = sin(mu_out);
                // toward the light: minus the propagation direction (as in the blocks)
                let wi = DVec3::new(-s_out, 0.0, mu_out);
                // The masking of a direction, the same at every azimuth
                // (`RoughDielectric::eval_mode_masked`, as in `walter_block`).
                let g1_out = bd.g1_cos(mu_out);
                for (yr, wr) in x.iter().zip(&wx) {
                    let mu_in = lo + (hi_a - lo) * yr;
                    let weight = (hi_b - lo_b) * wp * (hi_a - lo) * wr * mu_out * mu_in;
                    let s_in = sin(mu_in);
                    let g1_in = bd.g1_cos(mu_in);
                    for (k, &(c, s)) in phis.iter().enumerate() {
                        let wo = DVec3::new(s_in * c, s_in * s, -mu_in);
                        down[(0, k)] += weight * bd.eval_mode_masked(wi, wo, TransportMode::Radiance, g1_out, g1_in);
                    }
                }
            }
            let norm = inside.w[a] * inside.mu[a] * outside.w[b] * outside.mu[b];
            (a, b, rule.project(&down) / norm)
        })
        .collect();
    // Reciprocity (`W_in T_down = (W_out T_up)^T`, `W = w mu / eta^2`): the
    // light from inside at the same pairs of directions is `f / eta^2`.
    let e2 = eta * eta;
    for (a, b, down) in averages {
        for (m, (td, tu)) in t_down.iter_mut().zip(t_up.iter_mut()).enumerate() {
            let (d, u) = (
                outside.w[b] * outside.mu[b] * down[(0, m)],
                inside.w[a] * inside.mu[a] * down[(0, m)] / e2,
            );
            td[(a, b)] = share * d + (1.0 - share) * td[(a, b)];
            tu[(b, a)] = share * u + (1.0 - share) * tu[(b, a)];
        }
    }
}

/// `(R, T)` of Walter's face as [`RoughDielectric::eval_mode`] has it, for
/// light arriving from `w`: core's quadrature in the square of visible
/// normals (`directional_albedo_rule` on `rule`) times `G1(w) / G1_exact(w)`.
///
/// Core's quadrature weighs the micro-normals by the distribution of
/// visible normals, whose normalisation holds the exact Smith `G1` of `w`
/// (`Microfacet::g1_exact`), and the outgoing direction by
/// `Microfacet::g1`; `eval_mode` has `Microfacet::g1` for both, which for
/// Beckmann is Walter's rational approximation (`paperbsdf_core::microfacet`).
/// The incident direction's `G1` is a factor of the whole lobe, so the
/// ratio turns the one albedo into the other exactly. For GGX the two are
/// the same function (ratio 1). The simulator's face is `eval_mode`'s (its
/// sampling weights `eval_mode / pdf`), and so is the analytic lobe of
/// the model `slab`; until 2026-12-07 the normalisation took core's albedo,
/// up to 0.35% apart at grazing incidence: a thin sheet with Beckmann
/// faces (`eta` 1.1, `m` 0.05) lost 2.1e-3 of its `R + T` at 85.5 degrees
/// against the simulator (2.9e-3 at 86.1 on 64 nodes), what the two
/// albedos of its face differ by there (tests/rough_face.rs,
/// `normalisation_targets_are_walters_own_albedo`).
pub fn walter_albedo(bd: &RoughDielectric, w: DVec3, rule: &(Vec<f64>, Vec<f64>)) -> (f64, f64) {
    let (r, t) = directional_albedo_rule(bd, w, rule);
    let ratio = match bd.interface {
        Interface::Rough(mf) if mf.dist == Distribution::Beckmann => {
            let exact = mf.g1_exact(w, DVec3::Z);
            if exact > 0.0 {
                mf.g1(w, DVec3::Z) / exact
            } else {
                1.0
            }
        }
        _ => 1.0,
    };
    (r * ratio, t * ratio)
}

/// Scales every order of Walter's projected face `l` so that the order-0
/// albedos of every node match core's quadrature of the face (module doc):
/// from outside `R + T` (factors `s_o s_j` on `r_top`, `s_o s_j` on the
/// transmission blocks, outside and inside factors alike); from inside the
/// transmittance `T` (the same `s` on `t_up`) and, with factors of its own
/// (`a_o a_j` on `r_bot`), the reflectance `R`. Returns `s` (outside
/// nodes, then inside nodes). The factors come from the square-root
/// (Sinkhorn) iteration, and where it has not converged after
/// [`MAX_NORMALISATION_ITERATIONS`], from Newton's method
/// (`newton_scaling`) on the same equations.
///
/// From inside the split matters as well as the sum: a lobe narrower than
/// the nodes is sampled at its peak on the diagonal of both blocks, with
/// Jacobians (reflection `1 / (4 |h.w|)`, refraction `eta^2 |h.w| / (...)^2`)
/// that the nodes' weights do not balance, and a single factor per node
/// moved the reflection into the transmission: GGX m = 0.01 kept 0.2% of
/// the 4% Fresnel reflection near the normal (0.05: half; 0.3: within
/// 5e-3; a probe printing the nodes' albedo while writing this, not kept), so a thin sheet with faces smoother than 0.1 reflected up to 0.04
/// too little at normal incidence (thin tissue at m = 0.01: 0.205 against
/// the simulator's 0.244) until 2026-12-05. From outside only the sum is
/// kept: `r_top` takes the rest of the split, and the `slab` model replaces
/// the lit face's `r_top` by the analytic lobe and rescales what crosses it
/// to the transmittance that lobe leaves (crates/slab/src/bsdf.rs). Light
/// reaches `r_top` from nowhere else.
fn normalise_face(bd: &RoughDielectric, outside: &Grid, inside: &Grid, l: &mut [Layer]) -> Result<Vec<f64>, SlabError> {
    let rule = gauss_legendre_01(ALBEDO_POINTS);
    let target = |g: &Grid, side: f64| -> Vec<(f64, f64)> {
        g.mu.par_iter()
            .map(|&mu| walter_albedo(bd, dir_at_mu(mu, side), &rule))
            .collect()
    };
    let t_out: Vec<f64> = target(outside, 1.0).iter().map(|(r, t)| r + t).collect();
    let (mut r_in, mut t_in): (Vec<f64>, Vec<f64>) = target(inside, -1.0).into_iter().unzip();
    let (no, ni) = (outside.len(), inside.len());
    // A block that the grid leaves empty at an inside node (the rough face's
    // transmission from a node a hair's breadth from grazing, which core's
    // quadrature finds and the nodes outside miss) cannot be scaled to its
    // target: the other block takes that share, as the sum's single factor did.
    for j in 0..ni {
        let raw_t = column_albedo(&l[0].t_up, outside, inside, j);
        let raw_r = column_albedo(&l[0].r_bot, inside, inside, j);
        if raw_t <= 0.0 {
            r_in[j] += std::mem::take(&mut t_in[j]);
        } else if raw_r <= 0.0 {
            t_in[j] += std::mem::take(&mut r_in[j]);
        }
    }
    let (mut s_out, mut s_in) = (vec![1.0; no], vec![1.0; ni]);
    let mut a_in = vec![1.0; ni];
    let l0 = &l[0];
    // Below this a node's target is nil (total internal reflection, or no
    // reflection at all): its raw column must be too, and its factor stays.
    let nil = 1e-14;
    let mut worst_last = f64::INFINITY;
    for _ in 0..MAX_NORMALISATION_ITERATIONS {
        let col = |k: &DMatrix<f64>, to: &Grid, s_to: &[f64], j: usize| -> f64 {
            (0..to.len())
                .map(|o| to.w[o] * to.mu[o] * s_to[o] * k[(o, j)])
                .sum::<f64>()
        };
        let now_out: Vec<f64> = (0..no)
            .map(|j| {
                s_out[j] * (col(&l0.r_top, outside, &s_out, j) + col(&l0.t_down, inside, &s_in, j))
                    / (outside.w[j] * outside.mu[j])
            })
            .collect();
        let now_t_in: Vec<f64> = (0..ni)
            .map(|j| s_in[j] * col(&l0.t_up, outside, &s_out, j) / (inside.w[j] * inside.mu[j]))
            .collect();
        let now_r_in: Vec<f64> = (0..ni)
            .map(|j| a_in[j] * col(&l0.r_bot, inside, &a_in, j) / (inside.w[j] * inside.mu[j]))
            .collect();
        let mut worst: f64 = 0.0;
        let mut step = |s: &mut [f64], now: &[f64], want: &[f64]| -> Result<(), SlabError> {
            for (s, (a, t)) in s.iter_mut().zip(now.iter().zip(want)) {
                if *t <= nil && *a <= nil {
                    continue;
                }
                if !(*a > 0.0 && a.is_finite()) {
                    return Err(unresolved(bd));
                }
                worst = worst.max((a / t.max(nil) - 1.0).abs());
                *s *= (t.max(nil) / a).sqrt();
            }
            Ok(())
        };
        step(&mut s_out, &now_out, &t_out)?;
        step(&mut s_in, &now_t_in, &t_in)?;
        step(&mut a_in, &now_r_in, &r_in)?;
        worst_last = worst;
        if worst < NORMALISATION_TOLERANCE {
            break;
        }
    }
    if worst_last >= NORMALISATION_TOLERANCE {
        // Slow (faces close to index-matched): Newton's method from where
        // the square-root iteration stopped, on the two systems it solves
        // (outside `R + T` with inside `T`, which share their factors, and
        // inside `R`).
        let coupled = |e: usize, k: usize| -> f64 {
            match (e < no, k < no) {
                (true, true) => outside.w[k] * outside.mu[k] * l0.r_top[(k, e)] / (outside.w[e] * outside.mu[e]),
                (true, false) => {
                    let i = k - no;
                    inside.w[i] * inside.mu[i] * l0.t_down[(i, e)] / (outside.w[e] * outside.mu[e])
                }
                (false, true) => {
                    let j = e - no;
                    outside.w[k] * outside.mu[k] * l0.t_up[(k, j)] / (inside.w[j] * inside.mu[j])
                }
                (false, false) => 0.0,
            }
        };
        let a = DMatrix::from_fn(no + ni, no + ni, coupled);
        let want: Vec<f64> = t_out.iter().chain(&t_in).copied().collect();
        let mut v: Vec<f64> = s_out.iter().chain(&s_in).copied().collect();
        let worst_t = newton_scaling(&a, &want, &mut v, nil, NORMALISATION_TOLERANCE);
        s_out.copy_from_slice(&v[..no]);
        s_in.copy_from_slice(&v[no..]);
        let a_r = DMatrix::from_fn(ni, ni, |e, k| {
            inside.w[k] * inside.mu[k] * l0.r_bot[(k, e)] / (inside.w[e] * inside.mu[e])
        });
        let worst_r = newton_scaling(&a_r, &r_in, &mut a_in, nil, NORMALISATION_TOLERANCE);
        worst_last = worst_t.max(worst_r);
    }
    // Converged (below NORMALISATION_TOLERANCE), or to what is accepted.
    if worst_last.is_nan() || worst_last > NORMALISATION_SLOW_TOLERANCE {
        return Err(unresolved(bd));
    }
    for layer in l.iter_mut() {
        scale_rows_cols(&mut layer.r_top, &s_out, &s_out);
        scale_rows_cols(&mut layer.t_down, &s_in, &s_out);
        scale_rows_cols(&mut layer.r_bot, &a_in, &a_in);
        scale_rows_cols(&mut layer.t_up, &s_out, &s_in);
    }
    Ok(s_out.into_iter().chain(s_in).collect())
}

/// Steps of Newton's method in [`newton_scaling`] after which it stops.
const NEWTON_STEPS: usize = 60;

/// Newton's method for the symmetric scaling `v_e S_e = t_e` with
/// `S_e = sum_k a[(e, k)] v_k` (every node's albedo `now_e = v_e S_e` at
/// its target `t_e`), in the logarithms of the factors: `F_e = ln(now_e /
/// t_e)`, Jacobian `dF_e / d ln v_k = [e = k] + a[(e, k)] v_k / S_e`,
/// solved by LU, each step halved until `sum F^2` falls, until every
/// albedo is within `tolerance` of its target. The equations
/// whose target and albedo are both below `nil` are left out (their
/// factor held), as in the square-root iteration. Returns the largest
/// `|now_e / t_e - 1|` reached (infinite where an albedo is not positive).
/// The faces' normalisation ([`normalise_face`]) and the walk's scaling to
/// the energy the face loses (`crate::face_walk`) finish with it.
///
/// The square-root iteration (`v_e *= sqrt(t_e / now_e)`) slows to a
/// crawl where the system is nearly degenerate: a face close to
/// index-matched transmits almost all of its light from each outside node
/// to one inside node, so the outside and inside factors are fixed almost
/// only through their products, and its weak reflection pins them apart
/// (GGX `eta` 1.05, `m` 1.3 was 2.2e-6 from its targets after 20,000
/// iterations). Newton's step takes that direction in one solve.
pub(crate) fn newton_scaling(a: &DMatrix<f64>, target: &[f64], v: &mut [f64], nil: f64, tolerance: f64) -> f64 {
    let n = v.len();
    // `S_e` for every equation, and the albedos `v_e S_e`.
    let sums = |v: &[f64]| -> Vec<f64> { (0..n).map(|e| (0..n).map(|k| a[(e, k)] * v[k]).sum()).collect() };
    let albedos = |v: &[f64]| -> Vec<f64> { sums(v).iter().zip(v).map(|(s, x)| x * s).collect() };
    let active: Vec<usize> = {
        let now = albedos(v);
        (0..n).filter(|&e| !(target[e] <= nil && now[e] <= nil)).collect()
    };
    // The residuals `F` and the largest relative error, or `None` where an albedo is not positive.
    let residuals = |v: &[f64]| -> Option<(Vec<f64>, f64)> {
        let now = albedos(v);
        let mut worst: f64 = 0.0;
        let f = active
            .iter()
            .map(|&e| {
                let (x, t) = (now[e], target[e].max(nil));
                worst = worst.max((x / t - 1.0).abs());
                (x > 0.0 && x.is_finite()).then(|| (x / t).ln())
            })
            .collect::<Option<Vec<f64>>>()?;
        Some((f, worst))
    };
    let Some((mut f, mut worst)) = residuals(v) else {
        return f64::INFINITY;
    };
    for _ in 0..NEWTON_STEPS {
        if worst < tolerance {
            break;
        }
        let m = active.len();
        let s = sums(v);
        let jac = DMatrix::from_fn(m, m, |r, c| {
            let (e, k) = (active[r], active[c]);
            f64::from(u8::from(r == c)) + a[(e, k)] * v[k] / s[e]
        });
        let rhs = nalgebra::DVector::from_iterator(m, f.iter().map(|x| -x));
        let Some(dx) = jac.lu().solve(&rhs) else {
            break;
        };
        let merit = |f: &[f64]| f.iter().map(|x| x * x).sum::<f64>();
        let before = merit(&f);
        let mut step = 1.0;
        let mut taken = false;
        for _ in 0..40 {
            let mut trial = v.to_vec();
            for (r, &e) in active.iter().enumerate() {
                trial[e] *= (step * dx[r]).exp();
            }
            if let Some((f_new, w_new)) = residuals(&trial) {
                if merit(&f_new) < before {
                    v.copy_from_slice(&trial);
                    (f, worst) = (f_new, w_new);
                    taken = true;
                    break;
                }
            }
            step *= 0.5;
        }
        if !taken {
            break;
        }
    }
    worst
}

/// `K[o][j] *= rows[o] cols[j]`.
pub(crate) fn scale_rows_cols(k: &mut DMatrix<f64>, rows: &[f64], cols: &[f64]) {
    for j in 0..k.ncols() {
        for o in 0..k.nrows() {
            k[(o, j)] *= rows[o] * cols[j];
        }
    }
}

/// The error of a face whose projection [`normalise_face`] cannot scale to
/// its albedo: a node whose raw albedo is not finite, or the scaling still
/// above [`NORMALISATION_SLOW_TOLERANCE`] after the Sinkhorn iteration and
/// Newton's method (`newton_scaling`, where a face's raw projection cannot
/// be scaled to its targets: GGX `eta` 1.001, `m` 0.3 stays 3.4e-3 off).
/// On 32 nodes, 2026-12-07, both face modes, `m` from 0.02 to 1.2
/// (examples/near_index_support.rs): at `eta` 1.001 GGX with `m >= 0.1`
/// and Beckmann with `m >= 0.2`; at 1.01 GGX with `m` 1.2 and Beckmann
/// with 0.8 and 1.2; none from 1.02 on. Before Newton's method (the same
/// day) every face with `eta <= 1.03` but one was refused, and some up to
/// 1.1, and more nodes did not help (128 for eta 1.05, 2026-12-06). Now
/// more nodes let some through: GGX 1.001 with `m` 0.1 and Beckmann 1.01
/// with 0.8 and 1.2 from 64 nodes, GGX 1.001 with 0.2 to 0.8 and Beckmann
/// 1.001 with 0.2 and 0.3 from 128; not GGX 1.001 or 1.01 with 1.2 nor
/// Beckmann 1.001 from 0.5 (examples/near_index_support.rs, `--more-nodes`).
fn unresolved(bd: &RoughDielectric) -> SlabError {
    SlabError::UnresolvedFace {
        eta: bd.eta,
        m: bd.m,
        dist: bd.dist.name(),
    }
}

/// Flux albedo `sum_o w_o mu_o K[o][j] / (w_j mu_j)` of column `j` of `k` on output grid `to`
/// (`from` the grid of `j`): the fraction of collimated light's flux at node `j` that `k` sends out.
pub(crate) fn column_albedo(k: &DMatrix<f64>, to: &Grid, from: &Grid, j: usize) -> f64 {
    (0..to.len()).map(|o| to.w[o] * to.mu[o] * k[(o, j)]).sum::<f64>() / (from.w[j] * from.mu[j])
}

/// Adds the microsurface walk's orders >= 2 ([`crate::face_walk`]) to
/// The walk's reflection from outside is taken past the sheet's orders only
/// between directions below this cosine (more than 60 degrees from the
/// normal; [`crate::face_walk::outside_reflection`]): nearer the normal its
/// orders above 48 are nil (luster and matte: the in-plane values with the
/// cut at 60 degrees, at 50 degrees and without it agree to every one of 6
/// printed digits, from 30 R -30 to 85 R -85, measured 2026-12-05 by
/// rebuilding with this constant changed; examples/walk_orders.rs prints
/// those points), and the
/// chain on 13 of the 32 nodes costs a sixth.
pub const WALK_GRAZING_MU: f64 = 0.5;

/// The roughness `alpha` at and above which a face's walk is summed to the
/// orders asked for ([`walk_orders_for`]): luster's Beckmann 0.15 front,
/// whose forward peak at grazing incidence 256 orders resolve.
pub const WALK_REFERENCE_ALPHA: f64 = 0.15;

/// The most [`walk_orders_for`] multiplies the orders asked for by: 2.5,
/// reached at `alpha = 0.06`. Smoother faces scatter too little more than
/// once for their walk's peak to matter: under devB's sheet with 256 orders
/// against 1024, Beckmann 0.05 and 0.04 fronts moved the in-plane
/// reflection by 0.17% and 0.008% (0.06: 0.79%), and 960 orders for
/// glossy's Beckmann 0.04 front cost 0.3 s more build (1.0 s) for no change
/// the convergence example sees.
pub const WALK_MOST_FACTOR: f64 = 2.5;

/// The Fourier orders of the walk's reflection from outside for a face of
/// roughness `alpha` when `walk_orders` are asked for a face of
/// [`WALK_REFERENCE_ALPHA`] (0: none): `walk_orders` for rougher faces,
/// `walk_orders * min(WALK_REFERENCE_ALPHA / alpha, WALK_MOST_FACTOR)`
/// rounded up to a multiple of 64 for smoother ones, at most `max`. The
/// walk's forward peak at grazing incidence narrows in azimuth as `alpha`
/// does, so the orders it needs grow as `1 / alpha` (about `38 / alpha`):
/// with 256 for every face, Beckmann fronts of 0.12, 0.1, 0.08 and 0.06
/// under devB's sheet were 3.9%, 3.9%, 2.8% and 0.8% off the reflection
/// with 1024 (at 80 R -80, in the plane from 50 to 80 degrees); with this
/// rule doubling `walk_orders` (which doubles every face's orders) moves
/// Beckmann 0.04 to 0.2 fronts by at most 0.001% there (a probe,
/// 2026-12-06, not kept; tests/walk_orders.rs asserts it on luster with
/// smoother fronts; docs/slab.md "Convergence").
pub fn walk_orders_for(walk_orders: usize, alpha: f64, max: usize) -> usize {
    if walk_orders == 0 || alpha >= WALK_REFERENCE_ALPHA || alpha <= 0.0 {
        return walk_orders.min(max);
    }
    let factor = (WALK_REFERENCE_ALPHA / alpha).min(WALK_MOST_FACTOR);
    let wanted = (walk_orders as f64 * factor / 64.0).ceil() as usize * 64;
    wanted.min(max)
}

/// The window of the walk's reflection from outside summed to `big_m`
/// orders (module doc): 1 to order `flat`, then linear to 0 at `big_m`. With
/// `flat = 0` it is Fejer's `1 - m / big_m`, whose sum of a non-negative
/// series is non-negative; a flatter window keeps more of the orders below
/// `big_m`, exact in the limit, but rings when the series is not resolved.
pub fn walk_window(m: usize, big_m: usize, flat: usize) -> f64 {
    if m <= flat {
        1.0
    } else if m >= big_m {
        0.0
    } else {
        1.0 - (m - flat) as f64 / (big_m - flat) as f64
    }
}

/// Walter's projected face `l`, scaled to the energy that face loses at each
/// node (module doc), and returns what was added, with the walk's
/// reflection from outside to `walk_orders` orders
/// ([`ProjectedFace::walk_r_top`]; empty unless `walk_orders` exceeds the orders).
fn add_walk(
    bd: &RoughDielectric,
    outside: &Grid,
    inside: &Grid,
    l: &mut [Layer],
    azimuth_points: usize,
    walk_orders: usize,
) -> Result<(Compensation, Vec<DMatrix<f64>>), SlabError> {
    let Interface::Rough(mf) = bd.interface else {
        return Err(SlabError::Unsupported(
            "the microsurface walk of a face without microfacets",
        ));
    };
    let (lost_out, lost_in, clipped) = walter_loss(outside, inside, &l[0]);
    let lbar = |g: &Grid, lv: &[f64]| 2.0 * (0..g.len()).map(|j| g.w[j] * g.mu[j] * lv[j]).sum::<f64>();
    let (lbar_o, lbar_i) = (lbar(outside, &lost_out), lbar(inside, &lost_in));
    let walk = match crate::face_walk::multiple_scattering(
        mf,
        bd.eta,
        outside,
        inside,
        l.len(),
        // half the points per panel (module doc)
        (azimuth_points / 2).max(2),
        [&lost_out, &lost_in],
    ) {
        Ok(w) => w,
        // A face too smooth for the grid (m = 0.04 on 32 nodes): the walk's
        // discretised light misses some nodes altogether and cannot be
        // scaled to what they lose. Such a face loses little (its multiple
        // scattering is tiny), and that light gets core's separable lobes.
        Err(SlabError::Discretisation { .. }) => return Ok((compensate(bd, outside, inside, &mut l[0]), Vec::new())),
        Err(e) => return Err(e),
    };
    // Fejer's weights `1 - m / M` on the walk's orders (module doc): its
    // light at grazing angles is narrower in azimuth than `M` orders
    // resolve, and the truncated series rang below zero (where `eval`
    // clamps it, adding up to 3e-3 of energy at 85 degrees); Fejer's sum of
    // a non-negative function is non-negative, and order 0 (the energy) is
    // kept.
    let big_m = l.len() as f64;
    for (m, (layer, ms)) in l.iter_mut().zip(&walk.orders).enumerate() {
        let fejer = 1.0 - m as f64 / big_m;
        layer.r_top += &ms.r_top * fejer;
        layer.t_down += &ms.t_down * fejer;
        layer.r_bot += &ms.r_bot * fejer;
        layer.t_up += &ms.t_up * fejer;
    }
    let big = l.len();
    let walk_r_top = if walk_orders > big {
        let no = outside.len();
        let high = crate::face_walk::outside_reflection(
            mf,
            bd.eta,
            outside,
            big..walk_orders,
            (azimuth_points / 2).max(2),
            &walk.scale[..no],
            WALK_GRAZING_MU,
        )?;
        // The full chain's orders below `big` (unwindowed), the outside
        // chain's above.
        walk.orders[..big].iter().map(|l| l.r_top.clone()).chain(high).collect()
    } else {
        Vec::new()
    };
    // What the walk does not resolve (near normal incidence on smooth faces)
    // is carried by separable lobes.
    let (u_out, u_in) = walk.unresolved;
    let separable = if u_out.iter().chain(&u_in).any(|&u| u > 0.0) {
        let c = separable_lobes(bd, outside, inside, &mut l[0], u_out, u_in, 0.0);
        [c.lbar_out, c.lbar_in]
    } else {
        [0.0, 0.0]
    };
    let compensation = Compensation {
        walk: true,
        k_out: walk.k.0,
        k_in: walk.k.1,
        separable,
        lost_out,
        lost_in,
        lbar_out: lbar_o,
        lbar_in: lbar_i,
        clipped,
    };
    Ok((compensation, walk_r_top))
}

/// Adds the separable compensation lobes of step 2 of `paperbsdf_core::paper::face`
/// to order 0 of Walter's projected face `l` (module doc) and returns them.
fn compensate(bd: &RoughDielectric, outside: &Grid, inside: &Grid, l: &mut Layer) -> Compensation {
    let (lost_out, lost_in, clipped) = walter_loss(outside, inside, l);
    separable_lobes(bd, outside, inside, l, lost_out, lost_in, clipped)
}

/// `1 - R - T` of the projected face `l` at the outside and the inside
/// nodes (clipped at 0), and the most negative value clipped.
fn walter_loss(outside: &Grid, inside: &Grid, l: &Layer) -> (Vec<f64>, Vec<f64>, f64) {
    let mut clipped: f64 = 0.0;
    let mut lost = |a: f64| {
        let v = 1.0 - a;
        clipped = clipped.min(v);
        v.max(0.0)
    };
    let lost_out: Vec<f64> = (0..outside.len())
        .map(|j| lost(column_albedo(&l.r_top, outside, outside, j) + column_albedo(&l.t_down, inside, outside, j)))
        .collect();
    let lost_in: Vec<f64> = (0..inside.len())
        .map(|j| lost(column_albedo(&l.r_bot, inside, inside, j) + column_albedo(&l.t_up, outside, inside, j)))
        .collect();
    (lost_out, lost_in, clipped)
}

/// Adds to order 0 of `l` the separable reciprocal lobes (module doc) that
/// carry `lost_out` (outside nodes) and `lost_in` (inside nodes).
fn separable_lobes(
    bd: &RoughDielectric,
    outside: &Grid,
    inside: &Grid,
    l: &mut Layer,
    lost_out: Vec<f64>,
    lost_in: Vec<f64>,
    clipped: f64,
) -> Compensation {
    let lbar = |g: &Grid, lv: &[f64]| 2.0 * (0..g.len()).map(|j| g.w[j] * g.mu[j] * lv[j]).sum::<f64>();
    let (lbar_o, lbar_i) = (lbar(outside, &lost_out), lbar(inside, &lost_in));
    // The shares as core defines them (the Paper BSDF's faces use the same function);
    // a face that loses nothing from outside gets no compensation.
    let (k_o, k_i) = if lbar_o > 0.0 {
        compensation_shares(bd.dist, bd.eta, bd.m, lbar_o, lbar_i)
    } else {
        (0.0, 0.0)
    };
    // order 0 of f = c E_a(mu_j) E_b(mu_o): K[o][j] = w_j mu_j 2 pi c E_a(mu_j) E_b(mu_o)
    let add = |k: &mut DMatrix<f64>, from: &Grid, ea: &[f64], to_e: &[f64], c: f64| {
        if c == 0.0 {
            return;
        }
        for j in 0..from.len() {
            let a = 2.0 * PI * c * from.w[j] * from.mu[j] * ea[j];
            for (o, eb) in to_e.iter().enumerate() {
                k[(o, j)] += a * eb;
            }
        }
    };
    let inv = |x: f64| if x > 0.0 { 1.0 / (PI * x) } else { 0.0 };
    add(&mut l.r_top, outside, &lost_out, &lost_out, (1.0 - k_o) * inv(lbar_o));
    add(&mut l.t_down, outside, &lost_out, &lost_in, k_o * inv(lbar_i));
    add(&mut l.r_bot, inside, &lost_in, &lost_in, (1.0 - k_i) * inv(lbar_i));
    add(&mut l.t_up, inside, &lost_in, &lost_out, k_i * inv(lbar_o));
    Compensation {
        walk: false,
        k_out: k_o,
        k_in: k_i,
        separable: [lbar_o, lbar_i],
        lost_out,
        lost_in,
        lbar_out: lbar_o,
        lbar_in: lbar_i,
        clipped,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `walter_projection` takes the light from inside (`t_up`) from
    /// `t_down` by reciprocity: here it is evaluated directly, for faces
    /// of either distribution, a rough and a smooth one, on a sheet's grids
    /// and a coating's (the denser grid below the face), every order and
    /// node pair (the cell averages across the refraction edge and around
    /// the Snell image aside, which `cell_averages` makes reciprocal
    /// itself).
    #[test]
    fn light_from_inside_is_reciprocal() {
        let outside = Grid::outside(12);
        let sheet = Grid::inside(&outside, 1.5, 6);
        let coat = Grid::inside(&outside, 1.35, 6);
        let dense = Grid::inside(&outside, 1.8, 3);
        let cases = [
            (Distribution::Ggx, 0.3, 1.5, &sheet),
            (Distribution::Beckmann, 0.15, 1.5, &sheet),
            (Distribution::Ggx, 0.05, 1.35, &coat),
            (Distribution::Beckmann, 0.6, 1.8, &dense),
        ];
        let top = &outside;
        for (dist, m, eta, below) in cases {
            let bd = RoughDielectric::new(dist, eta, m).expect("a valid face");
            let orders = 12;
            let layers = walter_projection(&bd, top, below, orders, 4);
            let direct = walter_block(&RuleProjection::new(orders, 4, 0), &bd, below, false, top, true);
            // Pairs held as cell averages (the refraction edge's and the
            // Snell image's), which `cell_averages` makes reciprocal itself.
            let pairs = averaged_pairs(&bd, top, below);
            let averaged: Vec<(usize, usize)> = pairs.edge.iter().chain(&pairs.image).copied().collect();
            // Relative to the pair's order 0 (which bounds every order of a
            // non-negative function): the high orders are sums that cancel
            // far below their terms. Measured 3e-12 to 6e-11: the two
            // directions' half vectors are normalised from different sums,
            // and far in a narrow lobe's tail `D` amplifies that rounding
            // (`d ln D / d theta_h` near 1e4 for Beckmann 0.15 at 80
            // degrees); 1e-9 is rounding, an error of the relation would be
            // of order 1 (`eta^2` is 2.25).
            assert!(direct[0].amax() > 0.0);
            let mut worst: f64 = 0.0;
            for (l, d) in layers.iter().zip(&direct) {
                for o in 0..top.len() {
                    for j in 0..below.len() {
                        if averaged.contains(&(j, o)) {
                            continue;
                        }
                        let diff = (l.t_up[(o, j)] - d[(o, j)]).abs();
                        let scale = direct[0][(o, j)].abs();
                        if scale > 0.0 {
                            worst = worst.max(diff / scale);
                        } else {
                            assert_eq!(diff, 0.0);
                        }
                    }
                }
            }
            assert!(worst < 1e-9, "{dist:?} {m} eta {eta}: t_up off by {worst:e} of order 0");
        }
    }

    /// `newton_scaling` on a system shaped as a face close to index-matched:
    /// `n` outside and `n` inside factors, the outside equations holding a
    /// weak reflection (1e-4 of the transmission) and a transmission that
    /// sends each outside node almost only to its own inside node, the
    /// inside equations that transmission back; the targets made from known
    /// factors `v*` (between 0.8 and 1.25). Newton's method from 1 reaches
    /// them to rounding and finds `v*` (the scaling is unique), where the
    /// square-root iteration, after as many iterations as the normalisation
    /// gives it, is still far (the reason for Newton's method: the products
    /// `v_out v_in` are fixed at once, their ratio only through the weak
    /// reflection).
    #[test]
    fn newton_scaling_solves_a_nearly_degenerate_scaling() {
        let n = 12;
        let big = 2 * n;
        // A deterministic spread of positive values.
        let spread = |k: usize| 0.5 + 0.5 * ((k as f64 * 0.7548776662).fract());
        let a = DMatrix::from_fn(big, big, |e, k| match (e < n, k < n) {
            (true, true) => 1e-4 * spread(e * big + k),
            (true, false) | (false, true) => {
                let (i, j) = (e % n, k % n);
                if i == j {
                    1.0
                } else {
                    1e-3 * spread(i * n + j) / (1.0 + (i as f64 - j as f64).abs())
                }
            }
            (false, false) => 0.0,
        });
        let v_star: Vec<f64> = (0..big).map(|k| 0.8 + 0.45 * spread(3 * k + 1)).collect();
        let target: Vec<f64> = (0..big)
            .map(|e| v_star[e] * (0..big).map(|k| a[(e, k)] * v_star[k]).sum::<f64>())
            .collect();
        let mut v = vec![1.0; big];
        let worst = newton_scaling(&a, &target, &mut v, 1e-14, NORMALISATION_TOLERANCE);
        assert!(worst < NORMALISATION_TOLERANCE, "Newton's method left {worst:e}");
        let off = v
            .iter()
            .zip(&v_star)
            .map(|(x, y)| (x / y - 1.0).abs())
            .fold(0.0, f64::max);
        assert!(off < 1e-9, "the factors are {off:e} from the known ones");
        // The square-root iteration on the same system.
        let mut s = vec![1.0; big];
        let mut sinkhorn_worst = 0.0;
        for _ in 0..MAX_NORMALISATION_ITERATIONS {
            let now: Vec<f64> = (0..big)
                .map(|e| s[e] * (0..big).map(|k| a[(e, k)] * s[k]).sum::<f64>())
                .collect();
            sinkhorn_worst = now
                .iter()
                .zip(&target)
                .map(|(x, t)| (x / t - 1.0).abs())
                .fold(0.0, f64::max);
            for ((s, x), t) in s.iter_mut().zip(&now).zip(&target) {
                *s *= (t / x).sqrt();
            }
        }
        println!("after {MAX_NORMALISATION_ITERATIONS} square-root iterations: {sinkhorn_worst:e}; Newton: {worst:e}");
        assert!(
            sinkhorn_worst > 1e3 * NORMALISATION_TOLERANCE,
            "the square-root iteration converged ({sinkhorn_worst:e}): the system does not show the slow case"
        );
    }
}
