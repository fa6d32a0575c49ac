//! What the slab crate's integration tests share: the reciprocity measure of
//! a layer's matrices, and the simulator's totals for collimated light.
#![allow(dead_code)]

use nalgebra::DMatrix;
use paperbsdf_core::DVec3;
use paperbsdf_sim::{simulate_totals, Incidence, SimConfig, Slab};
use paperbsdf_slab::{Grid, Layer};

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
