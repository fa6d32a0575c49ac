//! The fit: split the measurement into fitted and extrapolation points, search
//! every discrete variant of the model globally (the default start plus a
//! Latin hypercube sample of the box), refine the best starts
//! locally (in parallel with rayon), and score the winner on both point sets
//! and per incident angle and kind (docs/design.md section 5).

pub use crate::error::FitError;
use crate::measurement::{Kind, Point};
use crate::model::{ComponentModel, FitModel};
use crate::objective::{residuals, rms_log_error, sqrt_weights};
use crate::optimize::{levenberg_marquardt, LmSettings, Stop};
use crate::report::{check_data, identifiability, Identifiability, ReportSettings, MEANINGLESS_RMS};
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

/// Settings of a fit.
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// Random points of the box scored per variant in the global stage.
    pub global_samples: usize,
    /// Number of starting points refined locally (the best of each variant is always among them).
    pub local_starts: usize,
    /// Local refinement settings.
    pub lm: LmSettings,
    /// Screening: every start is first refined for this many iterations, then
    /// only the best [`FitOptions::final_starts`] are refined to convergence (0: no screening).
    pub screen_iter: usize,
    /// Starts refined to convergence after screening.
    pub final_starts: usize,
    /// Incident angles (degrees) whose points are fitted; `None`: all points.
    pub fit_theta_i: Option<Vec<f64>>,
    /// Rounds of basin hopping after the local refinement: each round refines
    /// [`FitOptions::hop_starts`] random perturbations of the best point so far
    /// (normal, standard deviation 0.3, 0.15, 0.075, ... of the unit box) and
    /// keeps the best; escapes local minima that every start fell into.
    pub hop_rounds: usize,
    /// Perturbations refined per round of basin hopping (in parallel).
    pub hop_starts: usize,
    /// Seed of the global stage.
    pub seed: u64,
    /// Show a progress bar on stderr.
    pub progress: bool,
    /// How the identifiability report is computed (model error scale, profile checks).
    pub report: ReportSettings,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            global_samples: 128,
            local_starts: 16,
            lm: LmSettings::default(),
            screen_iter: 8,
            final_starts: 4,
            fit_theta_i: None,
            hop_rounds: 3,
            hop_starts: 4,
            seed: 1,
            progress: false,
            report: ReportSettings::default(),
        }
    }
}

/// The error of the fitted model on one incident angle and kind.
#[derive(Clone, Debug, serde::Serialize)]
pub struct GroupError {
    /// Incident angle, degrees.
    pub theta_i: f64,
    /// `R` or `T`.
    pub kind: Kind,
    /// Number of points.
    pub points: usize,
    /// Whether these points were left out of the fit (extrapolation).
    pub extrapolation: bool,
    /// Weighted RMS log error.
    pub rms_log_error: f64,
}

/// The outcome of a converged fit.
#[derive(Clone, Debug)]
pub struct FitOutcome {
    /// The model name (`paper`, ...).
    pub model: String,
    /// The discrete variant chosen.
    pub variant: String,
    /// Index of the chosen variant in the candidate list.
    pub variant_index: usize,
    /// Fitted parameter values (in the order of the variant's specs).
    pub x: Vec<f64>,
    /// The parameter file of the fitted values.
    pub params: serde_json::Value,
    /// Weighted RMS log error on the fitted points.
    pub rms_log_error: f64,
    /// Unweighted RMS log error on the fitted points.
    pub rms_log_error_unweighted: f64,
    /// Weighted RMS log error on the extrapolation points (`None` when there are none).
    pub extrapolation_rms_log_error: Option<f64>,
    /// Per incident angle and kind.
    pub per_group: Vec<GroupError>,
    /// Number of fitted and extrapolation points.
    pub counts: (usize, usize),
    /// Residual evaluations used.
    pub evaluations: usize,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Why the winning refinement stopped.
    pub stop: Stop,
    /// What the data determine ([`crate::report`]); `None` if the Jacobian could not be evaluated.
    pub identifiability: Option<Identifiability>,
    /// Warnings about the result (parameters on bounds, undetermined parameters).
    pub warnings: Vec<String>,
}

fn matches_theta(t: f64, list: &[f64]) -> bool {
    list.iter().any(|x| (x - t).abs() < 1e-6)
}

/// Splits points into fitted and extrapolation sets by incident angle.
pub fn split_points<'a>(points: &'a [Point], fit_theta_i: Option<&[f64]>) -> (Vec<&'a Point>, Vec<&'a Point>) {
    match fit_theta_i {
        None => (points.iter().collect(), vec![]),
        Some(list) => points.iter().partition(|p| matches_theta(p.theta_i, list)),
    }
}

/// Scores `model` per incident angle and kind.
pub fn group_errors(
    model: &dyn ComponentModel,
    points: &[Point],
    fit_theta_i: Option<&[f64]>,
    channels: usize,
) -> Vec<GroupError> {
    let mut keys: Vec<(f64, Kind)> = points.iter().map(|p| (p.theta_i, p.kind)).collect();
    keys.sort_by(|a, b| a.1.cmp(&b.1).then(a.0.partial_cmp(&b.0).unwrap()));
    keys.dedup_by(|a, b| a.1 == b.1 && (a.0 - b.0).abs() < 1e-6);
    keys.into_iter()
        .map(|(t, k)| {
            let pts: Vec<&Point> = points
                .iter()
                .filter(|p| p.kind == k && (p.theta_i - t).abs() < 1e-6)
                .collect();
            let (rms, _) = rms_log_error(model, &pts, channels).unwrap();
            GroupError {
                theta_i: t,
                kind: k,
                points: pts.len(),
                extrapolation: fit_theta_i.map(|l| !matches_theta(t, l)).unwrap_or(false),
                rms_log_error: rms,
            }
        })
        .collect()
}

/// Fits the best of `candidates` (the discrete variants of one model) to `points`.
pub fn fit(
    points: &[Point],
    channels: usize,
    candidates: &[Box<dyn FitModel>],
    opts: &FitOptions,
) -> Result<FitOutcome, FitError> {
    let t0 = std::time::Instant::now();
    let (fitted, _) = split_points(points, opts.fit_theta_i.as_deref());
    if fitted.is_empty() {
        let why = match &opts.fit_theta_i {
            Some(l) => format!(": no point has an incident angle in the fitted list {l:?}"),
            None => String::new(),
        };
        return Err(FitError::NoPoints(why));
    }
    let free = candidates.iter().map(|c| c.specs().len()).max().unwrap_or(0);
    check_data(&fitted, channels, free)?;
    let sw = sqrt_weights(&fitted, channels);
    let m = sw.len();
    let resid_for = |c: &dyn FitModel, u: &[f64], out: &mut [f64]| -> bool {
        match c.build(&c.values(u)) {
            Ok(model) => residuals(model.as_ref(), &fitted, &sw, channels, out),
            Err(_) => false,
        }
    };
    let cost_of = |c: &dyn FitModel, u: &[f64]| -> f64 {
        let mut out = vec![0.0; m];
        if resid_for(c, u, &mut out) {
            out.iter().map(|x| x * x).sum()
        } else {
            f64::INFINITY
        }
    };
    let pb = if opts.progress {
        let pb = indicatif::ProgressBar::new((candidates.len() * opts.global_samples + opts.local_starts) as u64);
        pb.set_style(
            indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {elapsed}")
                .unwrap()
                .progress_chars("=> "),
        );
        pb.set_message(format!(
            "fit {}",
            candidates
                .first()
                .map(|c| c.model_name().to_string())
                .unwrap_or_default()
        ));
        pb
    } else {
        indicatif::ProgressBar::hidden()
    };
    // Global stage: the default start and uniform random points of the box, per variant.
    let mut starts: Vec<(usize, Vec<f64>)> = Vec::new();
    for (ci, c) in candidates.iter().enumerate() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(opts.seed.wrapping_add(ci as u64 * 7919));
        starts.push((ci, c.default_unit()));
        // Latin hypercube: each parameter's range is cut into `k` strata, each used once.
        let k = opts.global_samples.max(2) - 1;
        let dims = c.specs().len();
        let mut cols: Vec<Vec<f64>> = Vec::with_capacity(dims);
        for _ in 0..dims {
            let mut col: Vec<f64> = (0..k).map(|i| (i as f64 + rng.gen::<f64>()) / k as f64).collect();
            for i in (1..k).rev() {
                col.swap(i, rng.gen_range(0..=i));
            }
            cols.push(col);
        }
        for i in 0..k {
            starts.push((ci, cols.iter().map(|col| col[i]).collect()));
        }
    }
    let mut scored: Vec<(f64, usize, Vec<f64>)> = starts
        .into_par_iter()
        .map(|(ci, u)| {
            let c = cost_of(candidates[ci].as_ref(), &u);
            pb.inc(1);
            (c, ci, u)
        })
        .collect();
    let mut evaluations = scored.len();
    scored.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap_or(std::cmp::Ordering::Equal));
    if !scored[0].0.is_finite() {
        let c = &candidates[0];
        let why = c
            .build(&c.values(&c.default_unit()))
            .err()
            .map_or_else(|| "non-finite values".to_string(), |e| e.to_string());
        return Err(FitError::NoValidStart(why));
    }
    // The best of each variant, then the overall best, up to `local_starts` (at least one per variant).
    let mut chosen: Vec<(usize, Vec<f64>)> = Vec::new();
    for ci in 0..candidates.len() {
        if let Some(s) = scored.iter().find(|s| s.1 == ci && s.0.is_finite()) {
            chosen.push((ci, s.2.clone()));
        }
    }
    for s in scored.iter().filter(|s| s.0.is_finite()) {
        if chosen.len() >= opts.local_starts.max(candidates.len()) {
            break;
        }
        if !chosen.iter().any(|c| c.0 == s.1 && c.1 == s.2) {
            chosen.push((s.1, s.2.clone()));
        }
    }
    let screening = opts.screen_iter > 0 && chosen.len() > opts.final_starts.max(1);
    let n_final = if screening { opts.final_starts.max(1) } else { 0 };
    pb.set_length(
        (candidates.len() * opts.global_samples + chosen.len() + n_final + opts.hop_rounds * opts.hop_starts) as u64,
    );
    let refine = |starts: Vec<(usize, Vec<f64>)>, lm: LmSettings| -> Vec<(usize, crate::optimize::LmResult)> {
        starts
            .into_par_iter()
            .map(|(ci, u)| {
                let c = candidates[ci].as_ref();
                let f = |u: &[f64], out: &mut [f64]| resid_for(c, u, out);
                let r = levenberg_marquardt(&f, &u, m, &lm);
                pb.inc(1);
                (ci, r)
            })
            .collect()
    };
    let mut results = if screening {
        let lm = LmSettings {
            max_iter: opts.screen_iter,
            ..opts.lm
        };
        refine(chosen, lm)
    } else {
        refine(chosen, opts.lm)
    };
    if screening {
        evaluations += results.iter().map(|r| r.1.evaluations).sum::<usize>();
        results.sort_by(|a, b| a.1.cost.partial_cmp(&b.1.cost).unwrap_or(std::cmp::Ordering::Equal));
        let finals: Vec<(usize, Vec<f64>)> = results.iter().take(n_final).map(|r| (r.0, r.1.u.clone())).collect();
        results = refine(finals, opts.lm);
    }
    evaluations += results.iter().map(|r| r.1.evaluations).sum::<usize>();
    let (ci, mut best) = results
        .into_iter()
        .min_by(|a, b| a.1.cost.partial_cmp(&b.1.cost).unwrap_or(std::cmp::Ordering::Equal))
        .unwrap();
    // Basin hopping within the winning variant.
    let mut rng = rand_pcg::Pcg64::seed_from_u64(opts.seed ^ 0x6A09_E667_F3BC_C908);
    for round in 0..opts.hop_rounds {
        let sd = 0.3 * 0.5f64.powi(round as i32);
        let starts: Vec<(usize, Vec<f64>)> = (0..opts.hop_starts)
            .map(|_| {
                let u = best
                    .u
                    .iter()
                    .map(|&x| {
                        // Box-Muller normal deviate, the result kept inside the box.
                        let (a, b): (f64, f64) = (rng.gen::<f64>().max(1e-300), rng.gen());
                        let z = (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos();
                        (x + sd * z).clamp(0.0, 1.0)
                    })
                    .collect();
                (ci, u)
            })
            .collect();
        for (_, r) in refine(starts, opts.lm) {
            evaluations += r.evaluations;
            if r.cost < best.cost && r.stop.converged() {
                best = r;
            }
        }
    }
    pb.finish_and_clear();
    let c = candidates[ci].as_ref();
    if !best.stop.converged() {
        return Err(FitError::NotConverged {
            variant: c.variant(),
            iterations: best.iterations,
            rms: best.cost.sqrt(),
        });
    }
    let x = c.values(&best.u);
    let model = c.build(&x).map_err(|e| FitError::NoValidStart(e.to_string()))?;
    let (rms, _) = rms_log_error(model.as_ref(), &fitted, channels).unwrap();
    if rms.is_nan() || rms > MEANINGLESS_RMS {
        return Err(FitError::Meaningless {
            variant: c.variant(),
            rms,
            factor: rms.exp(),
            limit: MEANINGLESS_RMS,
        });
    }
    let ident = identifiability(c, &best.u, &fitted, &sw, channels, &opts.report);
    let mut warnings = Vec::new();
    if let Some(id) = &ident {
        evaluations += id.evaluations;
        warnings = report_warnings(id);
    }
    Ok(FitOutcome::scored(
        c,
        ci,
        x,
        model.as_ref(),
        points,
        opts.fit_theta_i.as_deref(),
        channels,
        (evaluations, t0.elapsed().as_secs_f64(), best.stop),
        ident,
        warnings,
    ))
}

/// The warnings of an identifiability report: parameters on a bound of their
/// search range and parameters the data do not determine.
pub(crate) fn report_warnings(id: &Identifiability) -> Vec<String> {
    let mut warnings = Vec::new();
    for p in &id.params {
        let fix = p.name.split('[').next().unwrap_or(&p.name);
        if p.on_bound {
            warnings.push(format!(
                "{} = {:.6} ended on a bound of its search range [{}, {}]: the data push it beyond what the model allows; its value is not a measurement (hold it with --fix {fix}=VALUE)",
                p.name, p.value, p.bounds[0], p.bounds[1]
            ));
        } else if !p.determined {
            let how = if p.interval_width_unit.is_finite() {
                format!(
                    "any value from {:.4e} to {:.4e} ({:.0}% of its search range{}) fits within the model's own error, RMS log error {:.3}",
                    p.interval[0],
                    p.interval[1],
                    100.0 * p.interval_width_unit,
                    if p.interval_method == crate::report::IntervalMethod::Linear {
                        ", linearised"
                    } else {
                        ""
                    },
                    id.interval_level
                )
            } else {
                "no constraint at all: it trades off exactly against other parameters".to_string()
            };
            warnings.push(format!(
                "{} = {:.6} is not determined by the data: {how}; hold it at a plausible value with --fix {fix}=VALUE",
                p.name, p.value
            ));
        }
    }
    warnings
}

impl FitOutcome {
    /// The outcome of variant `variant_index`, `c`, at values `x` (`model`
    /// its build): its errors on the fitted and extrapolation `points` (split
    /// by `fit_theta_i`) and per incident angle and kind, with the run's
    /// `(evaluations, seconds, stop)`, report and warnings.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn scored(
        c: &dyn FitModel,
        variant_index: usize,
        x: Vec<f64>,
        model: &dyn ComponentModel,
        points: &[Point],
        fit_theta_i: Option<&[f64]>,
        channels: usize,
        (evaluations, seconds, stop): (usize, f64, Stop),
        identifiability: Option<Identifiability>,
        warnings: Vec<String>,
    ) -> FitOutcome {
        let (fitted, extra) = split_points(points, fit_theta_i);
        let (rms, rms_u) = rms_log_error(model, &fitted, channels).unwrap_or((f64::NAN, f64::NAN));
        FitOutcome {
            model: c.model_name().to_string(),
            variant: c.variant(),
            variant_index,
            params: c.params_json(&x),
            x,
            rms_log_error: rms,
            rms_log_error_unweighted: rms_u,
            extrapolation_rms_log_error: rms_log_error(model, &extra, channels).map(|e| e.0),
            per_group: group_errors(model, points, fit_theta_i, channels),
            counts: (fitted.len(), extra.len()),
            evaluations,
            seconds,
            stop,
            identifiability,
            warnings,
        }
    }

    /// The FIT.json document: `model`, `params`, `rms_log_error`,
    /// `extrapolation_rms_log_error` (null when none), errors per incident angle
    /// and kind, `seconds`, and how the fit went.
    pub fn to_json(&self, data: &[String], fit_theta_i: Option<&[f64]>) -> serde_json::Value {
        serde_json::json!({
            "model": self.model,
            "params": self.params,
            "rms_log_error": self.rms_log_error,
            "rms_log_error_unweighted": self.rms_log_error_unweighted,
            "extrapolation_rms_log_error": self.extrapolation_rms_log_error,
            "errors": self.per_group,
            "seconds": self.seconds,
            "variant": self.variant,
            "data": data,
            "fit_theta_i": fit_theta_i,
            "points": {"fitted": self.counts.0, "extrapolation": self.counts.1},
            "evaluations": self.evaluations,
            "stop": self.stop,
            "identifiability": self.identifiability,
            "uncertainty_definition": crate::report::UNCERTAINTY_DEFINITION,
            "warnings": self.warnings,
            "error_definition": format!(
                "sqrt(sum w r^2 / sum w), r = ln((f_model + {e}) / (f_meas + {e})), w = 1/max(stderr/(f_meas + {e}), {s})^2 when stderr is given, else 1",
                e = crate::objective::LOG_OFFSET, s = crate::objective::SIGMA_FLOOR
            ),
        })
    }
}
