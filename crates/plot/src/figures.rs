//! The analogues of the supplement's Figures 3, 4 and 5 and the table of fit
//! errors: every bundled paper (`matte`, `luster`, `glossy` in the data
//! directory) and the reference sets `reference/devA.csv`, `reference/devB.csv` is fitted with each
//! of the three models (`paper`, `lambert-glass`, `reduced-multilayer`) on the
//! incident angles of [`DEFAULT_FIT_THETA_I`]; the other angles are
//! extrapolation (grey panels). One figure per model, one row per paper.

use crate::{draw_figure, panels_for, Figure, PlotError, Row};
use paperbsdf_core::models::ModelKind;
use paperbsdf_fit::dataset::load_dataset;
use paperbsdf_fit::models::candidates;
use paperbsdf_fit::{fit, FitOptions, FitOutcome};
use std::path::{Path, PathBuf};

/// Incident angles fitted by default (those a data set has); the others are extrapolation.
pub const DEFAULT_FIT_THETA_I: [f64; 3] = [0.0, 30.0, 60.0];

/// The bundled papers, in figure row order.
pub const PAPERS: [&str; 3] = ["matte", "luster", "glossy"];

/// The figures: (number, model, file stem, title).
pub const FIGURES: [(u32, ModelKind, &str, &str); 3] = [
    (
        3,
        ModelKind::Paper,
        "fig3_paper",
        "Paper BSDF fits (analogue of supplement Figure 3)",
    ),
    (
        4,
        ModelKind::LambertGlass,
        "fig4_lambert_glass",
        "Lambertian + rough glass fits (analogue of supplement Figure 4)",
    ),
    (
        5,
        ModelKind::ReducedMultilayer,
        "fig5_reduced_multilayer",
        "Reduced multilayer BSDF fits (analogue of supplement Figure 5)",
    ),
];

/// Settings of [`make_figures`].
#[derive(Clone, Debug)]
pub struct FiguresOptions {
    /// Arrangement of the panels.
    pub layout: crate::Layout,
    /// Size of one panel.
    pub panel_size: (u32, u32),
    /// Directory with `matte.csv`, `luster.csv`, `glossy.csv` and optionally `reference/devA.csv`, `reference/devB.csv`.
    pub data_dir: PathBuf,
    /// Output directory for the figures and `fit_table.md`.
    pub out_dir: PathBuf,
    /// Fitted incident angles.
    pub fit_theta_i: Vec<f64>,
    /// Fit settings (the `fit_theta_i` inside is replaced per data set).
    pub fit: FitOptions,
}

/// One fit of the table.
#[derive(Clone, Debug)]
pub struct TableRow {
    /// Data set name.
    pub data: String,
    /// The fit.
    pub outcome: FitOutcome,
}

/// The reference sets of `reference/` fitted beside the papers (if present).
const REFERENCE_SETS: [&str; 2] = ["devA", "devB"];

/// A data set or model that could not be set up: the fit crate's message,
/// which names the file or the model.
fn data_error(e: impl std::fmt::Display) -> PlotError {
    PlotError::Data { message: e.to_string() }
}

/// The data sets of the figures: `(name, file, drawn in the figures)`, the
/// bundled papers first (each must exist), then the reference sets present.
fn data_sets(dir: &Path) -> Result<Vec<(String, String, bool)>, PlotError> {
    let mut v = Vec::new();
    for p in PAPERS {
        let f = dir.join(format!("{p}.csv"));
        if !f.exists() {
            return Err(PlotError::MissingData {
                file: f.display().to_string(),
                paper: p,
            });
        }
        v.push((p.to_string(), f.display().to_string(), true));
    }
    // The in-plane brute-force references; the folder also holds the other
    // reference data of the tests (and devA_grazing.csv etc.), which are not fitted.
    for name in REFERENCE_SETS {
        let r = dir.join("reference").join(format!("{name}.csv"));
        if r.is_file() {
            v.push((name.to_string(), r.display().to_string(), false));
        }
    }
    Ok(v)
}

/// Fits every data set with every model, draws the three figures (PNG and SVG,
/// linear value axis, plus a PNG with a log axis) and writes `fit_table.md`.
/// Returns the table rows.
pub fn make_figures(opts: &FiguresOptions) -> Result<Vec<TableRow>, PlotError> {
    let sets = data_sets(&opts.data_dir)?;
    std::fs::create_dir_all(&opts.out_dir).map_err(|source| PlotError::Io {
        file: opts.out_dir.display().to_string(),
        source,
    })?;
    let mut table = Vec::new();
    for (num, kind, stem, title) in FIGURES {
        let model = kind.name();
        let mut rows = Vec::new();
        for (name, path, in_figure) in &sets {
            let ds = load_dataset(std::slice::from_ref(path), None).map_err(data_error)?;
            let present: Vec<f64> = opts
                .fit_theta_i
                .iter()
                .cloned()
                .filter(|t| ds.points.iter().any(|p| (p.theta_i - t).abs() < 1e-6))
                .collect();
            let cands = candidates(model, ds.thickness, ds.channels == 3, None).map_err(data_error)?;
            let fo = FitOptions {
                fit_theta_i: Some(present.clone()),
                ..opts.fit.clone()
            };
            let out = fit(&ds.points, ds.channels, &cands, &fo).map_err(|e| PlotError::Fit {
                data: name.clone(),
                model,
                message: e.to_string(),
            })?;
            eprintln!(
                "figure {num}: {name:>8} {model:>18}: rms {:.4}, extrapolation {:.4}, {:.2} s ({})",
                out.rms_log_error,
                out.extrapolation_rms_log_error.unwrap_or(f64::NAN),
                out.seconds,
                out.variant
            );
            if *in_figure {
                let m = cands[out.variant_index].build(&out.x).map_err(data_error)?;
                rows.push(Row {
                    label: name.clone(),
                    panels: panels_for(&ds.points, Some(m.as_ref()), Some(&present)),
                });
            }
            table.push(TableRow {
                data: name.clone(),
                outcome: out,
            });
        }
        let mut fig = Figure::new(format!("{title}; grey: extrapolated incident angles"), rows);
        fig.layout = opts.layout;
        fig.panel_size = opts.panel_size;
        for ext in ["png", "svg", "pdf"] {
            draw_figure(&fig, &opts.out_dir.join(format!("{stem}.{ext}")))?;
        }
        fig.log_y = true;
        draw_figure(&fig, &opts.out_dir.join(format!("{stem}_log.png")))?;
    }
    let md = table_markdown(&table, opts);
    paperbsdf_io::write_atomic(opts.out_dir.join("fit_table.md"), md.as_bytes())?;
    Ok(table)
}

/// An optional error with four decimals, `-` when absent.
fn fmt_opt(v: Option<f64>) -> String {
    v.map(|e| format!("{e:.4}")).unwrap_or_else(|| "-".into())
}

/// The Markdown table of fit errors (and the fitted parameters).
pub fn table_markdown(rows: &[TableRow], opts: &FiguresOptions) -> String {
    let mut s = String::from("# Fit errors\n\n");
    s += &format!(
        "Written by `paperbsdf plot --figures --data-dir {} --out {}` (the time of each fit is printed, not kept here, so that rerunning leaves this file unchanged). Each data set is fitted on the incident angles {:?} (those it has); \
         the remaining angles are extrapolation. Error: weighted RMS of ln((f_model + e)/(f_meas + e)), e = {}, \
         weights 1/max(stderr/(f_meas + e), {})^2 (crates/fit/src/objective.rs). The bundled sets are simulated \
         (data/README.md); `devA`, `devB` are the independent brute-force references (Mitsuba 3).\n\n",
        opts.data_dir.display(),
        opts.out_dir.display(),
        opts.fit_theta_i,
        paperbsdf_fit::objective::LOG_OFFSET,
        paperbsdf_fit::objective::SIGMA_FLOOR
    );
    s += "| data | model | fitted RMS log error | extrapolation RMS log error | fitted / extrap. points | distributions |\n";
    s += "|---|---|---|---|---|---|\n";
    let mut names: Vec<&str> = rows.iter().map(|r| r.data.as_str()).collect();
    names.dedup();
    let mut order: Vec<&str> = Vec::new();
    for n in names {
        if !order.contains(&n) {
            order.push(n);
        }
    }
    for n in &order {
        for r in rows.iter().filter(|r| r.data == *n) {
            let o = &r.outcome;
            s += &format!(
                "| {} | {} | {:.4} | {} | {} / {} | {} |\n",
                r.data,
                o.model,
                o.rms_log_error,
                fmt_opt(o.extrapolation_rms_log_error),
                o.counts.0,
                o.counts.1,
                o.variant
            );
        }
    }
    s +=
        "\n## Does the Paper BSDF win?\n\n| data | lowest fitted error | lowest extrapolation error |\n|---|---|---|\n";
    for n in &order {
        let rs: Vec<&TableRow> = rows.iter().filter(|r| r.data == *n).collect();
        let best_fit = rs
            .iter()
            .min_by(|a, b| a.outcome.rms_log_error.total_cmp(&b.outcome.rms_log_error))
            .unwrap();
        let best_ex = rs
            .iter()
            .filter(|r| r.outcome.extrapolation_rms_log_error.is_some())
            .min_by(|a, b| {
                a.outcome
                    .extrapolation_rms_log_error
                    .unwrap()
                    .total_cmp(&b.outcome.extrapolation_rms_log_error.unwrap())
            })
            .map(|r| r.outcome.model.as_str())
            .unwrap_or("-");
        s += &format!("| {n} | {} | {best_ex} |\n", best_fit.outcome.model);
    }
    s += "\n## Fitted parameters\n\n";
    for r in rows {
        s += &format!("- {} / {}: `{}`\n", r.data, r.outcome.model, r.outcome.params);
    }
    s
}
