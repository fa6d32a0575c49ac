//! `paperbsdf plot`: in-plane plots of measurements and fitted models like the
//! supplement's Figures 3 to 5 (crate paperbsdf-plot), and `plot --figures`,
//! which fits every bundled paper with every model and writes the three
//! figures and the table of fit errors.

use anyhow::{anyhow, bail, Result};
use paperbsdf_fit::dataset::load_dataset;
use paperbsdf_fit::models::build_from_params;
use paperbsdf_fit::FitOptions;
use paperbsdf_plot::figures::{make_figures, FiguresOptions, DEFAULT_FIT_THETA_I};
use paperbsdf_plot::{draw_figure, panels_for, Figure, Layout, Row};
use std::path::PathBuf;

/// Arguments of `paperbsdf plot`.
#[derive(clap::Args, Debug)]
pub struct PlotArgs {
    /// Measurement files, one figure row each (not with --figures).
    pub data: Vec<String>,
    /// FIT.json files written by `paperbsdf fit`: one for all rows, or one per data file.
    #[arg(long)]
    pub fit: Vec<String>,
    /// Output file (.png, .svg or .pdf; default: the first data file's name with `_plot.png`, in the
    /// current directory); with --figures, the output directory (default docs).
    #[arg(long)]
    pub out: Option<String>,
    /// Panel layout: grid (per paper, BRDF panels over BTDF panels, one column per incident angle) or row (all in one row).
    #[arg(long, default_value = "grid")]
    pub layout: String,
    /// Size of one panel, WIDTHxHEIGHT in pixels (PNG) or points (SVG, PDF).
    #[arg(long = "panel-size", default_value = "300x220")]
    pub panel_size: String,
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

/// Parses `WIDTHxHEIGHT` (each 120 to 2000).
pub fn parse_panel_size(s: &str) -> Result<(u32, u32)> {
    let bad =
        || anyhow!("--panel-size `{s}`: expected WIDTHxHEIGHT, each a whole number from 120 to 2000, e.g. 300x220");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if !(120..=2000).contains(&w) || !(120..=2000).contains(&h) {
        return Err(bad());
    }
    Ok((w, h))
}

/// Runs `paperbsdf plot`.
pub fn run(args: PlotArgs) -> Result<()> {
    let layout =
        Layout::parse(&args.layout).ok_or_else(|| anyhow!("--layout `{}`: expected grid or row", args.layout))?;
    let panel_size = parse_panel_size(&args.panel_size)?;
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
            layout,
            panel_size,
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
    let out = match &args.out {
        Some(o) => o.clone(),
        None => {
            let stem = std::path::Path::new(&args.data[0])
                .file_stem()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_else(|| "plot".into());
            format!("{stem}_plot.png")
        }
    };
    paperbsdf_io::check_output_path(&out, "--out")?;
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
    let mut fig = Figure::new(args.title.unwrap_or_else(|| "in-plane BSDF".into()), rows);
    fig.log_y = args.log;
    fig.layout = layout;
    fig.panel_size = panel_size;
    draw_figure(&fig, std::path::Path::new(&out))?;
    println!("wrote {out}");
    Ok(())
}
