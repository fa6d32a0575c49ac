//! The panels of one paper ([`panels_for`]): per incident angle a BRDF and a
//! BTDF panel with the measurement (points with standard errors) and a model's
//! components and sum evaluated at 1-degree steps of the in-plane viewing angle
//! (`paperbsdf_core::geometry::in_plane_directions`, docs/design.md section 2), in
//! the colours of the supplement's figures.

use crate::{Panel, Series, Style};
use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_fit::{ComponentModel, Kind, Point};

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
pub fn panels_for(points: &[Point], model: Option<&dyn ComponentModel>, fit_theta_i: Option<&[f64]>) -> Vec<Panel> {
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
                for (name, set) in m.legend() {
                    let pts: Vec<(f64, f64)> = angles
                        .iter()
                        .zip(&dirs)
                        .map(|(&o, &(wi, wo))| (o, m.eval_set(wi, wo, set).mean()))
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
