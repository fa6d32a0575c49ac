//! Bounded minimisation of a sum of squared residuals in the unit cube.
//!
//! Global stage: uniform random points of the box (plus the default start) are
//! scored and the best become starting points. Local stage: a projected
//! Levenberg-Marquardt iteration (Levenberg 1944, Marquardt 1963; Nocedal &
//! Wright, *Numerical Optimization*, ch. 10) with a forward-difference
//! Jacobian, Marquardt's diagonal scaling, and an active set for parameters
//! pinned at a bound whose gradient points out of the box (the projected
//! gradient of L-BFGS-B); optionally, Broyden rank-one updates between
//! finite-difference Jacobians save model evaluations. The residuals are the weighted log residuals of
//! [`crate::objective`], so the cost is the squared RMS log error.

/// Why a local refinement stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Stop {
    /// The cost decreased by less than the relative tolerance (or the step was
    /// shorter than the step tolerance) on an accepted step, or the cost fell
    /// below the absolute tolerance.
    CostTolerance,
    /// No step along the damped Gauss-Newton direction decreased the cost: a local minimum.
    NoDescent,
    /// The projected gradient vanished.
    Gradient,
    /// The iteration limit was reached first: not converged.
    MaxIterations,
    /// The residuals were not finite at the start.
    Invalid,
}

impl Stop {
    /// Whether the refinement converged.
    pub fn converged(self) -> bool {
        matches!(self, Stop::CostTolerance | Stop::NoDescent | Stop::Gradient)
    }
}

/// Settings of the local refinement.
#[derive(Clone, Copy, Debug)]
pub struct LmSettings {
    /// Maximum number of Jacobian evaluations.
    pub max_iter: usize,
    /// Relative cost decrease below which an accepted step ends the search.
    pub cost_rtol: f64,
    /// Step length (unit-cube norm) below which an accepted step ends the search.
    pub step_tol: f64,
    /// Cost (squared RMS) below which the search ends as converged (default 1e-8: an
    /// RMS log error of 1e-4, a hundred times below the noise of a good measurement).
    pub cost_atol: f64,
    /// Finite-difference step in unit-cube coordinates.
    pub fd_step: f64,
    /// Window (iterations) of the stall test.
    pub stall_window: usize,
    /// The search ends as converged when the cost fell by less than this
    /// fraction over the last [`LmSettings::stall_window`] iterations (the
    /// interpolated boundary tables make the Paper BSDF piecewise smooth, and
    /// near a minimum on a kink the iteration can otherwise creep for hundreds
    /// of steps at a negligible gain).
    pub stall_rtol: f64,
    /// Broyden updates of the Jacobian between finite-difference Jacobians (default 0:
    /// a finite-difference Jacobian every iteration; with the Paper BSDF, whose
    /// boundary integrals are interpolated from tables, updated Jacobians made
    /// the refinement crawl near the minimum).
    pub broyden_steps: usize,
    /// Evaluate the finite-difference Jacobian's columns in parallel (rayon):
    /// for models whose build dominates (the `slab` model's solve), where the
    /// refinement itself is one search and has no other parallelism.
    pub parallel_jacobian: bool,
}

impl Default for LmSettings {
    fn default() -> Self {
        LmSettings {
            max_iter: 500,
            cost_rtol: 1e-7,
            step_tol: 1e-9,
            cost_atol: 1e-8,
            fd_step: 1e-5,
            broyden_steps: 0,
            stall_window: 10,
            stall_rtol: 1e-2,
            parallel_jacobian: false,
        }
    }
}

/// The result of a local refinement.
#[derive(Clone, Debug)]
pub struct LmResult {
    /// Final point (unit cube).
    pub u: Vec<f64>,
    /// Final cost (sum of squared residuals).
    pub cost: f64,
    /// Cost at the start `u0` (clamped to the box; infinite when the residuals were not finite there).
    pub start_cost: f64,
    /// Jacobian evaluations used.
    pub iterations: usize,
    /// Residual evaluations used.
    pub evaluations: usize,
    /// Why it stopped.
    pub stop: Stop,
}

/// Solves `a x = b` (n x n, row-major) by Gaussian elimination with partial pivoting.
/// `None` when singular.
pub fn solve(mut a: Vec<f64>, mut b: Vec<f64>, n: usize) -> Option<Vec<f64>> {
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i * n + col].abs().partial_cmp(&a[j * n + col].abs()).unwrap())?;
        if a[piv * n + col].abs() < 1e-300 {
            return None;
        }
        if piv != col {
            for k in 0..n {
                a.swap(piv * n + k, col * n + k);
            }
            b.swap(piv, col);
        }
        for i in col + 1..n {
            let f = a[i * n + col] / a[col * n + col];
            if f != 0.0 {
                for k in col..n {
                    a[i * n + k] -= f * a[col * n + k];
                }
                b[i] -= f * b[col];
            }
        }
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= a[i * n + k] * x[k];
        }
        x[i] = s / a[i * n + i];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Projected Levenberg-Marquardt from `u0` in [0, 1]^n. `resid(u, out)` fills
/// the `m` residuals and returns false when the model is invalid at `u`.
///
/// The Jacobian is computed by forward differences (`n` residual evaluations)
/// and, between those, updated after each accepted step by Broyden's rank-one
/// formula `J += (dr - J du) du^T / (du^T du)` (as MINPACK's `hybrd`), which
/// costs no evaluation; a fresh finite-difference Jacobian is taken after
/// [`LmSettings::broyden_steps`] updates, when a step with the updated Jacobian
/// fails, and before convergence is declared (every stop criterion is checked
/// with a finite-difference Jacobian).
pub fn levenberg_marquardt(
    resid: &(dyn Fn(&[f64], &mut [f64]) -> bool + Sync),
    u0: &[f64],
    m: usize,
    s: &LmSettings,
) -> LmResult {
    let n = u0.len();
    let mut u: Vec<f64> = u0.iter().map(|x| x.clamp(0.0, 1.0)).collect();
    let mut r = vec![0.0; m];
    let mut evals = 1;
    if !resid(&u, &mut r) {
        return LmResult {
            u,
            cost: f64::INFINITY,
            start_cost: f64::INFINITY,
            iterations: 0,
            evaluations: evals,
            stop: Stop::Invalid,
        };
    }
    let mut cost: f64 = r.iter().map(|x| x * x).sum();
    let start_cost = cost;
    let mut lambda = 1e-3;
    let mut jac = vec![0.0; m * n];
    let mut rt = vec![0.0; m];
    let mut iter = 0;
    let mut fresh = false;
    let mut updates = usize::MAX;
    let mut history: Vec<f64> = Vec::new();
    while iter < s.max_iter {
        iter += 1;
        if !fresh && updates >= s.broyden_steps {
            // Forward-difference Jacobian (backward at the upper bound).
            let column = |j: usize| -> Vec<f64> {
                let h = if u[j] + s.fd_step <= 1.0 { s.fd_step } else { -s.fd_step };
                let mut up = u.clone();
                up[j] += h;
                let mut rj = vec![0.0; m];
                let ok = resid(&up, &mut rj);
                (0..m).map(|i| if ok { (rj[i] - r[i]) / h } else { 0.0 }).collect()
            };
            let columns: Vec<Vec<f64>> = if s.parallel_jacobian {
                use rayon::prelude::*;
                (0..n).into_par_iter().map(column).collect()
            } else {
                (0..n).map(column).collect()
            };
            evals += n;
            for (j, col) in columns.iter().enumerate() {
                for i in 0..m {
                    jac[i * n + j] = col[i];
                }
            }
            fresh = true;
            updates = 0;
        }
        // Stall: the cost fell by less than `stall_rtol` (relative) over the last `stall_window` iterations.
        history.push(cost);
        if fresh && history.len() > s.stall_window {
            let old = history[history.len() - 1 - s.stall_window];
            if old - cost <= s.stall_rtol * cost {
                return LmResult {
                    u,
                    cost,
                    start_cost,
                    iterations: iter,
                    evaluations: evals,
                    stop: Stop::CostTolerance,
                };
            }
        }
        let mut g = vec![0.0; n];
        let mut a = vec![0.0; n * n];
        for i in 0..m {
            let row = &jac[i * n..(i + 1) * n];
            for j in 0..n {
                g[j] += row[j] * r[i];
                for k in j..n {
                    a[j * n + k] += row[j] * row[k];
                }
            }
        }
        for j in 0..n {
            for k in 0..j {
                a[j * n + k] = a[k * n + j];
            }
        }
        // Active set: at a bound with the descent direction pointing out.
        let free: Vec<usize> = (0..n)
            .filter(|&j| !((u[j] <= 0.0 && g[j] > 0.0) || (u[j] >= 1.0 && g[j] < 0.0)))
            .collect();
        let pg: f64 = free.iter().map(|&j| g[j] * g[j]).sum::<f64>().sqrt();
        if free.is_empty() || pg < 1e-14 {
            if fresh {
                return LmResult {
                    u,
                    cost,
                    start_cost,
                    iterations: iter,
                    evaluations: evals,
                    stop: Stop::Gradient,
                };
            }
            updates = usize::MAX;
            continue;
        }
        let nf = free.len();
        loop {
            let mut af = vec![0.0; nf * nf];
            let mut bf = vec![0.0; nf];
            for (p, &j) in free.iter().enumerate() {
                bf[p] = -g[j];
                for (q, &k) in free.iter().enumerate() {
                    af[p * nf + q] = a[j * n + k];
                }
                af[p * nf + p] += lambda * (a[j * n + j] + 1e-12);
            }
            let step = solve(af, bf, nf);
            let mut accepted = false;
            if let Some(d) = step {
                let mut un = u.clone();
                for (p, &j) in free.iter().enumerate() {
                    un[j] = (u[j] + d[p]).clamp(0.0, 1.0);
                }
                evals += 1;
                if resid(&un, &mut rt) {
                    let cn: f64 = rt.iter().map(|x| x * x).sum();
                    if cn < cost {
                        let dec = cost - cn;
                        // Broyden update with the step actually taken.
                        let du: Vec<f64> = (0..n).map(|j| un[j] - u[j]).collect();
                        let dd: f64 = du.iter().map(|x| x * x).sum();
                        if dd > 0.0 {
                            for i in 0..m {
                                let row = &mut jac[i * n..(i + 1) * n];
                                let jd: f64 = row.iter().zip(&du).map(|(a, b)| a * b).sum();
                                let c = (rt[i] - r[i] - jd) / dd;
                                for j in 0..n {
                                    row[j] += c * du[j];
                                }
                            }
                        }
                        let was_fresh = fresh;
                        u = un;
                        std::mem::swap(&mut r, &mut rt);
                        cost = cn;
                        lambda = (lambda / 3.0).max(1e-12);
                        accepted = true;
                        fresh = false;
                        updates += 1;
                        if cost <= s.cost_atol {
                            return LmResult {
                                u,
                                cost,
                                start_cost,
                                iterations: iter,
                                evaluations: evals,
                                stop: Stop::CostTolerance,
                            };
                        }
                        if dec <= s.cost_rtol * cost + 1e-30 || dd.sqrt() <= s.step_tol {
                            if was_fresh {
                                return LmResult {
                                    u,
                                    cost,
                                    start_cost,
                                    iterations: iter,
                                    evaluations: evals,
                                    stop: Stop::CostTolerance,
                                };
                            }
                            updates = usize::MAX;
                        }
                    }
                }
            }
            if accepted {
                break;
            }
            if !fresh {
                // The updated Jacobian misled the step: take a fresh one before damping more.
                updates = usize::MAX;
                break;
            }
            lambda *= 4.0;
            if lambda > 1e12 {
                return LmResult {
                    u,
                    cost,
                    start_cost,
                    iterations: iter,
                    evaluations: evals,
                    stop: Stop::NoDescent,
                };
            }
        }
    }
    LmResult {
        u,
        cost,
        start_cost,
        iterations: iter,
        evaluations: evals,
        stop: Stop::MaxIterations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_linear_system() {
        let x = solve(vec![2.0, 1.0, 1.0, 3.0], vec![3.0, 5.0], 2).unwrap();
        assert!((x[0] - 0.8).abs() < 1e-12 && (x[1] - 1.4).abs() < 1e-12);
    }

    #[test]
    fn rosenbrock_in_the_box() {
        // Rosenbrock residuals (10 (y - x^2), 1 - x) with x = 4u - 2: minimum at x = y = 1 (u = 0.75).
        let f = |u: &[f64], out: &mut [f64]| {
            let (x, y) = (4.0 * u[0] - 2.0, 4.0 * u[1] - 2.0);
            out[0] = 10.0 * (y - x * x);
            out[1] = 1.0 - x;
            true
        };
        let r = levenberg_marquardt(&f, &[0.1, 0.9], 2, &LmSettings::default());
        assert!(r.stop.converged(), "{:?}", r.stop);
        assert!(
            (r.u[0] - 0.75).abs() < 1e-5 && (r.u[1] - 0.75).abs() < 1e-5,
            "{:?}",
            r.u
        );
    }

    #[test]
    fn parallel_jacobian_takes_the_same_path() {
        // The columns are the same numbers whichever thread computes them, so
        // the iterates, the cost and the evaluation count are identical.
        let f = |u: &[f64], out: &mut [f64]| {
            let (x, y, z) = (4.0 * u[0] - 2.0, 4.0 * u[1] - 2.0, u[2]);
            out[0] = 10.0 * (y - x * x);
            out[1] = 1.0 - x;
            out[2] = (z - 0.3) * (1.0 + x * x);
            true
        };
        let serial = levenberg_marquardt(&f, &[0.1, 0.9, 0.8], 3, &LmSettings::default());
        let par = LmSettings {
            parallel_jacobian: true,
            ..LmSettings::default()
        };
        let parallel = levenberg_marquardt(&f, &[0.1, 0.9, 0.8], 3, &par);
        assert!(serial.stop.converged(), "{:?}", serial.stop);
        assert_eq!(serial.u, parallel.u);
        assert_eq!(serial.cost, parallel.cost);
        assert_eq!(serial.evaluations, parallel.evaluations);
        assert!((serial.u[2] - 0.3).abs() < 1e-6, "{:?}", serial.u);
    }

    #[test]
    fn minimum_outside_the_box_stops_at_the_bound() {
        // Residual u - 2: the constrained minimum in [0, 1] is u = 1.
        let f = |u: &[f64], out: &mut [f64]| {
            out[0] = u[0] - 2.0;
            true
        };
        let r = levenberg_marquardt(&f, &[0.2], 1, &LmSettings::default());
        assert!(r.stop.converged());
        assert!((r.u[0] - 1.0).abs() < 1e-12);
    }
}
