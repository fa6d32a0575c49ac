//! `paperbsdf fit`: fits a model to in-plane (or general) BSDF measurements
//! (docs/design.md section 5; crate paperbsdf-fit) or to a measured RGL `.bsdf`
//! file (sampled in and out of the plane of incidence,
//! [`paperbsdf_fit::measured`]), and writes FIT.json with the errors, what the
//! data determine, and warnings.

use crate::choices;
use anyhow::{bail, Result};
use paperbsdf_core::{Distribution, FaceScattering};
use paperbsdf_fit::dataset::load_dataset;
use paperbsdf_fit::measured::{directional_albedo, in_plane, sample_measured, PointFilter, Sampling};
use paperbsdf_fit::models::candidates_with_faces;
use paperbsdf_fit::{fit, fix_params, parse_fix, refine_with_slab, FitOptions, Kind, Point, RefineOptions};

/// `--refine`: a model that refines the fit from its optimum.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Refine {
    /// The same sheet solved by adding-doubling (`--model slab` elsewhere):
    /// within about 2% of the exact random walk, thin sheets included.
    Slab,
}

/// Arguments of `paperbsdf fit`.
#[derive(clap::Args, Debug)]
pub struct FitArgs {
    /// Measurement files (CSV: kind,theta_i_deg,theta_o_deg or wi_*,wo_* columns; f or r,g,b; optional stderr or weight), or one measured RGL `.bsdf` file.
    #[arg(required = true)]
    pub data: Vec<String>,
    /// Model: paper, lambert-glass or reduced-multilayer (`slab` refines a paper fit: --refine slab).
    #[arg(long)]
    pub model: String,
    /// Paper thickness d in mm (not fitted); default: from the data's `# thickness:` or `# params:` header.
    #[arg(long, allow_hyphen_values = true)]
    pub thickness: Option<f64>,
    /// Incident angles (degrees, comma-separated) to fit; points at other angles are extrapolation points, scored separately. Default: all.
    #[arg(long = "fit-theta-i", value_delimiter = ',', allow_hyphen_values = true)]
    pub fit_theta_i: Vec<f64>,
    /// Microfacet distributions to try per face (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "ggx,beckmann", value_parser = choices::distribution(), ignore_case = true)]
    pub dists: Vec<Distribution>,
    /// Write the fit (model, params, errors, seconds) to this JSON file (atomically).
    #[arg(long)]
    pub out: Option<String>,
    /// Random points of the parameter box scored per variant in the global search.
    #[arg(long, default_value_t = 128)]
    pub samples: usize,
    /// Starting points refined by Levenberg-Marquardt.
    #[arg(long, default_value_t = 16)]
    pub starts: usize,
    /// Iteration limit of each local refinement (a fit that reaches it has not converged).
    #[arg(long = "max-iter", default_value_t = 500)]
    pub max_iter: usize,
    /// Seed of the global search.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Faces of the paper and reduced-multilayer models: `multiple` (energy-conserving, the default) or
    /// `single` (Walter's single-scattering faces, as in the paper and Mitsuba's roughdielectric).
    #[arg(long = "face-scattering", default_value = "multiple", value_parser = choices::face_scattering(), ignore_case = true)]
    pub face_scattering: FaceScattering,
    /// Hold a parameter at a value (repeatable): e.g. `--fix eta_f=1.5 --fix m_b=0.4`; a colour parameter's name fixes all its channels.
    #[arg(long = "fix", value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// The model's own error (RMS log error) used for the uncertainty intervals of the report: a value
    /// fits "within the model's error" when its refitted error stays within sqrt(E0^2 + max(RMS, E0)^2),
    /// E0 the fit's error. Default 0.05, paper's documented accuracy in reflection (docs/accuracy.md);
    /// 0.02 for the slab refinement (docs/accuracy_slab.md).
    #[arg(long = "model-error", value_name = "RMS", allow_hyphen_values = true)]
    pub model_error: Option<f64>,
    /// Refine the fit with a more accurate model from its optimum: `slab` (the same sheet solved by
    /// adding-doubling; the same free parameters, bounds and --fix holds; a solve per evaluation,
    /// about a minute or more). FIT.json is then the slab fit, with the paper fit under `refinement`.
    #[arg(long, value_enum, ignore_case = true)]
    pub refine: Option<Refine>,
    /// Iteration limit (Jacobians, each one solve per free parameter, in parallel) of the --refine step.
    #[arg(long = "refine-max-iter", value_name = "N", default_value_t = 40)]
    pub refine_max_iter: usize,
    /// Nodes per hemisphere of every slab solve of --refine slab (default 32; 64 converges slab's values to within 0.2% of twice the nodes on the accuracy cases but one, and solves about 4 times slower). FIT.json records them as `slab_nodes`, and `eval`, `plot` and Python solve the fit with them.
    #[arg(long = "slab-nodes", value_name = "N")]
    pub slab_nodes: Option<usize>,
    /// Linearised uncertainty intervals only (no profile refits: faster, but the intervals can be too narrow).
    #[arg(long = "no-profile")]
    pub no_profile: bool,
    /// Leave out reflection points whose viewer is within DEG degrees of the light (where a goniometer's detector blocks the light).
    #[arg(long = "exclude-retro", value_name = "DEG")]
    pub exclude_retro: Option<f64>,
    /// Leave out points whose light or viewer is more than DEG degrees from the normal (unreliable grazing measurements).
    #[arg(long = "max-theta", value_name = "DEG")]
    pub max_theta: Option<f64>,
}

/// Whether `path` names a measured RGL file (by extension).
pub fn is_bsdf_file(path: &str) -> bool {
    path.to_ascii_lowercase().ends_with(".bsdf")
}

fn rms_over(model: &dyn paperbsdf_fit::ComponentModel, pts: &[&Point], channels: usize) -> Option<f64> {
    paperbsdf_fit::objective::rms_log_error(model, pts, channels).map(|e| e.0)
}

/// Runs `paperbsdf fit`.
pub fn run(args: FitArgs) -> Result<()> {
    if args.samples == 0 || args.starts == 0 || args.max_iter == 0 {
        bail!("--samples, --starts and --max-iter must be at least 1");
    }
    if let Some(e) = args.model_error {
        if !(e >= 0.0 && e.is_finite()) {
            bail!("--model-error {e} must be a finite RMS log error >= 0");
        }
    }
    if args.refine_max_iter == 0 {
        bail!("--refine-max-iter 0: the refinement needs at least 1 iteration");
    }
    if args.refine.is_some() {
        paperbsdf_fit::models::refinable(&args.model)?;
    } else if args.slab_nodes.is_some() {
        bail!("--slab-nodes: sets the discretisation of the refinement with slab; give it with --refine slab");
    }
    // Checked before the fit (its range), used by the refinement.
    let slab_options = paperbsdf_io::models::SlabSettings { nodes: args.slab_nodes }.options("--slab-nodes")?;
    if let Some(out) = &args.out {
        // Before the fit, not after it (issue 16).
        paperbsdf_io::check_output_path(out, "--out")?;
    }
    let filter = PointFilter {
        exclude_retro_deg: args.exclude_retro,
        max_theta_deg: args.max_theta,
    };
    filter.validate()?;
    let fixes = args.fix.iter().map(|f| parse_fix(f)).collect::<Result<Vec<_>, _>>()?;
    let bsdf_files: Vec<&String> = args.data.iter().filter(|p| is_bsdf_file(p)).collect();
    let mut albedo_rows: Vec<(f64, paperbsdf_core::Rgb)> = Vec::new();
    let mut ds = if bsdf_files.is_empty() {
        load_dataset(&args.data, args.thickness)?
    } else {
        if args.data.len() != 1 {
            bail!(
                "a measured .bsdf file is fitted on its own: give it as the only data file ({} files given)",
                args.data.len()
            );
        }
        if let Some(d) = args.thickness {
            if !(d > 0.0 && d.is_finite()) {
                bail!("--thickness {d} is outside its allowed range (0, inf) mm");
            }
        }
        let b = paperbsdf_io::MeasuredBsdf::load(bsdf_files[0])?;
        let sampling = Sampling::default();
        println!(
            "{}: \"{}\", {} incident elevations x {} azimuths; sampled at {} direction pairs (theta_i {:?}, in-plane and out-of-plane viewers)",
            bsdf_files[0],
            b.description,
            b.theta_i.len(),
            b.phi_i.len(),
            sampling.theta_i.len() * (sampling.in_plane_theta_o.len() + sampling.out_theta_o.len() * sampling.out_phi_o.len()),
            sampling.theta_i
        );
        for &t in &sampling.theta_i {
            albedo_rows.push((t, directional_albedo(&b, t)));
        }
        paperbsdf_fit::dataset::Dataset {
            origins: vec![bsdf_files[0].clone()],
            points: sample_measured(&b, &sampling),
            channels: 3,
            thickness: args.thickness,
            params_header: None,
        }
    };
    let before = ds.points.len();
    ds.points = filter.apply(std::mem::take(&mut ds.points));
    if ds.points.len() < before {
        println!(
            "left out {} of {before} points (--exclude-retro {:?}, --max-theta {:?})",
            before - ds.points.len(),
            args.exclude_retro,
            args.max_theta
        );
    }
    if !albedo_rows.is_empty() {
        println!("measured directional albedo (int f cos dwo over the upper hemisphere; r, g, b):");
        let mut brighter = Vec::new();
        for (t, a) in &albedo_rows {
            println!("  theta_i={t:>5}: {:.4}, {:.4}, {:.4}", a.0[0], a.0[1], a.0[2]);
            for (c, name) in ["red", "green", "blue"].iter().enumerate() {
                if a.0[c] > 1.0 {
                    brighter.push(format!("{name} {:.3} at theta_i {t}", a.0[c]));
                }
            }
        }
        if !brighter.is_empty() {
            eprintln!(
                "warning: the data reflect more than all the light that arrives ({}): no non-fluorescent slab can do that. \
                 Fluorescent whitening agents (common in white paper) re-emit absorbed ultraviolet as blue; the Paper BSDF cannot fit that excess",
                brighter.join(", ")
            );
        }
    }
    let cands = candidates_with_faces(
        &args.model,
        ds.thickness,
        ds.channels == 3,
        Some(&args.dists),
        args.face_scattering,
    )?;
    let cands = fix_params(cands, &fixes)?;
    let fit_theta_i = (!args.fit_theta_i.is_empty()).then(|| args.fit_theta_i.clone());
    let opts = FitOptions {
        global_samples: args.samples,
        local_starts: args.starts,
        lm: paperbsdf_fit::optimize::LmSettings {
            max_iter: args.max_iter,
            ..Default::default()
        },
        fit_theta_i: fit_theta_i.clone(),
        seed: args.seed,
        progress: true,
        report: paperbsdf_fit::report::ReportSettings {
            model_error: args.model_error.unwrap_or(paperbsdf_fit::report::MODEL_ERROR_RMS),
            profile: !args.no_profile,
            ..Default::default()
        },
        ..Default::default()
    };
    let out = fit(&ds.points, ds.channels, &cands, &opts)?;
    let refined = match args.refine {
        None => None,
        Some(Refine::Slab) => {
            println!(
                "{} fit: rms_log_error {:.5} (extrapolation {}) in {:.1} s; refining with slab from its optimum",
                out.model,
                out.rms_log_error,
                out.extrapolation_rms_log_error
                    .map(|e| format!("{e:.5}"))
                    .unwrap_or("none".into()),
                out.seconds
            );
            let ropts = RefineOptions {
                lm: paperbsdf_fit::optimize::LmSettings {
                    max_iter: args.refine_max_iter,
                    parallel_jacobian: true,
                    ..Default::default()
                },
                fit_theta_i: fit_theta_i.clone(),
                progress: true,
                report: Some(paperbsdf_fit::report::ReportSettings {
                    model_error: args.model_error.unwrap_or(paperbsdf_fit::refine::SLAB_MODEL_ERROR_RMS),
                    profile: false,
                    ..Default::default()
                }),
                slab: slab_options,
            };
            let r = refine_with_slab(&ds.points, ds.channels, &cands, &out, &ropts)?;
            println!(
                "slab ({} nodes) at the {} optimum: rms_log_error {:.5}; refined: {:.5} in {} solves, {:.1} s{}",
                r.slab_nodes,
                r.from_model,
                r.start_rms_log_error,
                r.outcome.rms_log_error,
                r.outcome.evaluations,
                r.outcome.seconds,
                if r.converged { "" } else { " (not converged)" }
            );
            Some(r)
        }
    };
    let paper_out = out;
    let out = refined.as_ref().map_or(&paper_out, |r| &r.outcome);
    println!("model: {} ({})", out.model, out.variant);
    println!("params: {}", out.params);
    println!(
        "rms_log_error: {:.5} (unweighted {:.5}) on {} points",
        out.rms_log_error, out.rms_log_error_unweighted, out.counts.0
    );
    match out.extrapolation_rms_log_error {
        Some(e) => println!("extrapolation_rms_log_error: {e:.5} on {} points", out.counts.1),
        None => println!("extrapolation_rms_log_error: none (every point was fitted)"),
    }
    for g in &out.per_group {
        println!(
            "  {} theta_i={:>5}: {:.5}{}",
            g.kind.name(),
            g.theta_i,
            g.rms_log_error,
            if g.extrapolation { " (extrapolation)" } else { "" }
        );
    }
    // In-plane and out-of-plane errors, on the fitted and the extrapolation points.
    let paper_model;
    let model: &dyn paperbsdf_fit::ComponentModel = match &refined {
        Some(r) => &r.model,
        None => {
            paper_model = cands[out.variant_index].build(&out.x)?;
            paper_model.as_ref()
        }
    };
    let (fitted, extra) = paperbsdf_fit::fitter::split_points(&ds.points, fit_theta_i.as_deref());
    fn part<'a>(pts: &[&'a Point], plane: bool) -> Vec<&'a Point> {
        pts.iter().copied().filter(|p| in_plane(p) == plane).collect()
    }
    let mut plane_json = serde_json::Map::new();
    for (name, plane) in [("in_plane", true), ("out_of_plane", false)] {
        let (f, e) = (part(&fitted, plane), part(&extra, plane));
        let (rf, re) = (rms_over(model, &f, ds.channels), rms_over(model, &e, ds.channels));
        if f.is_empty() && e.is_empty() {
            continue;
        }
        println!(
            "{name}: rms_log_error {} on {} fitted points, {} on {} extrapolation points",
            rf.map(|v| format!("{v:.5}")).unwrap_or("-".into()),
            f.len(),
            re.map(|v| format!("{v:.5}")).unwrap_or("-".into()),
            e.len()
        );
        plane_json.insert(
            name.into(),
            serde_json::json!({"rms_log_error": rf, "points": f.len(), "extrapolation_rms_log_error": re, "extrapolation_points": e.len()}),
        );
    }
    let reflection_only = ds.points.iter().all(|p| p.kind == Kind::R);
    let transmission_note = reflection_only.then(|| {
        "the data are reflection only: transmission is not constrained by them; the transmission of the fitted parameters is a prediction".to_string()
    });
    if let Some(n) = &transmission_note {
        println!("note: {n}");
    }
    if let Some(id) = &out.identifiability {
        println!(
            "what the data determine ({} values, {} free parameters; {} undetermined combination(s)):",
            id.values, id.free_params, id.undetermined_combinations
        );
        println!(
            "  interval: values whose refitted RMS log error stays within {:.4} (the fit's {:.4} and the model's own error {:.3}); \
             it holds the true value if the model at the true parameters fits that well. stderr: from the noise alone",
            id.interval_level, out.rms_log_error, id.model_error_scale
        );
        for p in &id.params {
            let status = if p.on_bound {
                "ON BOUND"
            } else if p.determined {
                "determined"
            } else {
                "not determined"
            };
            let method = match p.interval_method {
                paperbsdf_fit::report::IntervalMethod::Profile => "",
                paperbsdf_fit::report::IntervalMethod::Linear => " (linearised)",
            };
            println!(
                "  {:<12} {:>12.6}  interval [{:.6}, {:.6}]{method}  stderr {:<10.3e} {status}",
                p.name, p.value, p.interval[0], p.interval[1], p.stderr
            );
        }
    }
    if !fixes.is_empty() {
        println!(
            "held fixed: {}",
            fixes
                .iter()
                .map(|(n, v)| format!("{n}={v}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    for w in &out.warnings {
        eprintln!("warning: {w}");
    }
    println!("seconds: {:.2}", out.seconds);
    if let Some(path) = &args.out {
        let mut json = match &refined {
            Some(r) => r.to_json(&ds.origins, fit_theta_i.as_deref()),
            None => out.to_json(&ds.origins, fit_theta_i.as_deref()),
        };
        let obj = json.as_object_mut().expect("FIT.json is an object");
        obj.insert("errors_by_plane".into(), serde_json::Value::Object(plane_json));
        obj.insert(
            "fixed".into(),
            serde_json::json!(fixes
                .iter()
                .map(|(n, v)| (n.clone(), serde_json::json!(*v)))
                .collect::<serde_json::Map<String, serde_json::Value>>()),
        );
        obj.insert(
            "transmission".into(),
            serde_json::json!(transmission_note
                .as_deref()
                .unwrap_or("constrained by the transmission points of the data")),
        );
        obj.insert(
            "filters".into(),
            serde_json::json!({"exclude_retro_deg": args.exclude_retro, "max_theta_deg": args.max_theta}),
        );
        if !albedo_rows.is_empty() {
            obj.insert(
                "measured_albedo".into(),
                serde_json::json!(albedo_rows
                    .iter()
                    .map(|(t, a)| serde_json::json!({"theta_i": t, "rgb": a.0}))
                    .collect::<Vec<_>>()),
            );
        }
        let text = serde_json::to_string_pretty(&json)? + "\n";
        paperbsdf_io::write_atomic(path, text.as_bytes())?;
        println!("wrote {path}");
    }
    Ok(())
}
