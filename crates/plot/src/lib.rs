//! # paperbsdf-plot
//!
//! In-plane BSDF plots in the style of the Paper BSDF supplement's Figures 3
//! to 5: one row per paper, a BRDF and a BTDF panel per incident angle, the
//! measurement in red, the model's components (surface orange, single
//! scattering cyan, multiple scattering blue, ...) and their sum in black,
//! extrapolated incident angles (not used in the fit) on a grey background.
//! The horizontal axis is the signed viewing angle `theta_o` of DESIGN.md
//! section 2 (positive on the light's side); the value axis is linear or
//! logarithmic.
//!
//! Output is PNG (plotters' bitmap backend) or SVG. Text is drawn with the
//! DejaVu Sans font bundled in `fonts/` (through plotters' `ab_glyph`
//! feature), so the plots look the same on any machine, with or without
//! system fonts. Files are written atomically (a temporary file in the same
//! directory, then a rename).

#![warn(missing_docs)]

pub mod figures;

use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_fit::{Evaluable, Kind, Point};
use plotters::prelude::*;
use std::path::Path;

/// An error drawing or writing a figure.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The drawing backend failed.
    #[error("{file}: drawing failed: {message}")]
    Draw {
        /// The output file.
        file: String,
        /// The backend's message.
        message: String,
    },
    /// Writing the file failed.
    #[error("{file}: {source}")]
    Io {
        /// The output file.
        file: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The figure cannot be drawn (no rows, unknown file type).
    #[error("{file}: {message}")]
    Invalid {
        /// The output file.
        file: String,
        /// What is wrong.
        message: String,
    },
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// A line.
    Line,
    /// A line through filled circles (measurements).
    LineMarkers,
}

/// One curve of a panel.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Colour (r, g, b).
    pub colour: (u8, u8, u8),
    /// `(theta_o in degrees, f)` pairs.
    pub points: Vec<(f64, f64)>,
    /// How it is drawn.
    pub style: Style,
}

/// One panel: the BRDF or BTDF at one incident angle.
#[derive(Clone, Debug)]
pub struct Panel {
    /// Reflection or transmission.
    pub kind: Kind,
    /// Incident angle, degrees.
    pub theta_i: f64,
    /// Whether this incident angle was not used in the fit (grey background).
    pub extrapolated: bool,
    /// The curves.
    pub series: Vec<Series>,
}

/// One row: one paper.
#[derive(Clone, Debug)]
pub struct Row {
    /// Row label (the paper's name).
    pub label: String,
    /// The panels, left to right.
    pub panels: Vec<Panel>,
}

/// A whole figure.
#[derive(Clone, Debug)]
pub struct Figure {
    /// Title drawn at the top.
    pub title: String,
    /// The rows.
    pub rows: Vec<Row>,
    /// Logarithmic value axis.
    pub log_y: bool,
}

/// Colour of the measurement.
pub const MEASUREMENT: (u8, u8, u8) = (220, 20, 20);
/// Colour of the model's sum.
pub const TOTAL: (u8, u8, u8) = (0, 0, 0);

/// The colour of a model component by name (the supplement's colours:
/// surface orange, single scattering cyan, multiple scattering blue; the
/// Lambert-glass baseline: Lambertian blue, rough glass orange).
pub fn component_colour(name: &str) -> (u8, u8, u8) {
    match name {
        "surface" | "rough glass" => (255, 140, 0),
        "single" => (0, 190, 210),
        "multiple" | "lambert" => (30, 60, 220),
        "direct" => (150, 60, 190),
        _ => (110, 110, 110),
    }
}

/// Viewing angles at which model curves are evaluated: -89 to 89 degrees in steps of 1.
pub fn curve_angles() -> Vec<f64> {
    (-89..=89).map(|t| t as f64).collect()
}

/// The panels of one paper: for each incident angle of `points` (sorted) a
/// BRDF and a BTDF panel (when the data have that kind) with the measurement
/// and, when `model` is given, its components and sum. `fit_theta_i`: the
/// fitted angles (others are marked extrapolated); `None` marks none.
pub fn panels_for(points: &[Point], model: Option<&dyn Evaluable>, fit_theta_i: Option<&[f64]>) -> Vec<Panel> {
    let mut thetas: Vec<f64> = points.iter().map(|p| p.theta_i).collect();
    thetas.sort_by(|a, b| a.partial_cmp(b).unwrap());
    thetas.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    let mut panels = Vec::new();
    for &t in &thetas {
        for kind in [Kind::R, Kind::T] {
            let mut meas: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.kind == kind && (p.theta_i - t).abs() < 1e-6)
                .filter_map(|p| p.theta_o.map(|o| (o, p.f.mean())))
                .collect();
            if meas.is_empty() {
                continue;
            }
            meas.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
            let mut series = Vec::new();
            if let Some(m) = model {
                let angles = curve_angles();
                let dirs: Vec<_> = angles
                    .iter()
                    .map(|&o| in_plane_directions(t, o, kind == Kind::T))
                    .collect();
                for (ci, name) in m.component_names().iter().enumerate() {
                    let pts: Vec<(f64, f64)> = angles
                        .iter()
                        .zip(&dirs)
                        .map(|(&o, &(wi, wo))| (o, m.eval_component(ci, wi, wo).mean()))
                        .collect();
                    if pts.iter().all(|p| p.1 == 0.0) {
                        continue;
                    }
                    series.push(Series {
                        label: name.to_string(),
                        colour: component_colour(name),
                        points: pts,
                        style: Style::Line,
                    });
                }
                let pts = angles
                    .iter()
                    .zip(&dirs)
                    .map(|(&o, &(wi, wo))| (o, m.eval(wi, wo).mean()))
                    .collect();
                series.push(Series {
                    label: "model".into(),
                    colour: TOTAL,
                    points: pts,
                    style: Style::Line,
                });
            }
            series.push(Series {
                label: "measured".into(),
                colour: MEASUREMENT,
                points: meas,
                style: Style::LineMarkers,
            });
            let extrapolated = fit_theta_i
                .map(|l| !l.iter().any(|x| (x - t).abs() < 1e-6))
                .unwrap_or(false);
            panels.push(Panel {
                kind,
                theta_i: t,
                extrapolated,
                series,
            });
        }
    }
    panels
}

/// `x` with two significant digits (plain decimal notation).
fn sig2(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let d = (1 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.d$}")
}

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        static FONT: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");
        // The bundled file is a valid TrueType font; a failure here would only lose the text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

const PANEL_W: u32 = 250;
const PANEL_H: u32 = 200;
const HEADER_H: u32 = 56;
const LABEL_W: u32 = 28;

/// Pixel size of `fig`.
pub fn figure_size(fig: &Figure) -> (u32, u32) {
    let cols = fig.rows.iter().map(|r| r.panels.len()).max().unwrap_or(1).max(1) as u32;
    (
        LABEL_W + cols * PANEL_W,
        HEADER_H + fig.rows.len().max(1) as u32 * PANEL_H,
    )
}

fn y_range(panel: &Panel, log_y: bool) -> (f64, f64) {
    let vals = panel.series.iter().flat_map(|s| s.points.iter().map(|p| p.1));
    if log_y {
        let pos: Vec<f64> = vals.filter(|v| *v > 0.0 && v.is_finite()).collect();
        let hi = pos.iter().cloned().fold(1e-6, f64::max);
        // Down to the smallest positive value (measurement or component), but at
        // most four decades below the largest.
        let min = pos.iter().cloned().fold(f64::INFINITY, f64::min);
        let lo = (min * 0.8).max(hi * 1e-4).min(hi * 0.1);
        (lo.log10(), hi.log10() + 0.15)
    } else {
        let hi = vals.filter(|v| v.is_finite()).fold(0.0, f64::max);
        (0.0, if hi > 0.0 { hi * 1.08 } else { 1.0 })
    }
}

fn draw_err<E: std::fmt::Display>(file: &str) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError::Draw {
        file: file.to_string(),
        message: e.to_string(),
    }
}

fn draw_on<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    fig: &Figure,
    file: &str,
) -> Result<(), PlotError>
where
    DB::ErrorType: 'static,
{
    let de = draw_err(file);
    root.fill(&WHITE).map_err(&de)?;
    let (w, _) = root.dim_in_pixel();
    let (header, body) = root.split_vertically(HEADER_H);
    let title = format!(
        "{}   [x: θo in degrees, + on the light's side; y: f in 1/sr{}]",
        fig.title,
        if fig.log_y { ", log scale" } else { "" }
    );
    header
        .draw(&Text::new(title, (10, 6), ("sans-serif", 18).into_font()))
        .map_err(&de)?;
    // Legend: every label that occurs, in order of first appearance.
    let mut legend: Vec<(String, (u8, u8, u8))> = Vec::new();
    for s in fig
        .rows
        .iter()
        .flat_map(|r| r.panels.iter().flat_map(|p| p.series.iter()))
    {
        if !legend.iter().any(|l| l.0 == s.label) {
            legend.push((s.label.clone(), s.colour));
        }
    }
    legend.push(("extrapolated (not fitted)".into(), (200, 200, 200)));
    let mut x = 10i32;
    for (label, c) in &legend {
        let col = RGBColor(c.0, c.1, c.2);
        if label.starts_with("extrapolated") {
            header
                .draw(&Rectangle::new([(x, 32), (x + 24, 46)], col.filled()))
                .map_err(&de)?;
        } else {
            header
                .draw(&PathElement::new(vec![(x, 39), (x + 24, 39)], col.stroke_width(3)))
                .map_err(&de)?;
        }
        header
            .draw(&Text::new(label.clone(), (x + 30, 31), ("sans-serif", 14).into_font()))
            .map_err(&de)?;
        x += 40 + 8 * label.len() as i32;
        if x > w as i32 - 100 {
            break;
        }
    }
    let rows = body.split_evenly((fig.rows.len().max(1), 1));
    for (row, area) in fig.rows.iter().zip(rows) {
        let (label_area, panels_area) = area.split_horizontally(LABEL_W);
        let style = ("sans-serif", 16).into_font().transform(FontTransform::Rotate270);
        let (_, h) = label_area.dim_in_pixel();
        let tw = 9 * row.label.len() as i32;
        label_area
            .draw(&Text::new(row.label.clone(), (4, h as i32 / 2 + tw / 2), style))
            .map_err(&de)?;
        let cols = fig.rows.iter().map(|r| r.panels.len()).max().unwrap_or(1).max(1);
        let cells = panels_area.split_evenly((1, cols));
        for (panel, cell) in row.panels.iter().zip(cells) {
            let (lo, hi) = y_range(panel, fig.log_y);
            let caption = format!(
                "{} θi = {}°{}",
                if panel.kind == Kind::R { "BRDF" } else { "BTDF" },
                panel.theta_i,
                if panel.extrapolated { " (extrap.)" } else { "" }
            );
            let mut chart = ChartBuilder::on(&cell)
                .caption(caption, ("sans-serif", 14))
                .margin(4)
                .x_label_area_size(22)
                .y_label_area_size(40)
                .build_cartesian_2d(-90f64..90f64, lo..hi)
                .map_err(&de)?;
            if panel.extrapolated {
                chart.plotting_area().fill(&RGBColor(222, 222, 222)).map_err(&de)?;
            }
            let log_y = fig.log_y;
            let fmt = move |v: &f64| if log_y { sig2(10f64.powf(*v)) } else { sig2(*v) };
            chart
                .configure_mesh()
                .x_labels(7)
                .y_labels(5)
                .x_label_formatter(&|v| format!("{v:.0}"))
                .y_label_formatter(&fmt)
                .label_style(("sans-serif", 11))
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(&de)?;
            for s in &panel.series {
                let col = RGBColor(s.colour.0, s.colour.1, s.colour.2);
                let width = if s.label == "model" || s.label == "measured" {
                    3
                } else {
                    2
                };
                // Runs of drawable points: on a log axis, values below the axis are left out
                // (the curve is broken there rather than drawn along the bottom edge).
                let mut runs: Vec<Vec<(f64, f64)>> = vec![vec![]];
                for p in s.points.iter().filter(|p| p.1.is_finite()) {
                    if log_y && !(p.1 > 0.0 && p.1.log10() >= lo) {
                        runs.push(vec![]);
                    } else {
                        let y = if log_y { p.1.log10() } else { p.1 };
                        runs.last_mut().unwrap().push((p.0, y));
                    }
                }
                for run in runs.iter().filter(|r| !r.is_empty()) {
                    chart
                        .draw_series(LineSeries::new(run.clone(), col.stroke_width(width)))
                        .map_err(&de)?;
                }
                let pts: Vec<(f64, f64)> = runs.concat();
                if s.style == Style::LineMarkers {
                    chart
                        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, col.filled())))
                        .map_err(&de)?;
                }
            }
        }
    }
    root.present().map_err(&de)?;
    Ok(())
}

/// Renders `fig` into an RGB8 buffer (row-major, 3 bytes per pixel) of size [`figure_size`].
pub fn render_rgb(fig: &Figure) -> Result<(Vec<u8>, u32, u32), PlotError> {
    register_font();
    let (w, h) = figure_size(fig);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        draw_on(root, fig, "<buffer>")?;
    }
    Ok((buf, w, h))
}

/// Draws `fig` to `path`: PNG or SVG by the file's extension. Atomic: a
/// temporary file in the same directory is renamed into place.
pub fn draw_figure(fig: &Figure, path: &Path) -> Result<(), PlotError> {
    register_font();
    let file = path.display().to_string();
    if fig.rows.is_empty() {
        return Err(PlotError::Invalid {
            file,
            message: "nothing to plot (no rows)".into(),
        });
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext != "png" && ext != "svg" {
        return Err(PlotError::Invalid {
            file,
            message: format!("unknown figure type `.{ext}`: use .png or .svg"),
        });
    }
    let size = figure_size(fig);
    // The shared atomic writer: output directory checked, links written
    // through, non-regular targets refused, no temporary file left behind.
    let message = |e: PlotError| match e {
        PlotError::Draw { message, .. } => format!("drawing failed: {message}"),
        other => other.to_string(),
    };
    paperbsdf_io::atomic::write_atomic_with(path, |tmp| {
        if ext == "png" {
            draw_on(BitMapBackend::new(tmp, size).into_drawing_area(), fig, &file).map_err(message)
        } else {
            draw_on(SVGBackend::new(tmp, size).into_drawing_area(), fig, &file).map_err(message)
        }
    })
    .map_err(|e| match e {
        paperbsdf_io::DataError::Io { source, .. } => PlotError::Io {
            file: file.clone(),
            source,
        },
        paperbsdf_io::DataError::Other { message, .. } => PlotError::Invalid {
            file: file.clone(),
            message,
        },
        other => PlotError::Invalid {
            file: file.clone(),
            message: other.to_string(),
        },
    })
}
