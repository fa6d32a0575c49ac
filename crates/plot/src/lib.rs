//! # paperbsdf-plot
//!
//! In-plane BSDF plots in the style of the Paper BSDF supplement's Figures 3
//! to 5: per paper a row of BRDF panels over a row of BTDF panels, one column
//! per incident angle ([`Layout::Grid`]; [`Layout::Row`] puts them all in one
//! row), the measurement as red points with their standard-error bars, the
//! model's components (surface orange, single scattering cyan, multiple
//! scattering blue, ...) and their sum in black drawn over them, extrapolated
//! incident angles (not used in the fit) on a grey background. The horizontal
//! axis is the signed viewing angle `theta_o` of docs/design.md section 2 (positive
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

mod axes;
mod draw;
pub mod figures;
mod panels;

pub use axes::{linear_ticks, log_ticks, tick_label, TickedAxis};
pub use draw::{draw_figure, figure_size, register_font, render_rgb, svg_string};
pub use panels::{component_colour, curve_angles, panels_for, MEASUREMENT, TOTAL};

use paperbsdf_fit::Kind;

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
    /// A bundled paper measurement that [`figures::make_figures`] needs is missing.
    #[error("{file}: missing (the bundled {paper} paper measurement)")]
    MissingData {
        /// The expected file.
        file: String,
        /// The paper.
        paper: &'static str,
    },
    /// A data set of [`figures::make_figures`] could not be read, or its
    /// model not set up (the message names the file or the model).
    #[error("{message}")]
    Data {
        /// What is wrong.
        message: String,
    },
    /// A fit of [`figures::make_figures`] failed.
    #[error("{data}, {model}: {message}")]
    Fit {
        /// The data set.
        data: String,
        /// The model.
        model: &'static str,
        /// The fitter's message.
        message: String,
    },
    /// Writing a file other than a figure (the table of fit errors) failed.
    #[error(transparent)]
    Write(#[from] paperbsdf_io::DataError),
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
