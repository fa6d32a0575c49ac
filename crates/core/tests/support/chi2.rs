//! Chi-square goodness-of-fit test of a direction sampler against its density,
//! in the manner of pbrt-v4's `chi2test` and Mitsuba 3's `ChiSquareTest`.
//!
//! The sphere is cut into `N_COS x N_PHI` bins of equal area (uniform in
//! `cos theta` and `phi`). The expected count of each bin is `n` times the
//! integral of the density over it, by adaptive Simpson quadrature (each bin is
//! first split 4 x 4, or 16 x 16 where more than 1% of the draws landed, so
//! that narrow lobes are seen). One extra cell holds the
//! draws that returned no direction, expected `n (1 - integral of the density)`:
//! a density that does not account for every draw fails. Cells expected to
//! hold fewer than 5 draws are pooled. The test fails when the chi-square
//! p-value is below `SIGNIFICANCE`, or when a draw lands where the density
//! is zero.
#![allow(dead_code)]

use glam::DVec3;
use rand::{Rng, SeedableRng};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::PI;

/// Bins in `cos theta`.
pub const N_COS: usize = 16;
/// Bins in `phi`.
pub const N_PHI: usize = 32;
/// Rejection threshold for the p-value of one test. With a few hundred tests
/// in the suite, a correct sampler fails one of them with probability ~1e-3.
pub const SIGNIFICANCE: f64 = 1e-5;

fn dir(c: f64, phi: f64) -> DVec3 {
    let s = (1.0 - c * c).max(0.0).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), c)
}

/// Where composite Simpson reads the rectangle's edges: a relative `EDGE`
/// inside them, so that a density with a jump on an edge (a tabulated density
/// whose cells line up with the bins, as `paperbsdf_slab`'s) is read on the
/// rectangle's own side. Reading it on the far side biased the integral of
/// such a density by 0.2% (enough to fail the test of the no-direction
/// cell), while moving the nodes by `EDGE` changes a smooth density's
/// integral by about `EDGE` relative.
const EDGE: f64 = 1e-9;

fn simpson_2d(f: &dyn Fn(f64, f64) -> f64, c0: f64, c1: f64, p0: f64, p1: f64, k: usize) -> f64 {
    // Composite Simpson with k (even) intervals per axis.
    let (hc, hp) = ((c1 - c0) / k as f64, (p1 - p0) / k as f64);
    let at = |x0: f64, x1: f64, h: f64, i: usize| {
        if i == 0 {
            x0 + EDGE * (x1 - x0)
        } else if i == k {
            x1 - EDGE * (x1 - x0)
        } else {
            x0 + i as f64 * h
        }
    };
    let wt = |i: usize| {
        if i == 0 || i == k {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        }
    };
    let mut s = 0.0;
    for i in 0..=k {
        for j in 0..=k {
            s += wt(i) * wt(j) * f(at(c0, c1, hc, i), at(p0, p1, hp, j));
        }
    }
    s * hc * hp / 9.0
}

fn adaptive(f: &dyn Fn(f64, f64) -> f64, c0: f64, c1: f64, p0: f64, p1: f64, tol: f64, depth: u32) -> f64 {
    let coarse = simpson_2d(f, c0, c1, p0, p1, 2);
    let fine = simpson_2d(f, c0, c1, p0, p1, 4);
    if depth == 0 || (fine - coarse).abs() <= 15.0 * tol {
        return fine + (fine - coarse) / 15.0;
    }
    let (cm, pm) = (0.5 * (c0 + c1), 0.5 * (p0 + p1));
    let t = tol / 4.0;
    adaptive(f, c0, cm, p0, pm, t, depth - 1)
        + adaptive(f, cm, c1, p0, pm, t, depth - 1)
        + adaptive(f, c0, cm, pm, p1, t, depth - 1)
        + adaptive(f, cm, c1, pm, p1, t, depth - 1)
}

/// Runs the test with `n_samples` draws. `sample` maps three uniform numbers to a
/// unit direction on the sphere (or `None`: absorbed, or a delta lobe that `pdf`
/// does not cover); `pdf` is its solid-angle density. Returns the p-value on
/// success, a description of the failure otherwise.
pub fn chi2_test(
    name: &str,
    sample: impl Fn([f64; 3]) -> Option<DVec3>,
    pdf: impl Fn(DVec3) -> f64,
    n_samples: usize,
    seed: u64,
) -> Result<f64, String> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let nb = N_COS * N_PHI;
    let mut obs = vec![0.0f64; nb + 1];
    for _ in 0..n_samples {
        let u = [rng.gen::<f64>(), rng.gen::<f64>(), rng.gen::<f64>()];
        match sample(u) {
            None => obs[nb] += 1.0,
            Some(w) => {
                if !w.is_finite() || (w.length() - 1.0).abs() > 1e-6 {
                    return Err(format!("{name}: sampled a non-unit direction {w:?}"));
                }
                let ci = (((w.z + 1.0) * 0.5 * N_COS as f64) as usize).min(N_COS - 1);
                let mut phi = w.y.atan2(w.x);
                if phi < 0.0 {
                    phi += 2.0 * PI;
                }
                let pj = ((phi / (2.0 * PI) * N_PHI as f64) as usize).min(N_PHI - 1);
                obs[ci * N_PHI + pj] += 1.0;
            }
        }
    }
    let f = |c: f64, p: f64| {
        let v = pdf(dir(c, p));
        if v.is_finite() {
            v
        } else {
            0.0
        }
    };
    let mut exp = vec![0.0f64; nb + 1];
    let mut total = 0.0;
    for i in 0..N_COS {
        for j in 0..N_PHI {
            let (c0, c1) = (
                -1.0 + 2.0 * i as f64 / N_COS as f64,
                -1.0 + 2.0 * (i + 1) as f64 / N_COS as f64,
            );
            let (p0, p1) = (
                2.0 * PI * j as f64 / N_PHI as f64,
                2.0 * PI * (j + 1) as f64 / N_PHI as f64,
            );
            let mut v = 0.0;
            // A bin holding more than 1% of the draws contains a lobe narrow
            // enough to need a finer pre-split for the quadrature to see it.
            let s = if obs[i * N_PHI + j] > 0.01 * n_samples as f64 {
                16
            } else {
                4
            };
            for a in 0..s {
                for b in 0..s {
                    let (ca, cb) = (
                        c0 + (c1 - c0) * a as f64 / s as f64,
                        c0 + (c1 - c0) * (a + 1) as f64 / s as f64,
                    );
                    let (pa, pb) = (
                        p0 + (p1 - p0) * b as f64 / s as f64,
                        p0 + (p1 - p0) * (b + 1) as f64 / s as f64,
                    );
                    v += adaptive(&f, ca, cb, pa, pb, 1e-7, 9);
                }
            }
            exp[i * N_PHI + j] = v * n_samples as f64;
            total += v;
        }
    }
    if total > 1.0 + 1e-3 {
        return Err(format!("{name}: the density integrates to {total} > 1"));
    }
    exp[nb] = (1.0 - total).max(0.0) * n_samples as f64;
    // Draws where the density is zero. Only the direction bins: the cell of
    // draws that returned no direction is expected to hold n (1 - integral),
    // and where the density's integral is 1 to within the quadrature's error
    // (a density with discontinuities, e.g. a tabulated one) its expectation
    // rounds to 0 while a sampler that loses a tiny fraction of its draws
    // (a reflection below the horizon) still records some: that cell enters
    // the chi-square statistic (pooled with the other small cells) instead.
    if exp[nb] == 0.0 && obs[nb] > 0.0 {
        exp[nb] = f64::MIN_POSITIVE;
    }
    for k in 0..nb {
        if exp[k] == 0.0 && obs[k] > 0.0 {
            return Err(format!(
                "{name}: {} draws in cell {k} where the density is zero",
                obs[k]
            ));
        }
    }
    // Pool small cells (sorted by expected count) until each pooled cell expects >= 5.
    let mut idx: Vec<usize> = (0..=nb).collect();
    idx.sort_by(|a, b| exp[*a].partial_cmp(&exp[*b]).unwrap());
    let (mut chi2, mut dof) = (0.0, 0usize);
    let (mut pool_e, mut pool_o) = (0.0, 0.0);
    for &k in &idx {
        if exp[k] == 0.0 {
            continue;
        }
        if exp[k] < 5.0 || pool_e > 0.0 && pool_e < 5.0 {
            pool_e += exp[k];
            pool_o += obs[k];
            if pool_e >= 5.0 {
                chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
                dof += 1;
                pool_e = 0.0;
                pool_o = 0.0;
            }
            continue;
        }
        chi2 += (obs[k] - exp[k]) * (obs[k] - exp[k]) / exp[k];
        dof += 1;
    }
    if pool_e > 0.0 {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        dof += 1;
    }
    if dof < 2 {
        return Ok(1.0);
    }
    let p = 1.0 - ChiSquared::new((dof - 1) as f64).unwrap().cdf(chi2);
    if p < SIGNIFICANCE {
        return Err(format!("{name}: chi2 = {chi2:.1} with {} dof, p = {p:.3e}", dof - 1));
    }
    Ok(p)
}
