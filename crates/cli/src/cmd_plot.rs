//! `paperbsdf plot`: in-plane plots of measurements and fitted models like the
//! supplement's Figures 3 to 5 (crate paperbsdf-plot), and `plot --figures`,
//! which fits every bundled paper with every model and writes the three
//! figures and the table of fit errors.
//!
//! A measured RGL `.bsdf` file is drawn as data: its in-plane slices at
//! `--theta-i` and `--theta-o`, sampled in memory exactly as `paperbsdf
//! convert` samples them ([`paperbsdf_fit::measured::sample_in_plane`]).

use crate::cmd_eval::MAX_EVAL_ANGLES;
use crate::cmd_fit::is_bsdf_file;
use anyhow::{anyhow, bail, Result};
use paperbsdf_fit::dataset::{load_dataset, Dataset};
use paperbsdf_fit::measured::{sample_in_plane, PointFilter, Sampling};
use paperbsdf_fit::models::build_from_params_with;
use paperbsdf_fit::FitOptions;
use paperbsdf_io::angles::check_angles;
use paperbsdf_io::models::{SlabSettings, SLAB_NODES_KEY};
use paperbsdf_plot::figures::{make_figures, FiguresOptions, DEFAULT_FIT_THETA_I};
use paperbsdf_plot::{draw_figure, panels_for, Figure, Layout, Row};
use std::path::PathBuf;

/// Arguments of `paperbsdf plot`.
#[derive(clap::Args, Debug)]
pub struct PlotArgs {
    /// Measurement files (CSV, or measured RGL `.bsdf` files drawn at --theta-i x --theta-o), one figure row each
    /// (not with --figures).
    pub data: Vec<String>,
    /// FIT.json files written by `paperbsdf fit`: one for all rows, or one per data file.
    #[arg(long)]
    pub fit: Vec<String>,
    /// Output file (.png, .svg or .pdf; default: the first data file's name with `_plot.png`, in the
    /// current directory); with --figures, the output directory (default docs).
    #[arg(long)]
    pub out: Option<String>,
    /// Panel layout.
    #[arg(long, value_enum, default_value_t = LayoutChoice::Grid, ignore_case = true)]
    pub layout: LayoutChoice,
    /// Size of one panel, WIDTHxHEIGHT in pixels (PNG) or points (SVG, PDF).
    #[arg(long = "panel-size", default_value = "300x220")]
    pub panel_size: String,
    /// Logarithmic value axis.
    #[arg(long)]
    pub log: bool,
    /// Incident angles that were fitted (others get a grey background). Default: from the FIT.json; for a fit of a
    /// `.bsdf` file without one, grey beyond its sampled incidences (0 to 75 degrees); else none grey.
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
    /// For a measured `.bsdf` file: the incident angles of its in-plane slices, degrees, comma-separated, in [0, 90)
    /// (default 0,30,60).
    #[arg(long = "theta-i", value_delimiter = ',', allow_hyphen_values = true)]
    pub theta_i: Vec<f64>,
    /// For a measured `.bsdf` file: the viewing angles of its slices, FROM:TO:STEP in degrees (signed; negative is
    /// opposite the light), within (-90, 90); default -85:85:5, the in-plane sampling of `paperbsdf fit`.
    #[arg(long = "theta-o", allow_hyphen_values = true)]
    pub theta_o: Option<String>,
    /// Leave out reflection points whose viewer is within DEG degrees of the light.
    #[arg(long = "exclude-retro", value_name = "DEG")]
    pub exclude_retro: Option<f64>,
    /// Leave out points whose light or viewer is more than DEG degrees from the normal.
    #[arg(long = "max-theta", value_name = "DEG")]
    pub max_theta: Option<f64>,
}

/// `plot --layout`: the choices of [`Layout`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum LayoutChoice {
    /// Per paper, BRDF panels over BTDF panels, one column per incident angle.
    Grid,
    /// All panels in one row.
    Row,
}

impl From<LayoutChoice> for Layout {
    fn from(c: LayoutChoice) -> Layout {
        match c {
            LayoutChoice::Grid => Layout::Grid,
            LayoutChoice::Row => Layout::Row,
        }
    }
}

/// The in-plane slices of a measured `.bsdf` file at `theta_i` x `theta_o` that `filter` keeps,
/// as a dataset (reflection only, RGB).
fn bsdf_dataset(path: &str, theta_i: &[f64], theta_o: &[f64], filter: &PointFilter) -> Result<Dataset> {
    let b = paperbsdf_io::MeasuredBsdf::load(path)?;
    let points = sample_in_plane(&b, theta_i, theta_o, filter);
    if points.is_empty() {
        bail!("{path}: every angle pair was left out by --exclude-retro / --max-theta: nothing to plot");
    }
    Ok(Dataset {
        origins: vec![path.to_string()],
        points,
        channels: 3,
        thickness: None,
        params_header: None,
    })
}

/// The incident angles a FIT.json `j` was fitted at, for grey (extrapolated) panels: its
/// `fit_theta_i`; for a fit of a `.bsdf` file without one, every plotted angle `plotted` within the
/// range of the fit's sampled incidences ([`Sampling::default`], less those beyond its
/// `--max-theta`), so that only angles beyond that range are grey; otherwise `None` (none grey).
fn fitted_angles(j: &serde_json::Value, plotted: &[f64]) -> Option<Vec<f64>> {
    if let Some(a) = j["fit_theta_i"].as_array() {
        return Some(a.iter().filter_map(|v| v.as_f64()).collect());
    }
    let from_bsdf = j["data"]
        .as_array()
        .is_some_and(|d| d.iter().any(|v| v.as_str().is_some_and(is_bsdf_file)));
    if !from_bsdf {
        return None;
    }
    let max = j["filters"]["max_theta_deg"].as_f64().unwrap_or(90.0);
    let sampled: Vec<f64> = Sampling::default()
        .theta_i
        .into_iter()
        .filter(|&t| t <= max + 1e-9)
        .collect();
    let (lo, hi) = (
        sampled.iter().copied().fold(f64::INFINITY, f64::min),
        sampled.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    Some(
        plotted
            .iter()
            .copied()
            .filter(|&t| t >= lo - 1e-6 && t <= hi + 1e-6)
            .collect(),
    )
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
    let layout = Layout::from(args.layout);
    let panel_size = parse_panel_size(&args.panel_size)?;
    if args.figures {
        if !args.data.is_empty() || !args.fit.is_empty() {
            bail!("--figures takes its data from --data-dir; do not also give data files or --fit");
        }
        if !args.theta_i.is_empty()
            || args.theta_o.is_some()
            || args.exclude_retro.is_some()
            || args.max_theta.is_some()
        {
            bail!("--theta-i, --theta-o, --exclude-retro and --max-theta do not apply to --figures");
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
    let filter = PointFilter {
        exclude_retro_deg: args.exclude_retro,
        max_theta_deg: args.max_theta,
    };
    filter.validate()?;
    let any_bsdf = args.data.iter().any(|p| is_bsdf_file(p));
    let (theta_i, theta_o) = if any_bsdf {
        let ti = if args.theta_i.is_empty() {
            vec![0.0, 30.0, 60.0]
        } else {
            args.theta_i.clone()
        };
        let to = paperbsdf_io::angles::parse_angles(
            args.theta_o.as_deref().unwrap_or("-85:85:5"),
            "--theta-o",
            MAX_EVAL_ANGLES,
        )?;
        check_angles(&ti, "--theta-i", 0.0..=89.999)?;
        check_angles(&to, "--theta-o", -89.999..=89.999)?;
        (ti, to)
    } else {
        if !args.theta_i.is_empty() || args.theta_o.is_some() {
            bail!("--theta-i and --theta-o choose the slices of a measured .bsdf file; the data files given are measurement files, which are plotted at their own angles");
        }
        (Vec::new(), Vec::new())
    };
    let mut rows = Vec::new();
    for (i, path) in args.data.iter().enumerate() {
        let ds = if is_bsdf_file(path) {
            bsdf_dataset(path, &theta_i, &theta_o, &filter)?
        } else {
            let mut ds = load_dataset(std::slice::from_ref(path), None)?;
            ds.points = filter.apply(std::mem::take(&mut ds.points));
            if ds.points.is_empty() {
                bail!("{path}: every point was left out by --exclude-retro / --max-theta: nothing to plot");
            }
            ds
        };
        let fit_file = args.fit.get(if args.fit.len() == 1 { 0 } else { i });
        let (model, mut fitted) = match fit_file {
            Some(f) => {
                let text = std::fs::read_to_string(f).map_err(|e| anyhow!("{f}: {e}"))?;
                let j: serde_json::Value = serde_json::from_str(&text).map_err(|e| anyhow!("{f}: {e}"))?;
                let name = j["model"].as_str().ok_or_else(|| anyhow!("{f}: no `model` string"))?;
                // A slab fit with the discretisation it was fitted with.
                let slab =
                    SlabSettings::recorded(j.get(SLAB_NODES_KEY), f)?.options(&format!("{f}: `{SLAB_NODES_KEY}`"))?;
                let m = build_from_params_with(name, &j["params"], &slab).map_err(|e| anyhow!("{f}: {e}"))?;
                let mut plotted: Vec<f64> = ds.points.iter().map(|p| p.theta_i).collect();
                plotted.dedup();
                (Some(m), fitted_angles(&j, &plotted))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Grey panels: a FIT.json's `fit_theta_i` decides; a `.bsdf` fit without one is fitted
    /// over its sampled incidences (0 to 75 degrees, or up to its `--max-theta`); a CSV fit
    /// without one marks none.
    #[test]
    fn fitted_angles_of_a_fit() {
        let plotted = [0.0, 30.0, 80.0];
        let j = serde_json::json!({"fit_theta_i": [30.0], "data": ["x.bsdf"]});
        assert_eq!(fitted_angles(&j, &plotted), Some(vec![30.0]));
        let j = serde_json::json!({"fit_theta_i": null, "data": ["m/satin.BSDF"]});
        assert_eq!(fitted_angles(&j, &plotted), Some(vec![0.0, 30.0]));
        let j = serde_json::json!({"fit_theta_i": null, "data": ["satin.bsdf"], "filters": {"max_theta_deg": 20.0}});
        assert_eq!(fitted_angles(&j, &plotted), Some(vec![0.0]));
        let j = serde_json::json!({"fit_theta_i": null, "data": ["data/matte.csv"]});
        assert_eq!(fitted_angles(&j, &plotted), None);
    }
}
