//! Drawing a [`Figure`] with plotters: the header (title and legend), the
//! row labels, one chart per panel (round ticks from [`crate::axes`], error
//! bars, the model's curves over the measurement, a grey background for
//! extrapolated angles), and the output formats: PNG, SVG, an RGB buffer, and
//! PDF converted from the SVG by `svg2pdf`. Text is the bundled DejaVu Sans.

use crate::axes::{linear_ticks, log_ticks, tick_label, y_range, TickedAxis};
use crate::{Figure, Panel, PlotError, Style};
use paperbsdf_fit::Kind;
use plotters::prelude::*;
use std::path::Path;

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

fn draw_err<E: std::fmt::Display>(file: &str) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError::Draw {
        file: file.to_string(),
        message: e.to_string(),
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
    paperbsdf_io::atomic::write_atomic_with(path, |tmp| match ext.as_str() {
        "png" => draw_on(BitMapBackend::new(tmp, size).into_drawing_area(), fig, &file).map_err(WriteFailure::from),
        "svg" => draw_on(SVGBackend::new(tmp, size).into_drawing_area(), fig, &file).map_err(WriteFailure::from),
        _ => {
            let pdf = svg_string(fig, &file).and_then(|svg| svg_to_pdf(&svg, &file))?;
            std::fs::write(tmp, pdf).map_err(WriteFailure::Io)
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

/// Why writing a figure's temporary file failed, as the atomic writer reports
/// it after the file's name: a drawing failure without the file (which the
/// writer adds), other errors whole.
#[derive(Debug, thiserror::Error)]
enum WriteFailure {
    /// The drawing backend's message.
    #[error("drawing failed: {0}")]
    Draw(String),
    /// Any other error of the figure.
    #[error(transparent)]
    Plot(PlotError),
    /// Writing the PDF failed.
    #[error(transparent)]
    Io(std::io::Error),
}

impl From<PlotError> for WriteFailure {
    fn from(e: PlotError) -> Self {
        match e {
            PlotError::Draw { message, .. } => WriteFailure::Draw(message),
            other => WriteFailure::Plot(other),
        }
    }
}
