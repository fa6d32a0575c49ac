//! Refinement of a `paper` fit with the model `slab` (issue 13): the same
//! sheet solved by Fourier adding-doubling ([`paperbsdf_slab::SlabBsdf`]),
//! within about 2% of the exact random walk where the Paper BSDF's closed
//! forms miss by 3 to 46% (docs/accuracy_slab.md).
//!
//! A slab build is a solve (about 0.3 to 1 s on two cores), a thousand times a
//! Paper BSDF build, so `slab` is not searched globally. The refinement starts
//! at the `paper` optimum, where the two models describe nearly the same
//! sheet, and runs the same projected Levenberg-Marquardt iteration
//! ([`crate::optimize`]) over the same free parameters, bounds, scales and
//! held (`--fix`) values, on the same points and weighted log error
//! ([`crate::objective`]). Its finite-difference Jacobian takes one solve per
//! free parameter; those solves run in parallel (rayon). The iteration only
//! accepts steps that lower the error, so the refined error is never above
//! that of `slab` at the `paper` optimum (the start).
//!
//! What the data determine is reported from the linearised intervals only
//! (the profile refits of [`crate::report`] would take hundreds of solves),
//! with the model error scale [`SLAB_MODEL_ERROR_RMS`]: `slab`'s documented
//! accuracy against the simulator.

use crate::error::FitError;
use crate::fitter::{report_warnings, split_points, FitOutcome};
use crate::model::FitModel;
use crate::models::SlabFit;
use crate::objective::{residuals, rms_log_error, sqrt_weights};
use crate::optimize::{levenberg_marquardt, LmSettings, Stop};
use crate::report::{identifiability, ReportSettings};
use crate::Point;
use paperbsdf_slab::SlabBsdf;

/// `slab`'s own error scale for the uncertainty intervals (RMS log error):
/// its median error against the exact simulation is 1 to 2%
/// (docs/accuracy_slab.md, README), against 3 to 6% for `paper`.
pub const SLAB_MODEL_ERROR_RMS: f64 = 0.02;

/// Settings of a refinement with `slab`.
#[derive(Clone, Debug)]
pub struct RefineOptions {
    /// The Levenberg-Marquardt settings (iteration limit = Jacobians, each one
    /// solve per free parameter; the default 40 with parallel columns).
    pub lm: LmSettings,
    /// Incident angles (degrees) whose points were fitted (as the `paper` fit's); `None`: all.
    pub fit_theta_i: Option<Vec<f64>>,
    /// Show progress (solves done, the error so far) on stderr.
    pub progress: bool,
    /// The identifiability report's settings (`None`: no report). The
    /// report is always linearised here (`profile` is ignored).
    pub report: Option<ReportSettings>,
    /// The discretisation of every solve (the CLI's `--slab-nodes`; the
    /// default 32 nodes per hemisphere). FIT.json records its nodes.
    pub slab: paperbsdf_slab::SlabOptions,
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions {
            lm: LmSettings {
                max_iter: 40,
                parallel_jacobian: true,
                ..LmSettings::default()
            },
            fit_theta_i: None,
            progress: false,
            report: Some(ReportSettings {
                model_error: SLAB_MODEL_ERROR_RMS,
                profile: false,
                ..ReportSettings::default()
            }),
            slab: paperbsdf_slab::SlabOptions::default(),
        }
    }
}

/// A `paper` fit refined with `slab`.
#[derive(Clone, Debug)]
pub struct Refinement {
    /// The refined fit: model `slab`, its parameters and errors; its
    /// `evaluations` and `seconds` are the refinement's own.
    pub outcome: FitOutcome,
    /// The refined model (the solved sheet of `outcome.params`).
    pub model: SlabBsdf,
    /// The model refined from (`paper` or `reduced-multilayer`).
    pub from_model: String,
    /// That fit's parameter file.
    pub from_params: serde_json::Value,
    /// That fit's weighted RMS log error on the fitted points.
    pub from_rms_log_error: f64,
    /// That fit's error on the extrapolation points.
    pub from_extrapolation_rms_log_error: Option<f64>,
    /// The error of `slab` at that fit's parameters (the refinement's start).
    pub start_rms_log_error: f64,
    /// Whether the refinement converged (else it stopped at the iteration
    /// limit: better than the start, not a minimum).
    pub converged: bool,
    /// The outside nodes per hemisphere every solve had
    /// ([`RefineOptions::slab`]), FIT.json's `slab_nodes`.
    pub slab_nodes: usize,
}

/// Refines `from`, a fit of one of `candidates` (the variants that
/// [`crate::fit`] searched, with the same `--fix` holds), with `slab`, on the
/// same `points` (`channels` = 1 or 3).
pub fn refine_with_slab(
    points: &[Point],
    channels: usize,
    candidates: &[Box<dyn FitModel>],
    from: &FitOutcome,
    opts: &RefineOptions,
) -> Result<Refinement, FitError> {
    let t0 = std::time::Instant::now();
    let paper = candidates
        .get(from.variant_index)
        .ok_or_else(|| FitError::RefineFrom {
            model: format!(
                "{} (variant {} of {})",
                from.model,
                from.variant_index,
                candidates.len()
            ),
        })?
        .as_ref();
    let slab = SlabFit::with_options(paper, opts.slab)?;
    let specs = slab.specs();
    if from.x.len() != specs.len() {
        return Err(FitError::RefineFrom {
            model: format!(
                "{} ({} fitted values for {} free parameters)",
                from.model,
                from.x.len(),
                specs.len()
            ),
        });
    }
    let (fitted, _) = split_points(points, opts.fit_theta_i.as_deref());
    if fitted.is_empty() {
        return Err(FitError::NoPoints(String::new()));
    }
    let sw = sqrt_weights(&fitted, channels);
    let m = sw.len();
    let pb = if opts.progress {
        let pb = indicatif::ProgressBar::new_spinner();
        pb.set_style(
            indicatif::ProgressStyle::with_template("{spinner} refine with slab: {pos} solves, {msg} {elapsed}")
                .expect("template"),
        );
        pb.set_message("solving at the paper optimum".to_string());
        pb.enable_steady_tick(std::time::Duration::from_millis(200));
        pb
    } else {
        indicatif::ProgressBar::hidden()
    };
    // The lowest cost so far, for the progress message (the first is the start's).
    let best = std::sync::Mutex::new(f64::INFINITY);
    let resid = |u: &[f64], out: &mut [f64]| -> bool {
        let ok = match slab.build(&slab.values(u)) {
            Ok(model) => residuals(model.as_ref(), &fitted, &sw, channels, out),
            Err(_) => false,
        };
        pb.inc(1);
        if ok {
            let cost: f64 = out.iter().map(|r| r * r).sum();
            let mut b = best.lock().expect("no panic while held");
            if cost < *b {
                *b = cost;
                pb.set_message(format!("RMS log error {:.5}", cost.sqrt()));
            }
        }
        ok
    };
    let u0: Vec<f64> = specs.iter().zip(&from.x).map(|(s, &x)| s.unit(x)).collect();
    let r = levenberg_marquardt(&resid, &u0, m, &opts.lm);
    pb.finish_and_clear();
    if r.stop == Stop::Invalid {
        // The solver's own reason if it refused the sheet, else non-finite values.
        slab.build(&slab.values(&u0))?;
        return Err(FitError::NoValidStart(
            "the slab model gave non-finite values at the paper optimum".to_string(),
        ));
    }
    // LM's first evaluation was the start: the reference the refinement can only improve on.
    let start_rms = r.start_cost.sqrt();
    let mut evaluations = r.evaluations + 1; // and the final model's solve
    let x = slab.values(&r.u);
    let model = SlabBsdf::with_options(&slab.params(&x)?, &opts.slab)?;
    let (rms, _) = rms_log_error(&model, &fitted, channels).expect("points");
    let ident = opts.report.as_ref().and_then(|rs| {
        let rs = ReportSettings { profile: false, ..*rs };
        identifiability(&slab, &r.u, &fitted, &sw, channels, &rs)
    });
    let mut warnings = Vec::new();
    if let Some(id) = &ident {
        evaluations += id.evaluations;
        warnings = report_warnings(id);
    }
    let converged = r.stop.converged();
    if !converged {
        warnings.push(format!(
            "the refinement with slab stopped at its iteration limit ({} Jacobians) before converging: its error {rms:.5} is below the start's {start_rms:.5}, but the parameters are not a minimum (raise --refine-max-iter)",
            r.iterations
        ));
    }
    let outcome = FitOutcome::scored(
        &slab,
        from.variant_index,
        x,
        &model,
        points,
        opts.fit_theta_i.as_deref(),
        channels,
        (evaluations, t0.elapsed().as_secs_f64(), r.stop),
        ident,
        warnings,
    );
    Ok(Refinement {
        outcome,
        model,
        from_model: from.model.clone(),
        from_params: from.params.clone(),
        from_rms_log_error: from.rms_log_error,
        from_extrapolation_rms_log_error: from.extrapolation_rms_log_error,
        start_rms_log_error: start_rms,
        converged,
        slab_nodes: opts.slab.nodes,
    })
}

impl Refinement {
    /// The FIT.json document of the refined fit ([`FitOutcome::to_json`] of
    /// model `slab`) with `refined_from` (the model) and `refinement`: the
    /// `paper` fit's parameters and errors, the error of `slab` at them (the
    /// start), and the refinement's solves and seconds.
    pub fn to_json(&self, data: &[String], fit_theta_i: Option<&[f64]>) -> serde_json::Value {
        let mut j = self.outcome.to_json(data, fit_theta_i);
        j["refined_from"] = self.from_model.clone().into();
        // What `eval`, `plot` and Python solve the fit with (io's SLAB_NODES_KEY).
        j[paperbsdf_io::models::SLAB_NODES_KEY] = self.slab_nodes.into();
        j["refinement"] = serde_json::json!({
            "from_model": self.from_model,
            "from_params": self.from_params,
            "from_rms_log_error": self.from_rms_log_error,
            "from_extrapolation_rms_log_error": self.from_extrapolation_rms_log_error,
            "start_rms_log_error": self.start_rms_log_error,
            "rms_log_error": self.outcome.rms_log_error,
            "converged": self.converged,
            "solves": self.outcome.evaluations,
            "seconds": self.outcome.seconds,
            "definition": "start_rms_log_error: the slab model at the from_params (where the refinement starts); solves and seconds are the refinement's own (the paper fit's are not counted)",
        });
        j
    }
}
