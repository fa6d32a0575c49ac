//! What the data determine: a linearised uncertainty of each fitted
//! parameter, from the Jacobian of the weighted log residuals at the fit
//! (Gauss-Newton covariance, as in any nonlinear least-squares text, e.g.
//! Press et al., Numerical Recipes, section 15.5), warnings for parameters that
//! end on a bound of the search box, and checks of degenerate data.
//!
//! With `r` the normalised residuals of [`crate::objective::residuals`]
//! (`sum r^2` = squared weighted RMS error), `N` values, `p` free parameters
//! and `J = dr/du` (central differences, `u` the unit-cube coordinates), the
//! residual scatter estimates the noise, `s^2 = sum r^2 / (N - p)`, and the
//! covariance is `C_u = s^2 (J^T J)^+` (pseudo-inverse from the singular value
//! decomposition; directions whose singular value is below `1e-8` of the
//! largest are taken as undetermined, infinite variance). The standard error
//! of a value is `sqrt(C_u,ii) |dx/du|`. The model's own error counts as noise
//! here, so these are uncertainties given the model, not of the model.
//!
//! A parameter counts as **determined** when its standard error is below
//! [`DETERMINED_FRACTION`] of its search range in unit coordinates (a
//! 2-sigma interval at most a fifth of the box) and it is not on a bound. A
//! parameter **on a bound** (within [`BOUND_TOLERANCE`] of either end of the
//! box) has no meaningful symmetric uncertainty: the data would pull it beyond
//! what the model allows, which usually means the model is compensating for
//! something else; hold it at a plausible value with `--fix`.

use crate::measurement::Point;
use crate::model::{FitModel, Scale};
use crate::objective::residuals;
use nalgebra::DMatrix;

/// Largest standard error, as a fraction of the unit box, of a determined parameter.
pub const DETERMINED_FRACTION: f64 = 0.05;
/// Distance from either end of the unit box below which a parameter is on its bound.
pub const BOUND_TOLERANCE: f64 = 1e-3;

/// One fitted parameter and what the data say about it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ParamReport {
    /// Name as in parameter files.
    pub name: String,
    /// Fitted value.
    pub value: f64,
    /// One-sigma standard error (infinite when undetermined).
    pub stderr: f64,
    /// Standard error in unit-box coordinates.
    pub stderr_unit: f64,
    /// Lower and upper search bounds.
    pub bounds: [f64; 2],
    /// Whether the value is on a bound of the box.
    pub on_bound: bool,
    /// Whether the data determine it (see the module doc).
    pub determined: bool,
}

/// The identifiability report of a fit.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Identifiability {
    /// Per free parameter.
    pub params: Vec<ParamReport>,
    /// Singular values of `J` divided by the largest, descending.
    pub relative_singular_values: Vec<f64>,
    /// Number of parameter combinations the data do not constrain
    /// (relative singular value below 1e-3).
    pub undetermined_combinations: usize,
    /// Residual values `N` and free parameters `p`.
    pub values: usize,
    /// Free parameters.
    pub free_params: usize,
}

/// The report for model `c` at unit coordinates `u`, fitted to `points` with
/// normalised residual weights `sqrt_w` ([`crate::objective::sqrt_weights`]).
pub fn identifiability(
    c: &dyn FitModel,
    u: &[f64],
    points: &[&Point],
    sqrt_w: &[f64],
    channels: usize,
) -> Option<Identifiability> {
    let specs = c.specs();
    let p = specs.len();
    let n = sqrt_w.len();
    let resid = |u: &[f64]| -> Option<Vec<f64>> {
        let model = c.build(&c.values(u)).ok()?;
        let mut out = vec![0.0; n];
        residuals(model.as_ref(), points, sqrt_w, channels, &mut out).then_some(out)
    };
    let r0 = resid(u)?;
    let cost: f64 = r0.iter().map(|x| x * x).sum();
    let mut j = DMatrix::<f64>::zeros(n, p);
    let h = 1e-4;
    for k in 0..p {
        // central difference, one-sided at the box's ends
        let (lo, hi) = ((u[k] - h).max(0.0), (u[k] + h).min(1.0));
        let mut ul = u.to_vec();
        ul[k] = lo;
        let mut uh = u.to_vec();
        uh[k] = hi;
        let (rl, rh) = (resid(&ul)?, resid(&uh)?);
        for i in 0..n {
            j[(i, k)] = (rh[i] - rl[i]) / (hi - lo);
        }
    }
    let svd = j.clone().svd(false, true);
    let sv = &svd.singular_values;
    let vt = svd.v_t.as_ref()?;
    let smax = sv.iter().cloned().fold(0.0, f64::max);
    let dof = n.saturating_sub(p).max(1) as f64;
    let s2 = cost / dof;
    let mut rel: Vec<f64> = sv.iter().map(|s| if smax > 0.0 { s / smax } else { 0.0 }).collect();
    rel.sort_by(|a, b| b.partial_cmp(a).unwrap_or(std::cmp::Ordering::Equal));
    let params = (0..p)
        .map(|k| {
            let mut var = 0.0;
            for (m, &s) in sv.iter().enumerate() {
                let v = vt[(m, k)];
                if s <= 1e-8 * smax {
                    if v.abs() > 1e-6 {
                        var = f64::INFINITY;
                    }
                } else {
                    var += v * v / (s * s);
                }
            }
            let su = (s2 * var).sqrt();
            let spec = &specs[k];
            let x = spec.value(u[k]);
            let dxdu = match spec.scale {
                Scale::Linear => spec.hi - spec.lo,
                Scale::Log => x * (spec.hi / spec.lo).ln(),
            };
            let on_bound = u[k] < BOUND_TOLERANCE || u[k] > 1.0 - BOUND_TOLERANCE;
            ParamReport {
                name: spec.name.clone(),
                value: x,
                stderr: su * dxdu.abs(),
                stderr_unit: su,
                bounds: [spec.lo, spec.hi],
                on_bound,
                determined: !on_bound && su < DETERMINED_FRACTION,
            }
        })
        .collect();
    Some(Identifiability {
        params,
        undetermined_combinations: rel.iter().filter(|&&r| r < 1e-3).count(),
        relative_singular_values: rel,
        values: n,
        free_params: p,
    })
}

/// Refuses data that cannot determine a fit: fewer values than free
/// parameters, no signal (every value zero), or every weight zero. The error
/// says which.
pub fn check_data(points: &[&Point], channels: usize, free_params: usize) -> Result<(), String> {
    let values = points.len() * channels;
    if values < free_params {
        return Err(format!(
            "{} point(s) x {channels} channel(s) = {values} value(s) cannot determine {free_params} free parameters; \
             give more measurements or hold parameters with --fix NAME=VALUE",
            points.len()
        ));
    }
    if points.iter().all(|p| (0..channels).all(|c| p.f.0[c] == 0.0)) {
        return Err("every measured value is zero: there is no signal to fit".into());
    }
    if points
        .iter()
        .all(|p| (0..channels).all(|c| crate::objective::weight(p, c) == 0.0))
    {
        return Err("every point has weight zero: nothing would be fitted".into());
    }
    Ok(())
}

/// The RMS log error above which a fit is refused as meaningless: the model
/// misses the data by a factor e^2.3 = 10 on average.
pub const MEANINGLESS_RMS: f64 = 2.3;
