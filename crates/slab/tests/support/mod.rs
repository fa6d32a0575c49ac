//! What the slab crate's integration tests share: the reciprocity measure of
//! a layer's matrices, the simulator's totals for collimated light, a
//! deterministic rule for the integral of a BSDF over the outgoing
//! direction, a sheet built with the default and with `k` times the nodes, and
//! the directions around the lobes of `two_crossings` ([`lobe_points`]),
//! a sheet given two alike faces ([`with_both_faces`]), and a thin coated
//! sheet ([`thin_coated_sheet`]).
#![allow(dead_code)]

pub mod lobe_points;
pub mod thin_coated;

use nalgebra::DMatrix;
use paperbsdf_core::{DVec3, Distribution, PaperParams};
use paperbsdf_sim::{simulate_totals, Incidence, SimConfig, Slab};
use paperbsdf_slab::{Grid, Layer};
use std::f64::consts::PI;

/// Largest asymmetry of `W_a K_ab` against `(W_b K_ba)^T`, relative to the largest entry.
pub fn asymmetry(wa: &[f64], kab: &DMatrix<f64>, wb: &[f64], kba: &DMatrix<f64>) -> f64 {
    let a = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(wa)) * kab;
    let b = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(wb)) * kba;
    (&a - b.transpose()).amax() / a.amax().max(b.amax()).max(1e-300)
}

/// The largest asymmetry of a layer's reflections (each side with itself) and
/// of its two transmissions (against each other), `top` and `bot` its grids.
pub fn layer_asymmetry(l: &Layer, top: &Grid, bot: &Grid) -> f64 {
    let (wt, wb) = (top.reciprocity_weights(), bot.reciprocity_weights());
    asymmetry(&wt, &l.r_top, &wt, &l.r_top)
        .max(asymmetry(&wb, &l.r_bot, &wb, &l.r_bot))
        .max(asymmetry(&wb, &l.t_down, &wt, &l.t_up))
}

/// The simulator's reflectance and transmittance of `slab` for collimated
/// light from `wi` (`walks` walks in 16 batches, `seed`), channel 0:
/// `(R, stderr R, T, stderr T)`.
pub fn simulated_totals(slab: &Slab, wi: DVec3, walks: u64, seed: u64) -> (f64, f64, f64, f64) {
    let cfg = SimConfig {
        samples: walks,
        batches: 16,
        seed,
        ..Default::default()
    };
    let s = simulate_totals(slab, Incidence::Collimated(wi), &cfg).unwrap();
    (
        s.reflectance.mean.0[0],
        s.reflectance.stderr.0[0],
        s.transmittance.mean.0[0],
        s.transmittance.stderr.0[0],
    )
}

/// `int eval(wi, wo) |cos wo| dwo` over both hemispheres by a deterministic
/// rule: in `mu_o` Gauss-Legendre (`per` points) on each interval between the
/// table's nodes and `mu_i` (the table's triangles are linear in `mu_o`
/// there: their diagonal crosses the interval holding `mu_i` at `mu_o =
/// mu_i`; times the crossing shapes, linear on finer steps, the rule is
/// nearly exact) and on `[0, mu_0]`, each interval also split
/// in `split` equal parts (for the analytic face's lobe); in azimuth the
/// midpoint rule with `n_phi` points, exact for the table's Fourier sum when
/// `n_phi` exceeds its highest order (`sum_k cos(m phi_k)` vanishes unless
/// `n_phi` divides `m`: with 96 points the walk's order 96, of the default
/// 256 `SlabOptions::walk_orders`, read as order 0, -6e-5 at 80 degrees).
pub fn grid_albedo(f: impl Fn(DVec3) -> f64, nodes: &[f64], mu_i: f64, per: usize, split: usize, n_phi: usize) -> f64 {
    let (x, w) = paperbsdf_core::quadrature::gauss_legendre_01(per);
    let mut edges = vec![0.0];
    edges.extend_from_slice(nodes);
    if nodes.iter().all(|&m| (m - mu_i).abs() > 1e-12) && mu_i > nodes[0] && mu_i < 1.0 {
        edges.push(mu_i);
        edges.sort_by(f64::total_cmp);
    }
    let mut total = 0.0;
    for side in [1.0, -1.0] {
        for e in edges.windows(2) {
            let h = (e[1] - e[0]) / split as f64;
            for part in 0..split {
                let a = e[0] + part as f64 * h;
                for (xk, wk) in x.iter().zip(&w) {
                    let mu = a + xk * h;
                    let s = (1.0 - mu * mu).max(0.0).sqrt();
                    let mut ring = 0.0;
                    for k in 0..n_phi {
                        let phi = (k as f64 + 0.5) / n_phi as f64 * 2.0 * PI;
                        let wo = DVec3::new(s * phi.cos(), s * phi.sin(), side * mu);
                        ring += f(wo);
                    }
                    total += wk * h * mu * ring * 2.0 * PI / n_phi as f64;
                }
            }
        }
    }
    total
}

/// The default options of the model `slab` but `k` times their nodes
/// (outside and in the cone of total reflection).
pub fn options_times(k: usize) -> paperbsdf_slab::SlabOptions {
    let base = paperbsdf_slab::SlabOptions::default();
    paperbsdf_slab::SlabOptions {
        nodes: k * base.nodes,
        tir_nodes: k * base.tir_nodes,
        ..base
    }
}

/// The model `slab` of `p` with [`options_times`]`(k)`.
pub fn with_nodes_times(p: &paperbsdf_core::PaperParams, k: usize) -> paperbsdf_slab::SlabBsdf {
    paperbsdf_slab::SlabBsdf::with_options(p, &options_times(k)).unwrap()
}

/// The model `slab` of `p` with the default options and with twice the
/// nodes (outside and in the cone of total reflection): the pair the
/// issue's convergence criterion compares.
pub fn default_and_doubled_nodes(
    p: &paperbsdf_core::PaperParams,
) -> (paperbsdf_slab::SlabBsdf, paperbsdf_slab::SlabBsdf) {
    (with_nodes_times(p, 1), with_nodes_times(p, 2))
}

/// `p` with both faces of index `eta`, roughness `m` and distribution
/// `dist` (the faces close to index-matched of tests/simulator.rs and
/// examples/near_index_*.rs).
pub fn with_both_faces(p: PaperParams, eta: f64, m: f64, dist: Distribution) -> PaperParams {
    PaperParams {
        eta_f: eta,
        eta_b: eta,
        m_f: m,
        m_b: m,
        dist_f: dist,
        dist_b: dist,
        ..p
    }
}

/// The thin coated sheet of `thin_coated.rs` (shared with the CLI's
/// `tests/cli_refine.rs` and `examples/slab_build.rs`).
pub fn thin_coated_sheet() -> PaperParams {
    serde_json::from_str(thin_coated::THIN_COATED_SHEET_JSON).unwrap()
}
