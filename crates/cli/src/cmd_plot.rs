//! `paperbsdf plot`: in-plane plots of measurements and fitted models like the
//! supplement's Figures 3 to 5 (crate paperbsdf-plot), and `plot --figures`,
//! which fits every bundled paper with every model and writes the three
//! figures and the table of fit errors.

use anyhow::{anyhow, bail, Result};
use paperbsdf_fit::dataset::load_dataset;
use paperbsdf_fit::models::build_from_params;
use paperbsdf_fit::FitOptions;
use paperbsdf_plot::figures::{make_figures, FiguresOptions, DEFAULT_FIT_THETA_I};
use paperbsdf_plot::{draw_figure, panels_for, Figure, Row};
use std::path::PathBuf;

/// Arguments of `paperbsdf plot`.
#[derive(clap::Args, Debug)]
pub struct PlotArgs {
    /// Measurement files, one figure row each (not with --figures).
    pub data: Vec<String>,
    /// FIT.json files written by `paperbsdf fit`: one for all rows, or one per data file.
    #[arg(long)]
    pub fit: Vec<String>,
    /// Output file (.png or .svg); with --figures, the output directory.
    #[arg(long)]
    pub out: Option<String>,
    /// Logarithmic value axis.
    #[arg(long)]
    pub log: bool,
    /// Incident angles that were fitted (others get a grey background). Default: from the FIT.json, else none grey.
    #[arg(long = "fit-theta-i", value_delimiter = ',', allow_hyphen_values = true)]
    pub fit_theta_i: Vec<f64>,
    /// Figure title.
    #[arg(long)]
    pub title: Option<String>,
    /// Fit matte, luster and glossy (and reference/devA.csv, devB.csv) in the directory --data-dir with all three models
    /// and write fig3_paper, fig4_lambert_glass, fig5_reduced_multilayer (.png, .svg, _log.png) and fit_table.md to --out (default docs).
    #[arg(long)]
    pub figures: bool,
    /// Data directory for --figures.
    #[arg(long = "data-dir", default_value = "data")]
    pub data_dir: String,
}

/// Runs `paperbsdf plot`.
pub fn run(args: PlotArgs) -> Result<()> {
    if args.figures {
        if !args.data.is_empty() || !args.fit.is_empty() {
            bail!("--figures takes its data from --data-dir; do not also give data files or --fit");
        }
        let fit_theta_i = if args.fit_theta_i.is_empty() {
            DEFAULT_FIT_THETA_I.to_vec()
        } else {
            args.fit_theta_i
        };
        let opts = FiguresOptions {
            data_dir: PathBuf::from(&args.data_dir),
            out_dir: PathBuf::from(args.out.as_deref().unwrap_or("docs")),
            fit_theta_i,
            fit: FitOptions {
                progress: true,
                ..Default::default()
            },
        };
        let rows = make_figures(&opts).map_err(|e| anyhow!(e))?;
        println!(
            "{} fits; wrote figures and fit_table.md to {}",
            rows.len(),
            opts.out_dir.display()
        );
        return Ok(());
    }
    if args.data.is_empty() {
        bail!("give measurement files to plot (or --figures)");
    }
    let out = args
        .out
        .clone()
        .ok_or_else(|| anyhow!("--out FILE.png or FILE.svg is required"))?;
    if !(args.fit.is_empty() || args.fit.len() == 1 || args.fit.len() == args.data.len()) {
        bail!(
            "give one --fit for all data files or one per data file ({} data files, {} fits)",
            args.data.len(),
            args.fit.len()
        );
    }
    let mut rows = Vec::new();
    for (i, path) in args.data.iter().enumerate() {
        let ds = load_dataset(std::slice::from_ref(path), None).map_err(|e| anyhow!(e))?;
        let fit_file = args.fit.get(if args.fit.len() == 1 { 0 } else { i });
        let (model, mut fitted) = match fit_file {
            Some(f) => {
                let text = std::fs::read_to_string(f).map_err(|e| anyhow!("{f}: {e}"))?;
                let j: serde_json::Value = serde_json::from_str(&text).map_err(|e| anyhow!("{f}: {e}"))?;
                let name = j["model"].as_str().ok_or_else(|| anyhow!("{f}: no `model` string"))?;
                let m = build_from_params(name, &j["params"]).map_err(|e| anyhow!("{f}: {e}"))?;
                let th: Option<Vec<f64>> = j["fit_theta_i"]
                    .as_array()
                    .map(|a| a.iter().filter_map(|v| v.as_f64()).collect());
                (Some(m), th)
            }
            None => (None, None),
        };
        if !args.fit_theta_i.is_empty() {
            fitted = Some(args.fit_theta_i.clone());
        }
        let label = std::path::Path::new(path)
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        let panels = panels_for(&ds.points, model.as_deref(), fitted.as_deref());
        if panels.is_empty() {
            bail!("{path}: no in-plane points to plot (general-direction files have no theta_o)");
        }
        rows.push(Row { label, panels });
    }
    let fig = Figure {
        title: args.title.unwrap_or_else(|| "in-plane BSDF".into()),
        rows,
        log_y: args.log,
    };
    draw_figure(&fig, std::path::Path::new(&out))?;
    println!("wrote {out}");
    Ok(())
}
