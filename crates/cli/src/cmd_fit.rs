//! `paperbsdf fit`: fits a model to in-plane (or general) BSDF measurements
//! (DESIGN.md section 5; crate paperbsdf-fit) and writes FIT.json.

use anyhow::{anyhow, bail, Result};
use paperbsdf_core::{Distribution, FaceScattering};
use paperbsdf_fit::dataset::load_dataset;
use paperbsdf_fit::models::candidates_with_faces;
use paperbsdf_fit::{fit, FitOptions};

/// Arguments of `paperbsdf fit`.
#[derive(clap::Args, Debug)]
pub struct FitArgs {
    /// Measurement files (CSV: kind,theta_i_deg,theta_o_deg or wi_*,wo_* columns; f or r,g,b; optional stderr).
    #[arg(required = true)]
    pub data: Vec<String>,
    /// Model: paper, lambert-glass or reduced-multilayer.
    #[arg(long)]
    pub model: String,
    /// Paper thickness d in mm (not fitted); default: from the data's `# thickness:` or `# params:` header.
    #[arg(long, allow_hyphen_values = true)]
    pub thickness: Option<f64>,
    /// Incident angles (degrees, comma-separated) to fit; points at other angles are extrapolation points, scored separately. Default: all.
    #[arg(long = "fit-theta-i", value_delimiter = ',', allow_hyphen_values = true)]
    pub fit_theta_i: Vec<f64>,
    /// Microfacet distributions to try per face (comma-separated: ggx, beckmann).
    #[arg(long, value_delimiter = ',', default_value = "ggx,beckmann")]
    pub dists: Vec<String>,
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
    #[arg(long = "face-scattering", default_value = "multiple", value_parser = parse_face_scattering)]
    pub face_scattering: FaceScattering,
}

fn parse_face_scattering(s: &str) -> Result<FaceScattering, String> {
    s.parse::<FaceScattering>().map_err(|e| e.to_string())
}

/// Parses a list of distribution names.
pub fn parse_dists(v: &[String]) -> Result<Vec<Distribution>> {
    v.iter()
        .map(|s| {
            Distribution::parse(s)
                .ok_or_else(|| anyhow!("--dists: unknown distribution `{s}` (expected ggx or beckmann)"))
        })
        .collect()
}

/// Runs `paperbsdf fit`.
pub fn run(args: FitArgs) -> Result<()> {
    if args.samples == 0 || args.starts == 0 || args.max_iter == 0 {
        bail!("--samples, --starts and --max-iter must be at least 1");
    }
    let dists = parse_dists(&args.dists)?;
    let ds = load_dataset(&args.data, args.thickness).map_err(|e| anyhow!(e))?;
    let cands = candidates_with_faces(
        &args.model,
        ds.thickness,
        ds.channels == 3,
        Some(&dists),
        args.face_scattering,
    )
    .map_err(|e| anyhow!(e))?;
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
        ..Default::default()
    };
    let out = fit(&ds.points, ds.channels, &cands, &opts)?;
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
    println!("seconds: {:.2}", out.seconds);
    if let Some(path) = &args.out {
        let json = out.to_json(&ds.origins, fit_theta_i.as_deref());
        let text = serde_json::to_string_pretty(&json)? + "\n";
        paperbsdf_io::write_atomic(path, text.as_bytes())?;
        println!("wrote {path}");
    }
    Ok(())
}
