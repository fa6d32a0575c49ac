//! # paperbsdf-plot
//!
//! In-plane BSDF plots in the style of the Paper BSDF supplement's Figures 3
//! to 5: per paper a row of BRDF panels over a row of BTDF panels, one column
//! per incident angle ([`Layout::Grid`]; [`Layout::Row`] puts them all in one
//! row), the measurement as red points with their standard-error bars, the
//! model's components (surface orange, single scattering cyan, multiple
//! scattering blue, ...) and their sum in black drawn over them, extrapolated
//! incident angles (not used in the fit) on a grey background. The horizontal
//! axis is the signed viewing angle `theta_o` of DESIGN.md section 2 (positive
//! on the light's side); the value axis is linear or logarithmic, with ticks
//! at round values (1, 2, 5 times a power of ten on a log axis).
//!
//! Output is PNG (plotters' bitmap backend), SVG, or PDF (the SVG converted
//! by `svg2pdf` through `usvg`, text embedded as vector glyphs). Text is drawn with the
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
    /// Standard errors of the points (drawn as +-1 sigma bars), or empty.
    pub stderr: Vec<f64>,
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

/// How the panels of a figure are arranged.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Layout {
    /// Per paper, the BRDF panels in one line over the BTDF panels, one column
    /// per incident angle (as in the supplement's figures).
    #[default]
    Grid,
    /// Per paper, one line with every panel (BRDF and BTDF alternating).
    Row,
}

impl Layout {
    /// Parses `grid` or `row`.
    pub fn parse(s: &str) -> Option<Layout> {
        match s {
            "grid" => Some(Layout::Grid),
            "row" => Some(Layout::Row),
            _ => None,
        }
    }
}

/// Default size of one panel in pixels (PNG) or points (SVG, PDF).
pub const DEFAULT_PANEL_SIZE: (u32, u32) = (300, 220);

/// A whole figure.
#[derive(Clone, Debug)]
pub struct Figure {
    /// Title drawn at the top.
    pub title: String,
    /// The rows (one per paper).
    pub rows: Vec<Row>,
    /// Logarithmic value axis.
    pub log_y: bool,
    /// Arrangement of the panels.
    pub layout: Layout,
    /// Size of one panel, width and height.
    pub panel_size: (u32, u32),
}

impl Figure {
    /// A figure with a linear axis, the grid layout and the default panel size.
    pub fn new(title: impl Into<String>, rows: Vec<Row>) -> Figure {
        Figure {
            title: title.into(),
            rows,
            log_y: false,
            layout: Layout::Grid,
            panel_size: DEFAULT_PANEL_SIZE,
        }
    }

    /// The lines of panels as drawn: a label and one cell per column (`None`
    /// where a paper lacks that panel).
    pub fn lines(&self) -> Vec<(String, Vec<Option<&Panel>>)> {
        let mut out = Vec::new();
        match self.layout {
            Layout::Row => {
                for r in &self.rows {
                    out.push((r.label.clone(), r.panels.iter().map(Some).collect()));
                }
            }
            Layout::Grid => {
                // Columns: the incident angles of all rows, so that a column is one angle.
                let mut thetas: Vec<f64> = self
                    .rows
                    .iter()
                    .flat_map(|r| r.panels.iter().map(|p| p.theta_i))
                    .collect();
                thetas.sort_by(f64::total_cmp);
                thetas.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
                for r in &self.rows {
                    for (kind, what) in [(Kind::R, "BRDF"), (Kind::T, "BTDF")] {
                        if !r.panels.iter().any(|p| p.kind == kind) {
                            continue;
                        }
                        let cells = thetas
                            .iter()
                            .map(|t| r.panels.iter().find(|p| p.kind == kind && (p.theta_i - t).abs() < 1e-6))
                            .collect();
                        out.push((format!("{}: {what}", r.label), cells));
                    }
                }
            }
        }
        out
    }
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
            // (theta_o, f, stderr); a channel-mean f gets the channel-mean stderr.
            let mut meas: Vec<(f64, f64, Option<f64>)> = points
                .iter()
                .filter(|p| p.kind == kind && (p.theta_i - t).abs() < 1e-6)
                .filter_map(|p| p.theta_o.map(|o| (o, p.f.mean(), p.stderr.map(|s| s.mean()))))
                .collect();
            if meas.is_empty() {
                continue;
            }
            meas.sort_by(|a, b| a.0.total_cmp(&b.0));
            let meas_stderr: Vec<f64> = if meas.iter().all(|m| m.2.is_some()) {
                meas.iter().map(|m| m.2.unwrap_or(0.0)).collect()
            } else {
                Vec::new()
            };
            let meas: Vec<(f64, f64)> = meas.iter().map(|m| (m.0, m.1)).collect();
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
                        stderr: Vec::new(),
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
                    stderr: Vec::new(),
                    style: Style::Line,
                });
            }
            // The measurement first, so that the model's curves are drawn over it.
            series.insert(
                0,
                Series {
                    label: "measured".into(),
                    colour: MEASUREMENT,
                    points: meas,
                    stderr: meas_stderr,
                    style: Style::LineMarkers,
                },
            );
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

/// A tick value as people write it: at most `digits` significant digits,
/// no float noise (`0.30000000000000004` is `0.3`), no trailing zeros, and
/// scientific notation below 1e-3 or from 1e5 on.
pub fn tick_label(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return if x == 0.0 { "0".into() } else { format!("{x}") };
    }
    let e = x.abs().log10().floor() as i32;
    if !(-3..5).contains(&e) {
        let s = format!("{:.*e}", digits.saturating_sub(1), x);
        // 2.0e-4 -> 2e-4
        let (m, ex) = s.split_once('e').unwrap_or((&s, "0"));
        let m = if m.contains('.') {
            m.trim_end_matches('0').trim_end_matches('.')
        } else {
            m
        };
        return format!("{m}e{ex}");
    }
    let d = (digits as i32 - 1 - e).max(0) as usize;
    let s = format!("{x:.d$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Tick positions for a log axis from `10^lo` to `10^hi` (arguments are
/// log10 values; so are the results): the powers of ten, with 2 and 5 times
/// them when fewer than four decades are shown, and every 1..9 multiple when
/// less than one is, so that a panel always has at least two labelled ticks.
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = hi - lo;
    let mults: &[f64] = if span < 1.0 {
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    } else if span < 4.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let mut v = Vec::new();
    for k in (lo.floor() as i32 - 1)..=(hi.ceil() as i32) {
        for m in mults {
            let x = (m * 10f64.powi(k)).log10();
            if x >= lo - 1e-9 && x <= hi + 1e-9 {
                v.push(x);
            }
        }
    }
    if v.len() > 8 {
        // Thin to at most 8 ticks, keeping every n-th.
        let n = v.len().div_ceil(8);
        v = v.into_iter().step_by(n).collect();
    }
    v
}

/// Tick positions for a linear axis from `lo` to `hi`: 1, 2 or 5 times a
/// power of ten apart, about `n` of them.
pub fn linear_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let raw = (hi - lo) / n.max(1) as f64;
    if !(raw > 0.0 && raw.is_finite()) {
        return vec![lo];
    }
    let p = 10f64.powf(raw.log10().floor());
    // The round step nearest to `raw` in ratio, so that the count is about `n`
    // from either side (0..0.43 in 4: steps of 0.1, five ticks, not 0.2 and three).
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .min_by(|a, b| (a / raw).ln().abs().total_cmp(&(b / raw).ln().abs()))
        .unwrap_or(p);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// Registers the bundled DejaVu Sans as plotters' `sans-serif` (once per
/// process). Anything that draws text with plotters in this workspace must
/// call it first: with plotters' `ab_glyph` text backend there is no system
/// font lookup, and text fails with `FontUnavailable`.
pub fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        static FONT: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");
        // The bundled file is a valid TrueType font; a failure here would only lose the text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

const HEADER_H: u32 = 60;
const LABEL_W: u32 = 30;

/// Pixel size of `fig`: its lines of panels ([`Figure::lines`]) at `fig.panel_size`.
pub fn figure_size(fig: &Figure) -> (u32, u32) {
    let lines = fig.lines();
    let cols = lines.iter().map(|l| l.1.len()).max().unwrap_or(1).max(1) as u32;
    let (pw, ph) = fig.panel_size;
    (LABEL_W + cols * pw, HEADER_H + lines.len().max(1) as u32 * ph)
}

fn y_range(panel: &Panel, log_y: bool) -> (f64, f64) {
    // Values and the tops of the error bars.
    let vals = panel.series.iter().flat_map(|s| {
        s.points
            .iter()
            .enumerate()
            .map(move |(i, p)| p.1 + s.stderr.get(i).copied().unwrap_or(0.0))
    });
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

/// A linear axis from `lo` to `hi` whose grid lines and labels are exactly
/// `ticks` (plotters chooses its own key points otherwise, which on a log10
/// axis fall at non-round values).
#[derive(Clone, Debug)]
pub struct TickedAxis {
    /// Lower end of the axis.
    pub lo: f64,
    /// Upper end of the axis.
    pub hi: f64,
    /// Positions of the grid lines and labels.
    pub ticks: Vec<f64>,
}

impl plotters::coord::ranged1d::Ranged for TickedAxis {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;
    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let f = (v - self.lo) / (self.hi - self.lo);
        limit.0 + (f * (limit.1 - limit.0) as f64).round() as i32
    }
    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.max_num_points() == 0 {
            return Vec::new();
        }
        self.ticks.clone()
    }
    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// Draws one panel into `cell`: axes with round ticks, then the measurement
/// (points with +-1 standard-error bars, thin line), then the model's
/// components and its sum over it.
fn draw_panel<DB: DrawingBackend, E: Fn(DrawingAreaErrorKind<DB::ErrorType>) -> PlotError>(
    cell: &DrawingArea<DB, plotters::coord::Shift>,
    panel: &Panel,
    fig: &Figure,
    tick_font: u32,
    de: &E,
) -> Result<(), PlotError>
where
    DB::ErrorType: 'static,
{
    let log_y = fig.log_y;
    let (lo, hi) = y_range(panel, log_y);
    let caption = format!(
        "{} θi = {}°{}",
        if panel.kind == Kind::R { "BRDF" } else { "BTDF" },
        panel.theta_i,
        if panel.extrapolated { " (extrapolated)" } else { "" }
    );
    let y_ticks = if log_y {
        log_ticks(lo, hi)
    } else {
        linear_ticks(lo, hi, 4)
    };
    // Labels of the y ticks: as few significant digits as tell them apart.
    let digits = (1..=4)
        .find(|&d| {
            let l: Vec<String> = y_ticks
                .iter()
                .map(|v| tick_label(if log_y { 10f64.powf(*v) } else { *v }, d))
                .collect();
            l.windows(2).all(|w| w[0] != w[1])
        })
        .unwrap_or(4);
    let y_label = move |v: &f64| tick_label(if log_y { 10f64.powf(*v) } else { *v }, digits);
    let label_w =
        y_ticks.iter().map(|v| y_label(v).chars().count()).max().unwrap_or(3) as u32 * (tick_font * 6 / 10) + 10;
    let x_keys = vec![-90.0, -60.0, -30.0, 0.0, 30.0, 60.0, 90.0];
    let mut chart = ChartBuilder::on(cell)
        .caption(caption, ("sans-serif", tick_font + 2))
        .margin(5)
        .margin_right(10)
        .x_label_area_size(tick_font + 8)
        .y_label_area_size(label_w)
        .build_cartesian_2d(
            TickedAxis {
                lo: -90.0,
                hi: 90.0,
                ticks: x_keys,
            },
            TickedAxis { lo, hi, ticks: y_ticks },
        )
        .map_err(de)?;
    if panel.extrapolated {
        chart.plotting_area().fill(&RGBColor(222, 222, 222)).map_err(de)?;
    }
    chart
        .configure_mesh()
        .x_label_formatter(&|v| format!("{}", v.round() as i64))
        .y_label_formatter(&y_label)
        .label_style(("sans-serif", tick_font))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(225, 225, 225))
        .draw()
        .map_err(de)?;
    let to_y = |v: f64| if log_y { v.max(10f64.powf(lo)).log10() } else { v };
    for s in &panel.series {
        let col = RGBColor(s.colour.0, s.colour.1, s.colour.2);
        let width = match (s.label.as_str(), s.style) {
            (_, Style::LineMarkers) => 1,
            ("model", _) => 2,
            _ => 2,
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
        if s.style == Style::LineMarkers {
            // Error bars (+-1 standard error), clipped to the axis.
            for (p, e) in s.points.iter().zip(&s.stderr) {
                if p.1.is_finite() && *e > 0.0 && (!log_y || p.1 > 0.0) {
                    chart
                        .draw_series(std::iter::once(ErrorBar::new_vertical(
                            p.0,
                            to_y(p.1 - e).max(lo),
                            to_y(p.1),
                            to_y(p.1 + e).min(hi),
                            col.stroke_width(1),
                            4,
                        )))
                        .map_err(de)?;
                }
            }
        }
        let light = RGBColor(
            (s.colour.0 as u16 * 2 / 3 + 85) as u8,
            (s.colour.1 as u16 * 2 / 3 + 85) as u8,
            (s.colour.2 as u16 * 2 / 3 + 85) as u8,
        );
        for run in runs.iter().filter(|r| !r.is_empty()) {
            let c = if s.style == Style::LineMarkers { light } else { col };
            chart
                .draw_series(LineSeries::new(run.clone(), c.stroke_width(width)))
                .map_err(de)?;
        }
        if s.style == Style::LineMarkers {
            let pts: Vec<(f64, f64)> = runs.concat();
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 2, col.filled())))
                .map_err(de)?;
        }
    }
    Ok(())
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
        if !legend
            .iter()
            .any(|l| l.0 == s.label || (s.label == "measured" && l.0.starts_with("measured")))
        {
            legend.push((
                if s.label == "measured" && !s.stderr.is_empty() {
                    "measured ± 1 standard error".into()
                } else {
                    s.label.clone()
                },
                s.colour,
            ));
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
        } else if label.starts_with("measured") {
            header
                .draw(&PathElement::new(vec![(x + 12, 32), (x + 12, 46)], col.stroke_width(1)))
                .map_err(&de)?;
            header.draw(&Circle::new((x + 12, 39), 3, col.filled())).map_err(&de)?;
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
    let lines = fig.lines();
    let cols = lines.iter().map(|l| l.1.len()).max().unwrap_or(1).max(1);
    let areas = body.split_evenly((lines.len().max(1), 1));
    let label_font = (fig.panel_size.1 / 14).clamp(12, 18);
    let tick_font = (fig.panel_size.1 / 18).clamp(10, 14);
    for ((label, cells), area) in lines.iter().zip(areas) {
        let (label_area, panels_area) = area.split_horizontally(LABEL_W);
        let style = ("sans-serif", label_font)
            .into_font()
            .transform(FontTransform::Rotate270);
        let (_, h) = label_area.dim_in_pixel();
        let tw = (label_font as f64 * 0.55 * label.chars().count() as f64) as i32;
        label_area
            .draw(&Text::new(label.clone(), (6, h as i32 / 2 + tw / 2), style))
            .map_err(&de)?;
        let cell_areas = panels_area.split_evenly((1, cols));
        for (panel, cell) in cells.iter().zip(cell_areas) {
            let Some(panel) = panel else { continue };
            draw_panel(&cell, panel, fig, tick_font, &de)?;
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

/// `fig` drawn as the text of an SVG document.
pub fn svg_string(fig: &Figure, file: &str) -> Result<String, PlotError> {
    register_font();
    let size = figure_size(fig);
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, size).into_drawing_area();
        draw_on(root, fig, file)?;
    }
    Ok(s)
}

/// Converts the SVG of a figure to a one-page PDF (vector graphics; text in
/// the bundled DejaVu Sans, which stands for plotters' `sans-serif`).
fn svg_to_pdf(svg: &str, file: &str) -> Result<Vec<u8>, PlotError> {
    static FONT: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");
    let mut opt = usvg::Options::default();
    let db = opt.fontdb_mut();
    db.load_font_data(FONT.to_vec());
    db.set_sans_serif_family("DejaVu Sans");
    let invalid = |message: String| PlotError::Invalid {
        file: file.to_string(),
        message,
    };
    let tree = usvg::Tree::from_str(svg, &opt).map_err(|e| invalid(format!("SVG for PDF: {e}")))?;
    svg2pdf::to_pdf(
        &tree,
        svg2pdf::ConversionOptions::default(),
        svg2pdf::PageOptions::default(),
    )
    .map_err(|e| invalid(format!("PDF conversion: {e}")))
}

/// Draws `fig` to `path`: PNG, SVG or PDF by the file's extension. Atomic: a
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
    if ext != "png" && ext != "svg" && ext != "pdf" {
        return Err(PlotError::Invalid {
            file,
            message: format!("unknown figure type `.{ext}`: use .png, .svg or .pdf"),
        });
    }
    let size = figure_size(fig);
    // The shared atomic writer: output directory checked, links written
    // through, non-regular targets refused, no temporary file left behind.
    let message = |e: PlotError| match e {
        PlotError::Draw { message, .. } => format!("drawing failed: {message}"),
        other => other.to_string(),
    };
    paperbsdf_io::atomic::write_atomic_with(path, |tmp| match ext.as_str() {
        "png" => draw_on(BitMapBackend::new(tmp, size).into_drawing_area(), fig, &file).map_err(message),
        "svg" => draw_on(SVGBackend::new(tmp, size).into_drawing_area(), fig, &file).map_err(message),
        _ => svg_string(fig, &file)
            .and_then(|svg| svg_to_pdf(&svg, &file))
            .map_err(message)
            .and_then(|pdf| std::fs::write(tmp, pdf).map_err(|e| e.to_string())),
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
