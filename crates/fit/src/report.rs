//! What the data determine: for each fitted parameter the range of values
//! that fit the data as well as the model can be trusted to (its **model-error
//! interval**), a linearised standard error from the data's noise, warnings
//! for parameters that end on a bound of the search box, and checks of
//! degenerate data.
//!
//! # Why the noise alone is not the uncertainty
//!
//! The model is an approximation: against the exact simulation of the same
//! slab it misses by an RMS log error of about 0.01 to 0.05 in reflection and
//! 0.03 to 0.1 in transmission (docs/accuracy.md). Part of that error looks
//! like a change of parameters, and the fit absorbs it by moving them: on the
//! bundled matte set the model at the generating parameters misses the data
//! by 0.047 and the fit, with `sigma_s` 58 instead of 140 /mm, `eta_b` 1.07
//! instead of 1.5 and `m_b` 0.11 instead of 0.4, by 0.015. A covariance
//! `s^2 (J^T J)^+` treats the residual left at the fit as independent noise;
//! the part of the model's error that the parameters absorbed is not in that
//! residual, so such parameters looked determined to 1-2% of their value.
//!
//! # The model-error interval
//!
//! With `E(u)^2` the squared weighted RMS log error at unit coordinates `u`
//! (the cost of [`crate::objective::residuals`]), `E0` its value at the fit
//! and `eps` the model error scale (below), the interval of parameter `k` is
//! the set of values `x_k` whose **profile** error, the error refitted over
//! all other parameters with `x_k` held, satisfies
//!
//! `min over the others of E^2  <=  E0^2 + eps^2`.
//!
//! If the model at the true parameters misses the data by at most
//! `sqrt(E0^2 + eps^2)` (its own error plus the noise), the true value of
//! every parameter lies in its interval, however the parameters trade off:
//! holding `x_k` at the truth, the refit can do at least as well as the truth.
//! This is a bound, not a standard deviation; it is the identifiability the
//! model's accuracy allows, whatever the noise.
//!
//! The scale is `eps = max(MODEL_ERROR_RMS, E0)`: [`MODEL_ERROR_RMS`] = 0.05,
//! the upper end of the model's documented reflection error (reflection
//! dominates the weighted error, its relative standard errors being the
//! smaller), overridable with [`ReportSettings::model_error`]; a fit that
//! leaves a larger error `E0` shows that the model misses these data by at
//! least that much, and the scale grows with it.
//!
//! Computation (cheap, a fraction of a fit): the Jacobian `J = dr/du` at the
//! fit (central differences) gives the linearised interval `u_k +- eps
//! sqrt((J^T J)^+_kk)`, the interval of the quadratic approximation of the
//! profile. Where that is narrow enough to matter (at most twice the
//! determined width), each end is checked with true profile refits
//! (Levenberg-Marquardt over the other parameters, from the linearised profile
//! path): an end where the profile is still below the level is pushed out
//! (doubling the distance) until it is above it or at the bound of the box,
//! an end where it is above is tried at half the distance. The reported end
//! is a point where the profile was found above the level, or the bound of
//! the box, or (when the interval is already too wide for the parameter to be
//! determined) where the search stopped, the interval being at least that
//! wide. A refit that stops short of the profile's minimum overstates the
//! profile there, which could only make an interval too narrow at the final
//! halving; the refits start on the linearised profile path or from the
//! previous profile point (continuation) to keep that from happening, and a
//! refit ends as soon as it finds a point below the level (only which side of
//! the level the profile is on matters). The
//! other intervals stay linearised ([`IntervalMethod::Linear`]) and are too
//! wide to make the parameter determined. [`ReportSettings::profile`] =
//! false skips the refits (linearised intervals only: faster, but they can
//! be too narrow where the error surface is flatter than quadratic).
//!
//! A parameter counts as **determined** when its interval spans at most
//! [`DETERMINED_WIDTH`] of its search range in unit coordinates (a fifth of
//! the box: for a log-scale parameter such as `sigma_s` in [1, 3000] about a
//! factor 2.2 overall) and it is not on a bound. A parameter **on a bound**
//! (within [`BOUND_TOLERANCE`] of either end of the box) has no meaningful
//! interval: the data would pull it beyond what the model allows, which
//! usually means the model is compensating for something else. Hold
//! undetermined and bound parameters at plausible values with `--fix`.
//!
//! # The noise standard error
//!
//! Beside the interval, `stderr` is the usual linearised standard error from
//! the residual scatter (Gauss-Newton covariance, e.g. Press et al., Numerical
//! Recipes, section 15.5): `s^2 = E0^2 / (N - p)` with `N` values and `p` free
//! parameters, `C_u = s^2 (J^T J)^+` (pseudo-inverse from the singular value
//! decomposition; directions whose singular value is below `1e-8` of the
//! largest are undetermined, infinite variance), `stderr = sqrt(C_u,kk)
//! |dx/du|`. It is what the noise of the data alone would allow, given that the
//! model were exact; it is not the uncertainty of the parameter.

use crate::error::FitError;
use crate::measurement::Point;
use crate::model::{FitModel, Scale};
use crate::objective::residuals;
use crate::optimize::{levenberg_marquardt, LmSettings};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Largest width, as a fraction of the unit box, of the model-error interval of a determined parameter.
pub const DETERMINED_WIDTH: f64 = 0.2;
/// Distance from either end of the unit box below which a parameter is on its bound.
pub const BOUND_TOLERANCE: f64 = 1e-3;
/// The default model error scale: an RMS log error of 5%, the upper end of the
/// model's documented error in reflection against the exact simulation (docs/accuracy.md).
pub const MODEL_ERROR_RMS: f64 = 0.05;

/// How the report is computed.
#[derive(Clone, Copy, Debug)]
pub struct ReportSettings {
    /// The model error scale (RMS log error); the scale used is the larger of this and the fit's error.
    pub model_error: f64,
    /// Check the ends of the narrow intervals with profile refits (see the module doc).
    pub profile: bool,
    /// Settings of the profile refits.
    pub lm: LmSettings,
}

impl Default for ReportSettings {
    fn default() -> Self {
        ReportSettings {
            model_error: MODEL_ERROR_RMS,
            profile: true,
            lm: LmSettings {
                max_iter: 50,
                cost_rtol: 1e-4,
                ..LmSettings::default()
            },
        }
    }
}

/// How a model-error interval was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum IntervalMethod {
    /// Both ends checked by profile refits.
    Profile,
    /// The linearised interval (not checked: too wide to make the parameter determined, or profiles off).
    Linear,
}

/// One fitted parameter and what the data say about it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ParamReport {
    /// Name as in parameter files.
    pub name: String,
    /// Fitted value.
    pub value: f64,
    /// The model-error interval `[lo, hi]` (see the module doc), within the search bounds.
    pub interval: [f64; 2],
    /// Its width as a fraction of the search range in unit coordinates (infinite when unconstrained).
    pub interval_width_unit: f64,
    /// How the interval was found.
    pub interval_method: IntervalMethod,
    /// One-sigma standard error from the noise alone, the model taken as exact (infinite when undetermined).
    pub stderr: f64,
    /// That standard error in unit-box coordinates.
    pub stderr_unit: f64,
    /// Lower and upper search bounds.
    pub bounds: [f64; 2],
    /// Whether the value is on a bound of the box.
    pub on_bound: bool,
    /// Whether the data determine it: interval at most [`DETERMINED_WIDTH`] of the box, not on a bound.
    pub determined: bool,
}

/// The identifiability report of a fit.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Identifiability {
    /// Per free parameter.
    pub params: Vec<ParamReport>,
    /// The model error scale `eps` used for the intervals (RMS log error).
    pub model_error_scale: f64,
    /// The error level of the intervals, `sqrt(E0^2 + eps^2)`.
    pub interval_level: f64,
    /// Singular values of `J` divided by the largest, descending.
    pub relative_singular_values: Vec<f64>,
    /// Number of parameter combinations the data do not constrain
    /// (relative singular value below 1e-3).
    pub undetermined_combinations: usize,
    /// Residual values `N` and free parameters `p`.
    pub values: usize,
    /// Free parameters.
    pub free_params: usize,
    /// Profile refits made and the residual evaluations they used.
    pub profile_refits: usize,
    /// Residual evaluations of the report (Jacobian and profiles).
    pub evaluations: usize,
}

/// What the `identifiability` section of FIT.json means (written beside it).
pub const UNCERTAINTY_DEFINITION: &str = "interval: the values of the parameter for which the fit's weighted RMS log error, refitted over all other parameters (profile), stays within interval_level = sqrt(E0^2 + eps^2) (E0 the fit's error, eps = model_error_scale = max(0.05, E0): the model's own error, docs/accuracy.md); it contains the true value whenever the model at the true parameters fits the data that well. A bound, not a standard deviation; interval_method linear: from the Jacobian only. determined: interval at most a fifth of the search range (unit coordinates) and not on a bound. stderr: one-sigma error from the data's noise alone, taking the model as exact; not the parameter's uncertainty";

/// The report for model `c` at unit coordinates `u`, fitted to `points` with
/// normalised residual weights `sqrt_w` ([`crate::objective::sqrt_weights`]).
pub fn identifiability(
    c: &dyn FitModel,
    u: &[f64],
    points: &[&Point],
    sqrt_w: &[f64],
    channels: usize,
    settings: &ReportSettings,
) -> Option<Identifiability> {
    let specs = c.specs();
    let p = specs.len();
    let n = sqrt_w.len();
    let evals = std::sync::atomic::AtomicUsize::new(0);
    let resid_into = |u: &[f64], out: &mut [f64]| -> bool {
        evals.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        match c.build(&c.values(u)) {
            Ok(model) => residuals(model.as_ref(), points, sqrt_w, channels, out),
            Err(_) => false,
        }
    };
    let resid = |u: &[f64]| -> Option<Vec<f64>> {
        let mut out = vec![0.0; n];
        resid_into(u, &mut out).then_some(out)
    };
    let r0 = resid(u)?;
    let cost: f64 = r0.iter().map(|x| x * x).sum();
    let mut j = DMatrix::<f64>::zeros(n, p);
    let h = 1e-4;
    // Central differences, one-sided at the box's ends; the columns in parallel.
    let columns: Vec<Option<Vec<f64>>> = (0..p)
        .into_par_iter()
        .map(|k| {
            let (lo, hi) = ((u[k] - h).max(0.0), (u[k] + h).min(1.0));
            let mut ul = u.to_vec();
            ul[k] = lo;
            let mut uh = u.to_vec();
            uh[k] = hi;
            let (rl, rh) = (resid(&ul)?, resid(&uh)?);
            Some((0..n).map(|i| (rh[i] - rl[i]) / (hi - lo)).collect())
        })
        .collect();
    for (k, col) in columns.into_iter().enumerate() {
        let col = col?;
        for i in 0..n {
            j[(i, k)] = col[i];
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
    // The pseudo-inverse of J^T J (infinite diagonal along undetermined directions).
    let mut cinv = DMatrix::<f64>::zeros(p, p);
    let mut null = vec![false; p];
    for (m, &s) in sv.iter().enumerate() {
        if s <= 1e-8 * smax {
            for k in 0..p {
                null[k] |= vt[(m, k)].abs() > 1e-6;
            }
        } else {
            for a in 0..p {
                for b in 0..p {
                    cinv[(a, b)] += vt[(m, a)] * vt[(m, b)] / (s * s);
                }
            }
        }
    }
    let var = |k: usize| if null[k] { f64::INFINITY } else { cinv[(k, k)] };
    let eps = settings.model_error.max(cost.sqrt());
    let eps2 = eps * eps;
    let level2 = cost + eps2;
    let on_bound = |k: usize| u[k] < BOUND_TOLERANCE || u[k] > 1.0 - BOUND_TOLERANCE;
    let refits = std::sync::atomic::AtomicUsize::new(0);
    // The profile excess (E_k^2 - E0^2) / eps^2 with u_k held at `uk`, refitted from `start`;
    // returns it and the refitted point.
    let profile = |k: usize, uk: f64, start: &[f64]| -> (f64, Vec<f64>) {
        refits.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let free: Vec<usize> = (0..p).filter(|&i| i != k).collect();
        let full = |v: &[f64]| {
            let mut w = start.to_vec();
            w[k] = uk;
            for (a, &i) in free.iter().enumerate() {
                w[i] = v[a];
            }
            w
        };
        let f = |v: &[f64], out: &mut [f64]| resid_into(&full(v), out);
        let v0: Vec<f64> = free.iter().map(|&i| start[i]).collect();
        // Only whether the profile is below the level matters: a point below it
        // ends the refit (the minimum is lower still).
        let mut r0 = vec![0.0; n];
        if resid_into(&full(&v0), &mut r0) {
            let c0: f64 = r0.iter().map(|x| x * x).sum();
            if c0 < level2 {
                return ((c0 - cost) / eps2, full(&v0));
            }
        }
        let lm = LmSettings {
            cost_atol: level2 * (1.0 - 1e-9),
            ..settings.lm
        };
        let r = levenberg_marquardt(&f, &v0, n, &lm);
        ((r.cost - cost) / eps2, full(&r.u))
    };
    // One end of the interval of parameter k on side `sign` (+1 or -1), as a
    // distance in unit coordinates from u_k, starting from the linearised `t0`.
    let end = |k: usize, sign: f64, t0: f64| -> f64 {
        let room = if sign > 0.0 { 1.0 - u[k] } else { u[k] };
        let at = |t: f64| u[k] + sign * t;
        // the linearised profile path: the other parameters follow C e_k
        let path = |t: f64| -> Vec<f64> {
            (0..p)
                .map(|i| {
                    if i == k {
                        at(t)
                    } else {
                        (u[i] + sign * t * cinv[(i, k)] / cinv[(k, k)]).clamp(0.0, 1.0)
                    }
                })
                .collect()
        };
        let mut t = t0.min(room);
        if t <= 0.0 {
            return 0.0;
        }
        let (d, mut best) = profile(k, at(t), &path(t));
        if d >= 1.0 {
            // steeper than quadratic: try half the distance
            let (dh, _) = profile(k, at(0.5 * t), &path(0.5 * t));
            return if dh >= 1.0 { 0.5 * t } else { t };
        }
        // flatter: push out until the profile rises above the level, the box
        // ends, or the interval is too wide to make the parameter determined
        loop {
            if t >= room {
                return room;
            }
            if t > DETERMINED_WIDTH {
                return t;
            }
            let t2 = (2.0 * t).min(room);
            let (d2, b2) = profile(k, at(t2), &best);
            if d2 >= 1.0 {
                let tm = 0.5 * (t + t2);
                let (dm, _) = profile(k, at(tm), &best);
                return if dm >= 1.0 { tm } else { t2 };
            }
            t = t2;
            best = b2;
        }
    };
    let params: Vec<ParamReport> = (0..p)
        .into_par_iter()
        .map(|k| {
            let spec = &specs[k];
            let x = spec.value(u[k]);
            let dxdu = match spec.scale {
                Scale::Linear => spec.hi - spec.lo,
                Scale::Log => x * (spec.hi / spec.lo).ln(),
            };
            let su = (s2 * var(k)).sqrt();
            let half = (eps2 * var(k)).sqrt();
            let lin = [(u[k] - half).max(0.0), (u[k] + half).min(1.0)];
            let bound = on_bound(k);
            let check = settings.profile && !bound && lin[1] - lin[0] <= 2.0 * DETERMINED_WIDTH;
            let (iu, method) = if check {
                let (a, b) = rayon::join(|| end(k, -1.0, half), || end(k, 1.0, half));
                ([u[k] - a, u[k] + b], IntervalMethod::Profile)
            } else {
                (lin, IntervalMethod::Linear)
            };
            let width = if half.is_finite() { iu[1] - iu[0] } else { f64::INFINITY };
            ParamReport {
                name: spec.name.clone(),
                value: x,
                interval: [spec.value(iu[0]), spec.value(iu[1])],
                interval_width_unit: width,
                interval_method: method,
                stderr: su * dxdu.abs(),
                stderr_unit: su,
                bounds: [spec.lo, spec.hi],
                on_bound: bound,
                determined: !bound && width <= DETERMINED_WIDTH,
            }
        })
        .collect();
    Some(Identifiability {
        params,
        model_error_scale: eps,
        interval_level: level2.sqrt(),
        undetermined_combinations: rel.iter().filter(|&&r| r < 1e-3).count(),
        relative_singular_values: rel,
        values: n,
        free_params: p,
        profile_refits: refits.into_inner(),
        evaluations: evals.into_inner(),
    })
}

/// Refuses data that cannot determine a fit: fewer values than free
/// parameters, no signal (every value zero), or every weight zero. The error
/// says which.
pub fn check_data(points: &[&Point], channels: usize, free_params: usize) -> Result<(), FitError> {
    let values = points.len() * channels;
    if values < free_params {
        return Err(FitError::Degenerate(format!(
            "{} point(s) x {channels} channel(s) = {values} value(s) cannot determine {free_params} free parameters; \
             give more measurements or hold parameters with --fix NAME=VALUE",
            points.len()
        )));
    }
    if points.iter().all(|p| (0..channels).all(|c| p.f.0[c] == 0.0)) {
        return Err(FitError::Degenerate(
            "every measured value is zero: there is no signal to fit".into(),
        ));
    }
    if points
        .iter()
        .all(|p| (0..channels).all(|c| crate::objective::weight(p, c) == 0.0))
    {
        return Err(FitError::Degenerate(
            "every point has weight zero: nothing would be fitted".into(),
        ));
    }
    Ok(())
}

/// The RMS log error above which a fit is refused as meaningless: the model
/// misses the data by a factor e^2.3 = 10 on average.
pub const MEANINGLESS_RMS: f64 = 2.3;
