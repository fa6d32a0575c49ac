//! Precomputed tables of the boundary integrals of [`crate::boundary`], so that
//! building a surface's [`SurfaceIntegrals`] costs microseconds (it is needed in
//! every fit iteration and per texel of a textured material).
//!
//! Layout, per distribution (GGX, then Beckmann): a grid of `N_ETA x N_M` nodes
//! in (eta, m) with `eta = 1 + 4 s^2` and `m = (pi/2) t^2` for `s, t` uniform in
//! [0, 1] (dense where the integrals change fastest: near index matching and
//! near smooth); at each node the four `mu` curves of [`SurfaceIntegrals`]
//! (`att`, `r_out` on the outside grid, `r_in`, `t_in` on the inside grid aligned
//! with the node's critical angle) and the two hemispherical values (`rho_in`,
//! `tbar_in`). Values are little-endian f32 in `data/boundary_tables.bin`,
//! written by `cargo run --release -p paperbsdf-core --example gen_boundary_tables`
//! with the quadrature of [`crate::boundary`] ([`TABLE_QUADRATURE_POINTS`] points
//! per axis). The eta = 1 nodes are the limit eta -> 1+ of a rough face.

use crate::boundary::{MuGrid, SurfaceIntegrals, N_MU};
use crate::microfacet::Distribution;
use std::sync::OnceLock;

/// Nodes in eta.
pub const N_ETA: usize = 49;
/// Nodes in m.
pub const N_M: usize = 49;
/// Quadrature points per axis used to generate the tables.
pub const TABLE_QUADRATURE_POINTS: usize = 160;
/// Number of f32 values per node: four mu curves and two scalars.
pub const NODE_LEN: usize = 4 * N_MU + 2;
/// Number of f32 values in the table file.
pub const TABLE_LEN: usize = 2 * N_ETA * N_M * NODE_LEN;

/// eta of node `i`.
pub fn eta_node(i: usize) -> f64 {
    let s = i as f64 / (N_ETA - 1) as f64;
    1.0 + 4.0 * s * s
}
/// m of node `j`.
pub fn m_node(j: usize) -> f64 {
    let t = j as f64 / (N_M - 1) as f64;
    std::f64::consts::FRAC_PI_2 * t * t
}
/// Offset of node (dist, i, j) in the table.
pub fn node_offset(dist: Distribution, i: usize, j: usize) -> usize {
    let d = match dist {
        Distribution::Ggx => 0,
        Distribution::Beckmann => 1,
    };
    ((d * N_ETA + i) * N_M + j) * NODE_LEN
}

/// Serialises one node's integrals (the generator's format).
pub fn encode_node(s: &SurfaceIntegrals) -> Vec<f32> {
    let mut v = Vec::with_capacity(NODE_LEN);
    for arr in [&s.att_nodes, &s.r_out_nodes, &s.r_in_nodes, &s.t_in_nodes] {
        v.extend(arr.iter().map(|&x| x as f32));
    }
    v.push(s.rho_in as f32);
    v.push(s.tbar_in as f32);
    v
}

static TABLE_BYTES: &[u8] = include_bytes!("../../data/boundary_tables.bin");

fn table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| decode_f32_table(TABLE_BYTES, TABLE_LEN, "boundary_tables.bin"))
}

/// The little-endian `f32` values of a table file compiled into the library
/// (`include_bytes!`), which must hold exactly `len` of them. A wrong size is a
/// build of the library with a stale file, not bad input: it panics, naming
/// the file to regenerate.
pub(crate) fn decode_f32_table(bytes: &[u8], len: usize, file: &str) -> Vec<f32> {
    assert_eq!(bytes.len(), 4 * len, "{file} has the wrong size; regenerate it");
    bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// Fractional grid coordinate and lower index for a value `x` mapped to [0, 1] by `s`.
#[inline]
fn cell(s: f64, n: usize) -> (usize, f64) {
    let x = s.clamp(0.0, 1.0) * (n - 1) as f64;
    let i = (x as usize).min(n - 2);
    (i, x - i as f64)
}

/// The four nodes `(i, j)` around the face `(eta, m)` on a grid of `n_eta` x
/// `n_m` nodes in the coordinates `sqrt((eta - 1) / 4)` and `sqrt(m / (pi / 2))`
/// (those of [`eta_node`], [`m_node`]), with their bilinear weights; values
/// beyond the grid are read at its edge. Shared by these tables and the
/// coarser ones of [`crate::microsurface_tables`].
#[inline]
pub(crate) fn bilinear_corners(eta: f64, m: f64, n_eta: usize, n_m: usize) -> [(usize, usize, f64); 4] {
    let (i, fi) = cell(((eta - 1.0) / 4.0).max(0.0).sqrt(), n_eta);
    let (j, fj) = cell((m / std::f64::consts::FRAC_PI_2).max(0.0).sqrt(), n_m);
    [
        (i, j, (1.0 - fi) * (1.0 - fj)),
        (i, j + 1, (1.0 - fi) * fj),
        (i + 1, j, fi * (1.0 - fj)),
        (i + 1, j + 1, fi * fj),
    ]
}

/// Interpolated integrals of a rough face (`m > 0`, `eta > 1`).
pub fn interpolate(dist: Distribution, eta: f64, m: f64) -> SurfaceIntegrals {
    let t = table();
    interpolate_nodes(eta, m, |i, j| {
        let o = node_offset(dist, i, j);
        let mut v = [0.0; NODE_LEN];
        for (a, b) in v.iter_mut().zip(&t[o..o + NODE_LEN]) {
            *a = *b as f64;
        }
        v
    })
}

/// The integrals stored at node (i, j), on that node's own grid.
fn node_integrals(i: usize, j: usize, v: &[f64; NODE_LEN]) -> SurfaceIntegrals {
    let mut s = SurfaceIntegrals::zeroed(MuGrid::new(eta_node(i).max(1.0 + 1e-9), m_node(j)));
    s.att_nodes.copy_from_slice(&v[0..N_MU]);
    s.r_out_nodes.copy_from_slice(&v[N_MU..2 * N_MU]);
    s.r_in_nodes.copy_from_slice(&v[2 * N_MU..3 * N_MU]);
    s.t_in_nodes.copy_from_slice(&v[3 * N_MU..4 * N_MU]);
    s.rho_in = v[4 * N_MU];
    s.tbar_in = v[4 * N_MU + 1];
    s
}

/// Bilinear interpolation in (eta, m) of the node integrals given by
/// `node(i, j)` (in the layout of [`encode_node`]): each of the four
/// neighbouring nodes' curves is evaluated (cubic, on its own grid) at the
/// nodes of the query surface's own grid, at the same `mu` for the outside
/// curves and aligned with the critical cosine for the inside ones. Exposed so that the interpolation can
/// be checked against nodes computed directly.
pub fn interpolate_nodes(eta: f64, m: f64, node: impl Fn(usize, usize) -> [f64; NODE_LEN]) -> SurfaceIntegrals {
    let corners = bilinear_corners(eta, m, N_ETA, N_M);
    let grid = MuGrid::new(eta, m);
    let mut s = SurfaceIntegrals::zeroed(grid);
    let mut out_mu = [0.0; N_MU];
    let mut in_mu = [0.0; N_MU];
    for k in 0..N_MU {
        out_mu[k] = grid.outside_mu(k);
        in_mu[k] = grid.inside_mu(k);
    }
    for (ci, cj, wk) in corners {
        if wk == 0.0 {
            continue;
        }
        let c = node_integrals(ci, cj, &node(ci, cj));
        let mu_c = c.grid.mu_c;
        for k in 0..N_MU {
            let (att, r_out) = c.att_r_out(out_mu[k]);
            s.att_nodes[k] += wk * att;
            s.r_out_nodes[k] += wk * r_out;
            // Inside, the kink of total internal reflection moves with eta: the
            // corner is read at the same position relative to its own critical cosine.
            let mu = in_mu[k];
            let mu_corner = if mu < grid.mu_c {
                mu / grid.mu_c * mu_c
            } else if grid.mu_c < 1.0 {
                mu_c + (mu - grid.mu_c) / (1.0 - grid.mu_c) * (1.0 - mu_c)
            } else {
                1.0
            };
            let (r_in, t_in) = c.r_t_in(mu_corner);
            s.r_in_nodes[k] += wk * r_in;
            s.t_in_nodes[k] += wk * t_in;
        }
        s.rho_in += wk * c.rho_in;
        s.tbar_in += wk * c.tbar_in;
    }
    s
}
