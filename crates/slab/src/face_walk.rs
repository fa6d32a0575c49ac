//! The multiple-scattering rough face (`face_scattering = "multiple"`) as the
//! simulator has it: the random walk on the Smith microsurface of
//! `paperbsdf_core::microsurface` (Heitz, Hanika, d'Eon, Dachsbacher,
//! SIGGRAPH 2016, with the separable masking of the project's Walter face),
//! solved deterministically on the slab's grids, orders >= 2.
//!
//! **The walk is a Markov chain in direction.** In core's walk the height of
//! each scattering point is drawn afresh, so what happens next depends only
//! on the ray's side (outside or inside the face) and its propagation
//! direction `v` in that side's local frame (the medium above the
//! microsurface, `paperbsdf_core::microsurface`'s `local`): a ray going up
//! (`v.z > 0`) escapes with probability `G1(v.z)` (exact Smith `G1`) and is
//! otherwise intercepted; a ray going down is always intercepted. An
//! intercepted ray meets a facet visible from `-v` (above or below the
//! horizon) and is reflected or refracted with the phase density
//! `p(v -> v')` of [`Microsurface::scatter_density`] (per steradian of the new
//! direction; a refraction puts the ray on the other side, with local
//! direction minus the transmitted one). Every state is thus one of four
//! hemispheres: outside going up or down, inside going up or down. The
//! kernel depends on the azimuth difference only (an isotropic surface), so
//! Fourier orders decouple as in [`crate::layer`].
//!
//! **Discretisation (Nystrom).** The states are the nodes of the slab's own
//! grids: the outside grid for both outside hemispheres, the inside grid for
//! both inside hemispheres (`N = 2 (n_out + n_in)` states). Per order `m`,
//! `P_m[b][a] = integral_0^(2 pi) p(v_a -> v_b(phi)) cos(m phi) dphi` with
//! `v_a` at azimuth 0, by the graded azimuth rule of [`crate::interface`]
//! (the kernel's lobes are Walter's). The chain's transfer is
//! `M = P diag(w_a C_a)` with the grid weight `w_a` and the continuation
//! probability `C_a` (`1 - G1(mu_a)` going up, 1 going down). Light arriving
//! at node `a` (a state going down) is first scattered into `P[:, a]`, so
//! the light scattered twice or more, before its escape, is
//! `X = (I - M)^-1 M P` and the layer matrix entry (propagation directions,
//! radiance transport, the convention of [`crate::layer`]) is
//! `K_m[b][a] = w_a mu_a / mu_b G1(mu_b) X[b][a]` for an exit state `b`
//! (going up), times `(-1)^m` when `a` and `b` are on different sides: the
//! inside frame is the global one turned over, which turns azimuths by `pi`.
//! The same formula with `P` for `X` is order 1, Walter's face with the exact
//! Smith `G1` (tested against the projection of `RoughDielectric::eval_mode`).
//!
//! **Edges.** GGX's kernel jumps to zero where the micro-normal joining the
//! two directions turns horizontal (`D` of a horizontal micro-normal is
//! `m^2 / pi`; Beckmann's vanishes there). Its `z` is linear in the two
//! cosines, `e_a mu_a + e_b mu_b`: reflection within one hemisphere (a ray
//! going down that leaves going down, or up and up) needs the new cosine
//! on one side of the old, so the edge is the diagonal, where the nodes sat
//! exactly on it; refraction has it on the line `mu_b = eta mu_a` (or over
//! `eta`), as Walter's face ([`crate::interface`], "The refraction edge").
//! Sampled at the nodes the jumps left the raw chain's albedo off by up to
//! 11% of what Walter's face loses (GGX m = 0.6), alternating from node to
//! node, and the normalisation's factors by as much (0.95 to 1.13 at
//! m = 0.9 on 32 nodes): the walk's reflection at grazing angles moved by
//! 3.5-6% of itself, 0.32-0.36% of the sheets' values, when the nodes were
//! doubled (examples/convergence.rs: very rough, devA). The pairs of states
//! whose cells ([`crate::interface`]'s, each node's in `mu`) an edge
//! crosses take the kernel averaged over the two cells in the chain's
//! measure `dmu`, the arriving cell by [`WALK_EDGE_POINTS`] Gauss-Legendre
//! points and the leaving cell split at the edge: the raw albedo is then
//! within 0.55% of the loss (tests/face_walk.rs), the factors within 0.6%
//! of 1, and those sheets move by 0.06-0.07%. About 10 ms per GGX face
//! (timed inside the build while writing this).
//!
//! **Normalisation.** The continuous walk loses nothing, so its orders >= 2
//! carry exactly what Walter's face loses, `L(mu) = 1 - R(mu) - T(mu)`. The
//! chain's matrices are made reciprocal (the mean of each block and its
//! reciprocal image, [`crate::layer`]'s relations) and then scaled
//! symmetrically (`K[o][j] s_o s_j`, a Sinkhorn iteration as
//! [`crate::interface`]'s) so that each node's albedo is the `L` that
//! Walter's projected face leaves: the discrete face conserves energy at
//! every node, and the chain decides the shape and the split between
//! reflection and transmission. The factors show how far the raw chain was
//! ([`WalkFace::scale`]). A node where the raw chain returns almost nothing
//! of what it must carry ([`MIN_RESOLVED`]: a smooth face, whose walk's
//! lobes near normal incidence fall between the nodes) is left out of the
//! scaling and its loss returned ([`WalkFace::unresolved`]): such a face
//! loses little, and `crate::interface` gives it separable lobes.

use crate::azimuth_fft::RuleProjection;
use crate::error::SlabError;
use crate::interface::{cells, newton_scaling, scale_rows_cols, NORMALISATION_SLOW_TOLERANCE};
use crate::layer::Layer;
use crate::quad::Grid;
use nalgebra::DMatrix;
use paperbsdf_core::microsurface::{Microsurface, Scatterer};
use paperbsdf_core::quadrature::gauss_legendre_01;
use paperbsdf_core::{DVec3, Distribution, Microfacet};
use rayon::prelude::*;

/// Square-root iterations of the symmetric scaling to the lost energy
/// ([`symmetric_scaling`]) after which Newton's method finishes it. Faces
/// close to index-matched crawl there as in the faces' normalisation
/// (`crate::interface`, `MAX_NORMALISATION_ITERATIONS`): on the faces of
/// examples/near_index_support.rs the square-root iteration took up to
/// 10,365 iterations (20,000 were allowed until 2026-12-07), most faces
/// 100 to 1,000.
const MAX_SCALING_ITERATIONS: usize = 2_000;

/// Where the scaling to the lost energy stops: every node's albedo within
/// this relative error of its target.
const SCALING_TOLERANCE: f64 = 1e-12;

/// One state of the chain: a node of a grid on one side, going up or down.
#[derive(Clone, Copy, Debug)]
struct State {
    outside: bool,
    up: bool,
    mu: f64,
    w: f64,
    /// The node's cell in `mu` (`crate::interface::cells`), over which the
    /// kernel is averaged where an edge crosses it (module doc, "Edges").
    cell: (f64, f64),
}

impl State {
    /// The local propagation direction at azimuth `phi` given by its cosine and sine.
    #[inline]
    fn dir(&self, c: f64, s: f64) -> DVec3 {
        let st = (1.0 - self.mu * self.mu).max(0.0).sqrt();
        DVec3::new(st * c, st * s, if self.up { self.mu } else { -self.mu })
    }
}

/// The orders >= 2 of the walk as layers, and what the normalisation did.
#[derive(Clone, Debug)]
pub struct WalkFace {
    /// The multiply scattered light per Fourier order (the four blocks of a
    /// face: outside grid on top, inside grid below), normalised.
    pub orders: Vec<Layer>,
    /// The chain's own order-0 albedo per node before the normalisation
    /// (outside nodes, then inside nodes): what the discretised walk returns
    /// of the light Walter's face loses.
    pub raw_albedo: Vec<f64>,
    /// The symmetric scaling factors (outside nodes, then inside nodes).
    pub scale: Vec<f64>,
    /// Flux-weighted share of the multiply scattered light that is
    /// transmitted, for diffuse light from outside (`k_o` of core's
    /// compensation) and from inside (`k_i`), of the light the walk carries.
    pub k: (f64, f64),
    /// The loss at the nodes the walk does not resolve (its raw albedo below
    /// [`MIN_RESOLVED`] of the loss; 0 elsewhere), outside nodes and inside
    /// nodes: the walk carries none of it, the caller must.
    pub unresolved: (Vec<f64>, Vec<f64>),
}

/// A node whose raw albedo from the discretised walk is below this fraction
/// of the energy it must carry is not resolved by the grid (a face so smooth
/// that the walk's lobes fall between the nodes near normal incidence:
/// Beckmann 0.08 on 32 nodes); its loss is left to the caller.
pub const MIN_RESOLVED: f64 = 0.01;

/// The states in order: outside up, outside down, inside up, inside down.
fn states(outside: &Grid, inside: &Grid) -> Vec<State> {
    let mut v = Vec::with_capacity(2 * (outside.len() + inside.len()));
    for (g, out) in [(outside, true), (inside, false)] {
        let cells = cells(g, g.len());
        for up in [true, false] {
            for ((&mu, &w), &cell) in g.mu.iter().zip(&g.w).zip(&cells) {
                v.push(State {
                    outside: out,
                    up,
                    mu,
                    w,
                    cell,
                });
            }
        }
    }
    v
}

/// Gauss-Legendre points per axis and part of the cell averages across an
/// edge of the kernel (module doc, "Edges"): the kernel is smooth on either
/// side; 3 points gave the same convergence (examples/convergence.rs, within
/// 0.01 percentage points) with 18 kernel evaluations per pair and azimuth
/// instead of 8.
pub const WALK_EDGE_POINTS: usize = 2;

/// The unnormalised micro-normal's `z` of the scattering from state `a` to
/// state `b` is `e_a mu_a + e_b mu_b` (module doc, "Edges"): `(e_a, e_b)`.
fn edge_coefficients(s: &Microsurface, a: &State, b: &State) -> (f64, f64) {
    // i = -v_a (the arriving ray reversed); reflection: h ~ i + v_b,
    // refraction (the other side's frame turned over, o = -v_b): h ~ i + eta_l o.
    let e_a = if a.up { -1.0 } else { 1.0 };
    let z_b = if b.up { 1.0 } else { -1.0 };
    let e_b = if a.outside == b.outside {
        z_b
    } else {
        -z_b * if a.outside { s.eta } else { 1.0 / s.eta }
    };
    (e_a, e_b)
}

/// Whether the edge `e_a mu_a + e_b mu_b = 0` crosses the cells of `a` and `b`.
fn edge_crosses(e: (f64, f64), a: &State, b: &State) -> bool {
    let corners = [
        (a.cell.0, b.cell.0),
        (a.cell.0, b.cell.1),
        (a.cell.1, b.cell.0),
        (a.cell.1, b.cell.1),
    ]
    .map(|(x, y)| e.0 * x + e.1 * y);
    corners.iter().any(|&v| v < 0.0) && corners.iter().any(|&v| v > 0.0)
}

/// The chain's kernel from state `a` (scattered by `sc`) into the direction
/// `vb` of state `b`'s side: a reflection on the same side, a refraction
/// (in the other side's frame, turned over) otherwise.
#[inline(always)]
fn kernel(sc: &Scatterer, a: &State, b: &State, vb: DVec3) -> f64 {
    if a.outside == b.outside {
        sc.density(vb, true)
    } else {
        sc.density(-vb, false)
    }
}

/// The kernel from `a` to `b` at the azimuths `phis`, averaged over the two
/// cells (in `mu`, the chain's measure), the cell of `b` split at the edge
/// (module doc, "Edges").
fn edge_average(s: &Microsurface, a: &State, b: &State, e: (f64, f64), phis: &[(f64, f64)], row: &mut [f64]) {
    let (x, w) = gauss_legendre_01(WALK_EDGE_POINTS);
    row.iter_mut().for_each(|v| *v = 0.0);
    let (la, ha) = a.cell;
    let (lb, hb) = b.cell;
    for (xa, wa) in x.iter().zip(&w) {
        let sa = State {
            mu: la + (ha - la) * xa,
            ..*a
        };
        let sc = s.scatter_from(-sa.dir(1.0, 0.0), a.outside);
        let cut = (-e.0 * sa.mu / e.1).clamp(lb, hb);
        for (p0, p1) in [(lb, cut), (cut, hb)] {
            if p1 <= p0 {
                continue;
            }
            for (xb, wb) in x.iter().zip(&w) {
                let sb = State {
                    mu: p0 + (p1 - p0) * xb,
                    ..*b
                };
                let weight = wa * wb * (p1 - p0) / (hb - lb);
                for (v, &(c, sn)) in row.iter_mut().zip(phis) {
                    *v += weight * kernel(&sc, a, b, sb.dir(c, sn));
                }
            }
        }
    }
}

/// `P_m` for every order (module doc), as `orders` matrices `N x N`.
fn phase_matrices(s: &Microsurface, st: &[State], orders: usize, q: usize) -> Vec<DMatrix<f64>> {
    phase_matrices_from(s, st, 0, orders, q)
}

/// `P_m` for the orders `from..orders` (the azimuth rule of `orders`).
fn phase_matrices_from(s: &Microsurface, st: &[State], from: usize, orders: usize, q: usize) -> Vec<DMatrix<f64>> {
    // A row's Fourier coefficients: one matrix product with the rule's
    // weighted cosines (blocked and vectorised by nalgebra), the uniform
    // panels by FFT for long series (the outside chain's up to 640 orders:
    // its product took 0.16 s of glossy's build on one thread).
    let projection = RuleProjection::new(orders, q, from);
    let n = st.len();
    let cols = kernel_coefficients(s, st, &projection, true);
    (0..orders - from)
        .map(|m| DMatrix::from_fn(n, n, |b, a| cols[a][(b, m)]))
        .collect()
}

/// The Fourier coefficients of the chain's kernel from every state `a`
/// (one matrix each: rows the states `b`, columns the orders of
/// `projection`, from samples at the azimuths of its rule), the
/// cells across an edge averaged (GGX). With `reciprocal`, only one of each
/// pair of reverse paths is evaluated: light from `a` to `b` and light
/// from `b` reversed (`rev b`: the same node, the other way up) to `a`
/// reversed take the same micro-normal, and `density * norm` is `D F / 4`
/// in reflection and `D (1 - F) |i.h| |o.h| eta_l^2 / (i.h + eta_l o.h)^2`
/// in refraction, whose reverse has `1 / eta_l` for `eta_l`. So `K(a, b) =
/// K(rev b, rev a) N(rev b) / N(a)` times `eta_l(a)^2` if the path crosses
/// the face (`eta_l` the index beyond the face over `a`'s side's), at the
/// same azimuth difference (an isotropic face: reversing both directions
/// turns it by `pi` and changes its sign), hence with the same Fourier
/// coefficients. Half the evaluations and half the projections; the unit
/// test `reverse_paths_are_reciprocal` checks it against direct
/// evaluation. Only the coefficients are kept: the full chain's samples
/// were 73 MB per face (48 orders against 248 azimuths), and copying them
/// took 3.8% of glossy's build (perf, one thread).
fn kernel_coefficients(
    s: &Microsurface,
    st: &[State],
    projection: &RuleProjection,
    reciprocal: bool,
) -> Vec<DMatrix<f64>> {
    let phis = projection.phis();
    let n = st.len();
    let n_phi = phis.len();
    let scatterers: Vec<Scatterer> = st.iter().map(|a| s.scatter_from(-a.dir(1.0, 0.0), a.outside)).collect();
    // The reverse of each state (the same side and node, the other way up).
    let rev: Vec<Option<usize>> = st
        .iter()
        .map(|a| {
            st.iter()
                .position(|b| b.outside == a.outside && b.mu == a.mu && b.up != a.up)
        })
        .collect();
    // Pair (a, b) is evaluated unless its reverse (rev b, rev a) is, by the
    // rule `a <= rev b` (exactly one of two distinct reverse pairs meets it;
    // a pair that is its own reverse does).
    let evaluated = |a: usize, b: usize| !reciprocal || rev[b].is_none_or(|rb| a <= rb) || rev[a].is_none();
    let direct: Vec<DMatrix<f64>> = (0..n)
        .into_par_iter()
        .map(|a| {
            let sc = &scatterers[a];
            let sa = &st[a];
            let rows: Vec<usize> = (0..n).filter(|&b| evaluated(a, b)).collect();
            let vals = DMatrix::from_fn(rows.len(), n_phi, |r, k| {
                let b = &st[rows[r]];
                let (c, sn) = phis[k];
                kernel(sc, sa, b, b.dir(c, sn))
            });
            let coef = projection.project(&vals);
            let mut out = DMatrix::zeros(n, coef.ncols());
            for (r, &b) in rows.iter().enumerate() {
                out.row_mut(b).copy_from(&coef.row(r));
            }
            out
        })
        .collect();
    // Beckmann's D vanishes at a horizontal micro-normal: no edges.
    let ggx = s.mf.dist == Distribution::Ggx;
    (0..n)
        .into_par_iter()
        .map(|a| {
            let sa = &st[a];
            let mut coef = direct[a].clone();
            let na = scatterers[a].norm();
            for b_idx in 0..n {
                if evaluated(a, b_idx) {
                    continue;
                }
                let (Some(rb), Some(ra)) = (rev[b_idx], rev[a]) else {
                    continue;
                };
                let factor = if na > 0.0 {
                    let crossing = if sa.outside == st[b_idx].outside {
                        1.0
                    } else if sa.outside {
                        s.eta * s.eta
                    } else {
                        1.0 / (s.eta * s.eta)
                    };
                    crossing * scatterers[rb].norm() / na
                } else {
                    0.0
                };
                let reverse = direct[rb].row(ra) * factor;
                coef.row_mut(b_idx).copy_from(&reverse);
            }
            if ggx {
                let mut row = vec![0.0; n_phi];
                for (b_idx, b) in st.iter().enumerate() {
                    let e = edge_coefficients(s, sa, b);
                    if edge_crosses(e, sa, b) {
                        edge_average(s, sa, b, e, phis, &mut row);
                        let c = projection.project(&DMatrix::from_row_slice(1, n_phi, &row));
                        coef.row_mut(b_idx).copy_from(&c.row(0));
                    }
                }
            }
            coef
        })
        .collect()
}

/// The layer of order `m` from `X` (rows: exit states, columns: arrival
/// states; module doc's `K_m[b][a]`; `X = P` gives order 1).
fn to_layer(s: &Microsurface, st: &[State], x: &DMatrix<f64>, m: usize, no: usize, ni: usize) -> Layer {
    // Index ranges of the four hemispheres.
    let (o_up, o_dn, i_up, i_dn) = (0, no, 2 * no, 2 * no + ni);
    let sign = if m % 2 == 1 { -1.0 } else { 1.0 };
    let block = |rows: usize, nr: usize, cols: usize, nc: usize, sg: f64| {
        DMatrix::from_fn(nr, nc, |b, a| {
            let (sb, sa) = (&st[rows + b], &st[cols + a]);
            sg * sa.w * sa.mu / sb.mu * s.g1(sb.mu) * x[(rows + b, cols + a)]
        })
    };
    Layer {
        r_top: block(o_up, no, o_dn, no, 1.0),
        t_down: block(i_up, ni, o_dn, no, sign),
        r_bot: block(i_up, ni, i_dn, ni, 1.0),
        t_up: block(o_up, no, i_dn, ni, sign),
    }
}

/// Order 1 of the walk on the grids (Walter's face with the exact Smith
/// `G1`, unnormalised), for checking the chain's conventions against
/// [`crate::interface`]'s projection of `RoughDielectric::eval_mode`.
pub fn single_scattering(
    mf: Microfacet,
    eta: f64,
    outside: &Grid,
    inside: &Grid,
    orders: usize,
    q: usize,
) -> Vec<Layer> {
    let s = Microsurface::new(mf, eta);
    let st = states(outside, inside);
    let p = phase_matrices(&s, &st, orders, q);
    p.iter()
        .enumerate()
        .map(|(m, pm)| to_layer(&s, &st, pm, m, outside.len(), inside.len()))
        .collect()
}

/// The walk's orders >= 2 for the face of distribution `mf` and relative
/// index `eta` between the grids `outside` (air) and `inside`, scaled so that
/// the albedo of every node is `lost[0][j]` (outside nodes) or
/// `lost[1][j]` (inside nodes): the energy Walter's projected face loses
/// (module doc). `orders` Fourier orders, `q` points per azimuth panel.
pub fn multiple_scattering(
    mf: Microfacet,
    eta: f64,
    outside: &Grid,
    inside: &Grid,
    orders: usize,
    q: usize,
    lost: [&[f64]; 2],
) -> Result<WalkFace, SlabError> {
    let [lost_out, lost_in] = lost;
    let s = Microsurface::new(mf, eta);
    let st = states(outside, inside);
    let (no, ni) = (outside.len(), inside.len());
    let p = phase_matrices(&s, &st, orders, q);
    let layers: Vec<Layer> = scattered_twice_or_more(&s, &st, &p, "the microsurface walk's chain")?
        .par_iter()
        .enumerate()
        .map(|(m, x)| symmetrised(to_layer(&s, &st, x, m, no, ni), outside, inside))
        .collect();
    let raw_albedo = albedos(&layers[0], outside, inside);
    // Nodes the discretised walk does not resolve (module doc) keep their
    // loss for the caller; the walk is scaled to the others.
    let lost_all: Vec<f64> = lost_out.iter().chain(lost_in).copied().collect();
    let unresolved: Vec<f64> = lost_all
        .iter()
        .zip(&raw_albedo)
        .map(|(&t, &a)| if t > 0.0 && a < MIN_RESOLVED * t { t } else { 0.0 })
        .collect();
    let target: Vec<f64> = lost_all.iter().zip(&unresolved).map(|(t, u)| t - u).collect();
    let (t_out, t_in) = target.split_at(no);
    let scale = symmetric_scaling(&layers[0], outside, inside, t_out, t_in)?;
    let mut layers = layers;
    for l in layers.iter_mut() {
        scale_layer(l, &scale, no);
    }
    let share = |t: &DMatrix<f64>, from: &Grid, to: &Grid, lost: &[f64]| -> f64 {
        let total: f64 = (0..from.len()).map(|j| from.w[j] * from.mu[j] * lost[j]).sum();
        if total <= 0.0 {
            return 0.0;
        }
        let tr: f64 = (0..from.len())
            .map(|j| (0..to.len()).map(|o| to.w[o] * to.mu[o] * t[(o, j)]).sum::<f64>())
            .sum();
        tr / total
    };
    let k = (
        share(&layers[0].t_down, outside, inside, t_out),
        share(&layers[0].t_up, inside, outside, t_in),
    );
    let (u_out, u_in) = unresolved.split_at(no);
    Ok(WalkFace {
        orders: layers,
        raw_albedo,
        scale,
        k,
        unresolved: (u_out.to_vec(), u_in.to_vec()),
    })
}

/// The walk's reflection from outside (`r_top`, orders >= 2) for the
/// Fourier orders `orders` (with the azimuth rule of `orders.end`), from the
/// chain restricted to the outside states: the light that refracts into the
/// face's dielectric on the way is left out. For the orders above those
/// that carry the energy (the `slab` model's forward peak at grazing
/// incidence on a smooth face, `crate::interface`) that light is broad in
/// azimuth (two refractions): luster's orders 48 to 96 from this chain are
/// within 8e-6 of the full chain's in the BSDF (tests/walk_orders.rs).
/// [`multiple_scattering`]'s full chain gives the lower orders. Made
/// reciprocal as the full chain's and scaled by `scale_out`, the full
/// chain's factors of the outside nodes ([`WalkFace::scale`]). Only the
/// outside nodes below `mu_max` take part (the grazing ones, where the
/// walk's light is narrow in azimuth); the matrices are 0 at the others.
pub fn outside_reflection(
    mf: Microfacet,
    eta: f64,
    outside: &Grid,
    orders: std::ops::Range<usize>,
    q: usize,
    scale_out: &[f64],
    mu_max: f64,
) -> Result<Vec<DMatrix<f64>>, SlabError> {
    let s = Microsurface::new(mf, eta);
    let no_all = outside.len();
    // The outside nodes below `mu_max` (ascending, so the first `no`).
    let no = outside.mu.iter().filter(|&&mu| mu < mu_max).count();
    let cells_out = cells(outside, no);
    let cells_out = &cells_out;
    let st: Vec<State> = [true, false]
        .into_iter()
        .flat_map(|up| {
            (0..no).map(move |j| State {
                outside: true,
                up,
                mu: outside.mu[j],
                w: outside.w[j],
                cell: cells_out[j],
            })
        })
        .collect();
    let p = phase_matrices_from(&s, &st, orders.start, orders.end, q);
    let wt = outside.reciprocity_weights();
    let xs = scattered_twice_or_more(&s, &st, &p, "the microsurface walk's chain outside the face")?;
    Ok(xs
        .par_iter()
        .map(|x| {
            // r_top: exit states going up (0..no), arrivals going down (no..2 no).
            let r = DMatrix::from_fn(no, no, |b, a| {
                let (sb, sa) = (&st[b], &st[no + a]);
                sa.w * sa.mu / sb.mu * s.g1(sb.mu) * x[(b, no + a)]
            });
            DMatrix::from_fn(no_all, no_all, |o, j| {
                if o < no && j < no {
                    0.5 * (r[(o, j)] + wt[j] * r[(j, o)] / wt[o]) * scale_out[o] * scale_out[j]
                } else {
                    0.0
                }
            })
        })
        .collect())
}

/// The chain's light scattered twice or more before its escape, per order
/// (module doc): `X = (I - M)^-1 M P` with `M = P diag(w_a C_a)`, for the
/// states `st` and their phase matrices `p`; `step` names the chain in the
/// error of a singular system.
fn scattered_twice_or_more(
    s: &Microsurface,
    st: &[State],
    p: &[DMatrix<f64>],
    step: &'static str,
) -> Result<Vec<DMatrix<f64>>, SlabError> {
    let n = st.len();
    let cont: Vec<f64> = st
        .iter()
        .map(|a| a.w * if a.up { 1.0 - s.g1(a.mu) } else { 1.0 })
        .collect();
    p.par_iter()
        .map(|pm| {
            let mut mm = pm.clone();
            for (a, c) in cont.iter().enumerate() {
                mm.column_mut(a).scale_mut(*c);
            }
            let rhs = &mm * pm;
            let a = DMatrix::identity(n, n) - &mm;
            crate::linalg::solve(a, &rhs).ok_or(SlabError::Singular { step })
        })
        .collect()
}

/// The layer made exactly reciprocal: each block averaged with its image
/// under the relations of [`crate::layer`] (`W R` symmetric,
/// `W_bot T_down = (W_top T_up)^T`, `W = diag(w mu / eta^2)`).
fn symmetrised(l: Layer, top: &Grid, bot: &Grid) -> Layer {
    let (wt, wb) = (top.reciprocity_weights(), bot.reciprocity_weights());
    let refl = |r: &DMatrix<f64>, w: &[f64]| {
        DMatrix::from_fn(r.nrows(), r.ncols(), |o, j| 0.5 * (r[(o, j)] + w[j] * r[(j, o)] / w[o]))
    };
    // Z = (W_bot T_down + (W_top T_up)^T) / 2.
    let z = DMatrix::from_fn(bot.len(), top.len(), |o, j| {
        0.5 * (wb[o] * l.t_down[(o, j)] + wt[j] * l.t_up[(j, o)])
    });
    Layer {
        r_top: refl(&l.r_top, &wt),
        t_down: DMatrix::from_fn(bot.len(), top.len(), |o, j| z[(o, j)] / wb[o]),
        r_bot: refl(&l.r_bot, &wb),
        t_up: DMatrix::from_fn(top.len(), bot.len(), |o, j| z[(j, o)] / wt[o]),
    }
}

/// Order-0 albedo `R + T` of every node (outside, then inside).
fn albedos(l: &Layer, top: &Grid, bot: &Grid) -> Vec<f64> {
    let col =
        |k: &DMatrix<f64>, to: &Grid, j: usize| (0..to.len()).map(|o| to.w[o] * to.mu[o] * k[(o, j)]).sum::<f64>();
    let out = (0..top.len()).map(|j| (col(&l.r_top, top, j) + col(&l.t_down, bot, j)) / (top.w[j] * top.mu[j]));
    let ins = (0..bot.len()).map(|j| (col(&l.r_bot, bot, j) + col(&l.t_up, top, j)) / (bot.w[j] * bot.mu[j]));
    out.chain(ins).collect()
}

/// Factors `s` (outside nodes, then inside nodes) such that `K[o][j] s_o s_j`
/// has the albedos `target` (a symmetric Sinkhorn iteration; a node whose
/// target is 0 gets factor 0), finished by Newton's method
/// (`interface::newton_scaling`) where the square-root iteration has not
/// converged after [`MAX_SCALING_ITERATIONS`]; refused above
/// `interface::NORMALISATION_SLOW_TOLERANCE`, as the faces' normalisation.
fn symmetric_scaling(l: &Layer, top: &Grid, bot: &Grid, t_out: &[f64], t_in: &[f64]) -> Result<Vec<f64>, SlabError> {
    let target: Vec<f64> = t_out.iter().chain(t_in).copied().collect();
    let mut s: Vec<f64> = target.iter().map(|&t| if t > 0.0 { 1.0 } else { 0.0 }).collect();
    if square_root_scaling(l, top, bot, &target, &mut s, MAX_SCALING_ITERATIONS)? < SCALING_TOLERANCE {
        return Ok(s);
    }
    // Slow: Newton's method from the point the square-root iteration
    // reached. Nodes of target 0 keep their factor 0 (an albedo and a
    // target of 0 are left out).
    let worst = newton_scaling(&scaling_matrix(l, top, bot), &target, &mut s, 0.0, SCALING_TOLERANCE);
    if worst <= NORMALISATION_SLOW_TOLERANCE {
        Ok(s)
    } else {
        Err(unresolved())
    }
}

/// Scales `l`'s blocks by the factors `s` of its nodes (the `no` outside
/// nodes, then the inside ones): `K[o][j] s_o s_j`.
fn scale_layer(l: &mut Layer, s: &[f64], no: usize) {
    let (s_out, s_in) = s.split_at(no);
    scale_rows_cols(&mut l.r_top, s_out, s_out);
    scale_rows_cols(&mut l.t_down, s_in, s_out);
    scale_rows_cols(&mut l.r_bot, s_in, s_in);
    scale_rows_cols(&mut l.t_up, s_out, s_in);
}

/// The square-root (symmetric Sinkhorn) iteration of [`symmetric_scaling`]
/// on the factors `s`, at most `iterations` steps or until every albedo is
/// within [`SCALING_TOLERANCE`] of its target; returns the largest relative
/// error of the last step, an error where an albedo is not positive.
fn square_root_scaling(
    l: &Layer,
    top: &Grid,
    bot: &Grid,
    target: &[f64],
    s: &mut [f64],
    iterations: usize,
) -> Result<f64, SlabError> {
    let (no, ni) = (top.len(), bot.len());
    // Column sums with the current factors: a_j = s_j sum_o w_o mu_o s_o K[o][j] / (w_j mu_j).
    let col = |k: &DMatrix<f64>, to: &Grid, s_to: &[f64], j: usize| -> f64 {
        (0..to.len())
            .map(|o| to.w[o] * to.mu[o] * s_to[o] * k[(o, j)])
            .sum::<f64>()
    };
    let mut worst = f64::INFINITY;
    for _ in 0..iterations {
        let (s_out, s_in) = s.split_at(no);
        let a: Vec<f64> = (0..no)
            .map(|j| s_out[j] * (col(&l.r_top, top, s_out, j) + col(&l.t_down, bot, s_in, j)) / (top.w[j] * top.mu[j]))
            .chain((0..ni).map(|j| {
                s_in[j] * (col(&l.r_bot, bot, s_in, j) + col(&l.t_up, top, s_out, j)) / (bot.w[j] * bot.mu[j])
            }))
            .collect();
        worst = 0.0;
        for ((sj, aj), tj) in s.iter_mut().zip(&a).zip(target) {
            if *tj <= 0.0 {
                continue;
            }
            if !(*aj > 0.0 && aj.is_finite()) {
                return Err(unresolved());
            }
            worst = worst.max((aj / tj - 1.0).abs());
            *sj *= (tj / aj).sqrt();
        }
        if worst < SCALING_TOLERANCE {
            break;
        }
    }
    Ok(worst)
}

/// The albedos of [`symmetric_scaling`] as `s_e sum_k a[(e, k)] s_k`
/// (outside nodes, then inside nodes): `a[(e, k)] = w_k mu_k K[k][e] /
/// (w_e mu_e)` with `K` the block of `l` from node `e` to node `k`.
fn scaling_matrix(l: &Layer, top: &Grid, bot: &Grid) -> DMatrix<f64> {
    let no = top.len();
    let wm = |g: &Grid, k: usize| g.w[k] * g.mu[k];
    DMatrix::from_fn(no + bot.len(), no + bot.len(), |e, k| match (e < no, k < no) {
        (true, true) => wm(top, k) * l.r_top[(k, e)] / wm(top, e),
        (true, false) => wm(bot, k - no) * l.t_down[(k - no, e)] / wm(top, e),
        (false, true) => wm(top, k) * l.t_up[(k, e - no)] / wm(bot, e - no),
        (false, false) => wm(bot, k - no) * l.r_bot[(k - no, e - no)] / wm(bot, e - no),
    })
}

/// The error of a walk the grid does not resolve.
fn unresolved() -> SlabError {
    SlabError::Discretisation {
        name: "nodes",
        value: f64::NAN,
        range: "enough nodes to resolve the rough face's multiple scattering (its scaling to the lost energy did not converge)",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The walk's scaling to the lost energy on faces close to
    /// index-matched (GGX `eta` 1.01 with `m` 0.8, 1.02 with 1.2; grids of
    /// 32 and 16 nodes, as a default `slab` build), where the square-root
    /// iteration crawls: after [`MAX_SCALING_ITERATIONS`] it is still above
    /// [`SCALING_TOLERANCE`] (asserted, so that Newton's path is what is
    /// tested; measured 5.8e-11 and 1.3e-11), and [`symmetric_scaling`]
    /// reaches every target (measured 8e-16 and 1.1e-15), checked by
    /// summing the scaled blocks directly (`albedos`, not `scaling_matrix`).
    /// The targets are those of known factors 2% from 1, so that a solution
    /// exists. (GGX 1.001 with `m` 0.02 is not asked: there the square-root
    /// iteration stops at 1.9e-11 and Newton's method at 3.3e-11 of these
    /// targets, at the rounding of its albedos of 1e-10.)
    #[test]
    fn scaling_close_to_index_matched_is_finished_by_newton() {
        for (eta, m) in [(1.01, 0.8), (1.02, 1.2)] {
            scaling_case(eta, m);
        }
    }

    fn scaling_case(eta: f64, m: f64) {
        let outside = Grid::outside(32);
        let inside = Grid::inside(&outside, eta, 16);
        let s = Microsurface::new(Microfacet::new(Distribution::Ggx, m), eta);
        let st = states(&outside, &inside);
        let (no, ni) = (outside.len(), inside.len());
        let p = phase_matrices(&s, &st, 1, 8);
        let x = scattered_twice_or_more(&s, &st, &p, "test").unwrap();
        let l = symmetrised(to_layer(&s, &st, &x[0], 0, no, ni), &outside, &inside);
        // Targets that factors 2% from 1 reach (a solution exists).
        let known: Vec<f64> = (0..no + ni).map(|k| 1.0 + 0.02 * (k as f64).sin()).collect();
        let mut bent = l.clone();
        scale_layer(&mut bent, &known, no);
        let target = albedos(&bent, &outside, &inside);
        let mut plain: Vec<f64> = target.iter().map(|&t| if t > 0.0 { 1.0 } else { 0.0 }).collect();
        let slow = square_root_scaling(&l, &outside, &inside, &target, &mut plain, MAX_SCALING_ITERATIONS).unwrap();
        let f = symmetric_scaling(&l, &outside, &inside, &target[..no], &target[no..]).unwrap();
        let mut scaled = l.clone();
        scale_layer(&mut scaled, &f, no);
        let now = albedos(&scaled, &outside, &inside);
        let worst = now
            .iter()
            .zip(&target)
            .filter(|(_, t)| **t > 0.0)
            .map(|(a, t)| (a / t - 1.0).abs())
            .fold(0.0, f64::max);
        println!(
            "GGX {eta} {m}: square-root iteration after {MAX_SCALING_ITERATIONS}: {slow:e}; with Newton: {worst:e}"
        );
        assert!(
            slow > SCALING_TOLERANCE,
            "the square-root iteration converged ({slow:e}): Newton's path untested"
        );
        assert!(worst < SCALING_TOLERANCE, "albedos {worst:e} from their targets");
    }

    /// `kernel_coefficients` takes half of the chain's kernel from the
    /// reverse paths (reciprocity); here against every pair evaluated
    /// directly, on the full chain's states (both sides, both ways:
    /// reflection and refraction from either side) and on the outside states
    /// alone, for both distributions, a smooth and a rough face and a dense
    /// medium, in every order of a graded rule (whose points run from `phi`
    /// near 0, where the reflection peaks, to `pi`), by the matrix product
    /// and by the FFT.
    #[test]
    fn reverse_paths_are_reciprocal() {
        let outside = Grid::outside(10);
        let (orders, q) = (16, 2);
        for (dist, m, eta) in [
            (Distribution::Ggx, 0.3, 1.5),
            (Distribution::Beckmann, 0.1, 1.5),
            (Distribution::Ggx, 0.05, 1.33),
            (Distribution::Beckmann, 0.8, 2.0),
        ] {
            let inside = Grid::inside(&outside, eta, 5);
            let s = Microsurface::new(Microfacet::new(dist, m), eta);
            let all = states(&outside, &inside);
            let outside_only: Vec<State> = all.iter().filter(|a| a.outside).copied().collect();
            for (st, fft) in [(&all, false), (&outside_only, true)] {
                let projection = RuleProjection::with_fft(orders, q, 0, fft);
                let fast = kernel_coefficients(&s, st, &projection, true);
                let slow = kernel_coefficients(&s, st, &projection, false);
                let mut worst: f64 = 0.0;
                let mut compared = 0;
                // Rows far below the chain's scale (a narrow lobe's tail,
                // down to subnormal numbers, where the projection's
                // rounding is of the order of the values) are compared
                // with 1e-100 of the largest coefficient.
                let floor = 1e-100 * slow.iter().map(|d| d.amax()).fold(0.0, f64::max);
                for (f, d) in fast.iter().zip(&slow) {
                    for b in 0..st.len() {
                        let row = d.row(b).amax().max(floor);
                        for k in 0..orders {
                            let diff = (f[(b, k)] - d[(b, k)]).abs();
                            if row > 0.0 {
                                worst = worst.max(diff / row);
                                compared += 1;
                            } else {
                                assert_eq!(diff, 0.0, "{dist:?} {m}: a kernel where none is");
                            }
                        }
                    }
                }
                // Rounding (measured 6.5e-15 to 1.2e-10): the two
                // directions' half vectors are normalised from different
                // sums, and `D` amplifies that far in a narrow lobe's tail;
                // an error of the relation is of order 1 (`eta^2`, the
                // norms' ratio: `1 / eta` for `1 / eta^2` gives 0.5).
                println!("{dist:?} {m} eta {eta} fft {fft}: worst {worst:e} of {compared}");
                assert!(compared > 1000, "{compared} coefficients compared");
                assert!(
                    worst < 1e-9,
                    "{dist:?} {m} eta {eta}: reverse paths off by {worst:e} of the row's largest"
                );
            }
        }
    }
}
