//! Accuracy of the analytic Paper BSDF against the ground truth.
//!
//! `cargo run --release -p paperbsdf-sim --example accuracy [-- --walks N --out-dir DIR --face-scattering MODE]`
//! writes `DIR/accuracy.md` (default `docs/`) and one plot per case
//! (`DIR/accuracy_<case>.svg`) for the default faces (`face_scattering =
//! "multiple"`, in the model and in the simulator), or with `--face-scattering
//! single` (Walter's faces in both) `DIR/accuracy_single.md` and
//! `DIR/accuracy_single_<case>.svg`. For each case (the three presets, devA, devB and
//! a spread of slabs from thin to thick and smooth to rough) and each incident
//! angle (0, 30, 60, 75 degrees), the simulator estimates the in-plane BSDF at
//! `theta_o = -80..80` step 10 in reflection and transmission, split by the
//! number of volume scattering events, together with the total reflectance and
//! transmittance; the model (`PaperBsdf::eval` and `eval_component`) is
//! evaluated at the same directions and its directional albedo by
//! `bsdf::sampled_albedo`. Reported: the RMS log error
//! `sqrt(mean(ln((f_model + e) / (f_sim + e))^2))` with `e = 1e-3`, the
//! albedo errors, and which component (surface/unscattered = order 0, single =
//! order 1, multiple = order >= 2) carries the largest error.
//!
//! With `--slab` it compares both models, the Paper BSDF and the numerical
//! model `slab` (`paperbsdf_slab::SlabBsdf`, adding-doubling), against the same
//! simulations and writes `DIR/accuracy_slab.md` (`accuracy_single_slab.md`)
//! instead: per case and incident angle the RMS log errors of both, the
//! noise floor, and `slab`'s albedo and component errors (orders 0, 1 and
//! 2+ against its surface + direct, `single` and `multiple`; until
//! 2026-12-07 its `multiple` held every scattering order and orders 1 and
//! 2+ were compared together).

use paperbsdf_core::bsdf::sampled_albedo;
use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::models::ComponentModel;
use paperbsdf_core::paper::{Component, PaperBsdf};
use paperbsdf_core::{Bsdf, PaperParams, Rgb};
use paperbsdf_sim::{simulate_bsdf, Estimate, SimConfig, Slab};
use paperbsdf_slab::SlabBsdf;
use plotters::prelude::*;
use std::fmt::Write as _;

#[path = "support/cases.rs"]
mod cases;
use cases::cases;

const THETA_I: [f64; 4] = [0.0, 30.0, 60.0, 75.0];
const E_LOG: f64 = 1e-3;

/// One in-plane point: sim total and by order, model total and components.
struct Point {
    transmission: bool,
    theta_o: f64,
    sim: Estimate,
    sim_order: [Estimate; 3],
    model: Rgb,
    /// Model split like the simulator's orders: surface + direct, single, multiple.
    model_order: [Rgb; 3],
    /// `slab` (with `--slab`): its value, and its split like the
    /// simulator's orders: surface + direct, single, multiple.
    slab: Option<(Rgb, [Rgb; 3])>,
}

struct AngleResult {
    theta_i: f64,
    points: Vec<Point>,
    sim_r: Estimate,
    sim_t: Estimate,
    model_r: Rgb,
    model_t: Rgb,
    /// `slab`'s directional albedo (with `--slab`).
    slab_rt: Option<(Rgb, Rgb)>,
}

fn log_err(m: f64, s: f64) -> f64 {
    ((m.max(0.0) + E_LOG) / (s.max(0.0) + E_LOG)).ln()
}

fn channels(p: &PaperParams) -> usize {
    if p.is_rgb() {
        3
    } else {
        1
    }
}

fn rms_log(points: &[&Point], nc: usize) -> f64 {
    rms_log_of(points, nc, |p| p.model)
}

/// [`rms_log`] of the model values `value(point)`.
fn rms_log_of(points: &[&Point], nc: usize, value: impl Fn(&Point) -> Rgb) -> f64 {
    let mut s = 0.0;
    let mut n = 0;
    for p in points {
        let v = value(p);
        for c in 0..nc {
            s += log_err(v.0[c], p.sim.mean.0[c]).powi(2);
            n += 1;
        }
    }
    (s / n.max(1) as f64).sqrt()
}

/// `slab`'s component errors, order by order (as [`component_errors`]):
/// order 0 against its surface + direct, order 1 against its `single`, 2+
/// against its `multiple`.
fn slab_component_errors(points: &[&Point], nc: usize) -> [f64; 3] {
    relative_errors(points, nc, |p, k, c| {
        let (_, parts) = p.slab.as_ref()?;
        Some((parts[k].0[c], p.sim_order[k].mean.0[c]))
    })
}

/// Per part `k < K`: the RMS over points and channels of
/// `(model - sim) / (f_sim + e)`, with `(model, sim) = part(point, k, channel)`
/// (points where it is `None` left out).
fn relative_errors<const K: usize>(
    points: &[&Point],
    nc: usize,
    part: impl Fn(&Point, usize, usize) -> Option<(f64, f64)>,
) -> [f64; K] {
    let mut out = [0.0; K];
    for (k, o) in out.iter_mut().enumerate() {
        let mut s = 0.0;
        let mut n = 0;
        for p in points {
            for c in 0..nc {
                let Some((m, sim)) = part(p, k, c) else { continue };
                s += ((m - sim) / (p.sim.mean.0[c] + E_LOG)).powi(2);
                n += 1;
            }
        }
        *o = (s / n.max(1) as f64).sqrt();
    }
    out
}

/// The RMS log error the simulation's own noise alone would give: sqrt(mean((se / (f + e))^2)).
fn noise_floor(points: &[&Point], nc: usize) -> f64 {
    let mut s = 0.0;
    let mut n = 0;
    for p in points {
        for c in 0..nc {
            s += (p.sim.stderr.0[c] / (p.sim.mean.0[c].max(0.0) + E_LOG)).powi(2);
            n += 1;
        }
    }
    (s / n.max(1) as f64).sqrt()
}

/// RMS over points and channels of (model_k - sim_k) / (sim + e), per order k.
fn component_errors(points: &[&Point], nc: usize) -> [f64; 3] {
    relative_errors(points, nc, |p, k, c| {
        Some((p.model_order[k].0[c], p.sim_order[k].mean.0[c]))
    })
}

const ORDER_NAMES: [&str; 3] = ["surface/unscattered", "single", "multiple"];

fn plot(path: &str, title: &str, res: &[AngleResult], rgb: bool) -> Result<(), Box<dyn std::error::Error>> {
    paperbsdf_plot::register_font();
    let root = SVGBackend::new(path, (1200, 900)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let panels = root.split_evenly((2, 2));
    for (panel, r) in panels.iter().zip(res) {
        let vals = r.points.iter().flat_map(|p| [p.sim.mean.0[0], p.model.0[0]]);
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for v in vals {
            if v > 0.0 {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        let lo = (lo * 0.7).max(1e-4);
        let hi = (hi * 1.5).max(lo * 10.0);
        // Log10 coordinates with ticks at round values (paperbsdf-plot's helpers), so
        // labels read 0.03, 0.05, 0.1, ... rather than float noise.
        let (llo, lhi) = (lo.log10(), hi.log10());
        let ticks = paperbsdf_plot::log_ticks(llo, lhi);
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("θi = {}°", r.theta_i), ("sans-serif", 18))
            .margin(8)
            .margin_right(16)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(
                paperbsdf_plot::TickedAxis {
                    lo: -85.0,
                    hi: 85.0,
                    ticks: vec![-80.0, -60.0, -40.0, -20.0, 0.0, 20.0, 40.0, 60.0, 80.0],
                },
                paperbsdf_plot::TickedAxis {
                    lo: llo,
                    hi: lhi,
                    ticks,
                },
            )?;
        chart
            .configure_mesh()
            .x_desc("θo (degrees; negative: opposite the light)")
            .y_desc(if rgb { "f (1/sr), red channel" } else { "f (1/sr)" })
            .x_label_formatter(&|v| format!("{}", v.round() as i64))
            .y_label_formatter(&|v| paperbsdf_plot::tick_label(10f64.powf(*v), 2))
            .draw()?;
        let lo = llo;
        for (t, colour, label) in [(false, RGBColor(200, 60, 20), "R"), (true, RGBColor(20, 90, 200), "T")] {
            let pts: Vec<&Point> = r.points.iter().filter(|p| p.transmission == t).collect();
            chart
                .draw_series(LineSeries::new(
                    pts.iter()
                        .map(|p| (p.theta_o, p.model.0[0].max(1e-300).log10().max(lo))),
                    colour.stroke_width(2),
                ))?
                .label(format!("{label} model"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
            chart
                .draw_series(pts.iter().map(|p| {
                    Circle::new(
                        (p.theta_o, p.sim.mean.0[0].max(1e-300).log10().max(lo)),
                        4,
                        colour.filled(),
                    )
                }))?
                .label(format!("{label} simulation"))
                .legend(move |(x, y)| Circle::new((x + 10, y), 4, colour.filled()));
            for p in &pts {
                let (m, s) = (p.sim.mean.0[0], p.sim.stderr.0[0]);
                chart.draw_series(std::iter::once(PathElement::new(
                    vec![
                        (p.theta_o, (m - 2.0 * s).max(1e-300).log10().max(lo)),
                        (p.theta_o, (m + 2.0 * s).max(1e-300).log10().max(lo)),
                    ],
                    colour.stroke_width(1),
                )))?;
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
    }
    root.present()?;
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut walks: u64 = 16_384;
    let mut out_dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs").to_string();
    let mut only: Option<String> = None;
    let mut faces = paperbsdf_core::FaceScattering::Multiple;
    let mut with_slab = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--walks" => walks = args.next().ok_or("--walks needs a number")?.parse()?,
            "--out-dir" => out_dir = args.next().ok_or("--out-dir needs a directory")?,
            "--only" => only = Some(args.next().ok_or("--only needs a case name")?),
            "--slab" => with_slab = true,
            "--face-scattering" => {
                faces = args
                    .next()
                    .ok_or("--face-scattering needs single or multiple")?
                    .parse()
                    .map_err(|e| format!("--face-scattering: {e}"))?
            }
            _ => {
                return Err(format!(
                "unknown argument `{a}` (use --walks N, --out-dir DIR, --only CASE, --face-scattering single|multiple, --slab)"
            )
                .into())
            }
        }
    }
    let t_start = std::time::Instant::now();
    let mut slab_rows = String::new();
    let mut worst_slab = 0.0f64;
    let mut md = String::new();
    let mut summary = String::new();
    let mut details = String::new();
    writeln!(summary, "| case | kind | RMS log error at theta_i = 0 / 30 / 60 / 75 | albedo error (model - sim) at 0 / 30 / 60 / 75 | largest component error |")?;
    writeln!(summary, "|---|---|---|---|---|")?;
    let prefix = match faces {
        paperbsdf_core::FaceScattering::Multiple => "accuracy",
        paperbsdf_core::FaceScattering::Single => "accuracy_single",
    };
    for (name, mut p) in cases() {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        p.face_scattering = faces;
        eprintln!("{name} ...");
        let slab = Slab::from_params(&p)?;
        let model = PaperBsdf::new(&p)?;
        let slab_model = if with_slab {
            let t0 = std::time::Instant::now();
            match SlabBsdf::new(&p) {
                Ok(b) => {
                    eprintln!("  slab built in {:.2} s", t0.elapsed().as_secs_f64());
                    Some(b)
                }
                Err(e) => {
                    writeln!(slab_rows, "| {name} | - | not supported by `slab` yet: {e} | | | |")?;
                    None
                }
            }
        } else {
            None
        };
        let nc = channels(&p);
        let tos: Vec<f64> = (-8..=8).map(|k| 10.0 * k as f64).collect();
        let mut res = Vec::new();
        for (k, &ti) in THETA_I.iter().enumerate() {
            let mut wos = Vec::new();
            let mut kinds = Vec::new();
            for t in [false, true] {
                for &o in &tos {
                    wos.push(in_plane_directions(ti, o, t).1);
                    kinds.push((t, o));
                }
            }
            let (wi, _) = in_plane_directions(ti, 0.0, false);
            let cfg = SimConfig {
                samples: walks,
                batches: 32,
                seed: 1000 + k as u64,
                by_order: true,
                progress: true,
                ..Default::default()
            };
            let run = simulate_bsdf(&slab, wi, &wos, &cfg)?;
            let orders = run.by_order.expect("requested");
            let points = kinds
                .iter()
                .zip(&wos)
                .enumerate()
                .map(|(j, (&(t, o), &wo))| {
                    let comp = |c| model.eval_components(wi, wo, paperbsdf_core::paper::ComponentSet::only(c));
                    Point {
                        transmission: t,
                        theta_o: o,
                        sim: run.f[j],
                        sim_order: orders[j],
                        model: model.eval(wi, wo),
                        model_order: [
                            comp(Component::Surface) + comp(Component::Direct),
                            comp(Component::Single),
                            comp(Component::Multiple),
                        ],
                        slab: slab_model.as_ref().map(|b| {
                            (
                                b.eval(wi, wo),
                                [
                                    b.eval_component(wi, wo, Component::Surface)
                                        + b.eval_component(wi, wo, Component::Direct),
                                    b.eval_component(wi, wo, Component::Single),
                                    b.eval_component(wi, wo, Component::Multiple),
                                ],
                            )
                        }),
                    }
                })
                .collect();
            let (mr, mt) = sampled_albedo(&model, wi, 96);
            res.push(AngleResult {
                theta_i: ti,
                points,
                sim_r: run.reflectance,
                sim_t: run.transmittance,
                model_r: mr,
                model_t: mt,
                slab_rt: slab_model.as_ref().map(|b| sampled_albedo(b, wi, 96)),
            });
        }
        if slab_model.is_some() {
            for (kind_t, kind) in [(false, "R"), (true, "T")] {
                for r in &res {
                    let pts: Vec<&Point> = r.points.iter().filter(|p| p.transmission == kind_t).collect();
                    let e_paper = rms_log(&pts, nc);
                    let e_slab = rms_log_of(&pts, nc, |p| p.slab.as_ref().map_or(Rgb::ZERO, |s| s.0));
                    let floor = noise_floor(&pts, nc);
                    let (sr, st) = r.slab_rt.expect("slab albedo");
                    let (ma, sa) = if kind_t { (st, r.sim_t) } else { (sr, r.sim_r) };
                    let ce = slab_component_errors(&pts, nc);
                    worst_slab = worst_slab.max(e_slab);
                    writeln!(
                        slab_rows,
                        "| {name} | {} {kind} | {e_paper:.3} | **{e_slab:.3}** | {floor:.3} | {:.4} / {:.4} +- {:.4} | {:.3} / {:.3} / {:.3} |",
                        r.theta_i,
                        ma.mean(),
                        sa.mean.mean(),
                        sa.stderr.mean(),
                        ce[0],
                        ce[1],
                        ce[2]
                    )?;
                }
            }
            continue;
        }
        if with_slab {
            continue;
        }
        let svg = format!("{prefix}_{name}.svg");
        plot(
            &format!("{out_dir}/{svg}"),
            &format!("{name}: Paper BSDF (lines) vs simulation (dots, 2 sigma bars)"),
            &res,
            nc == 3,
        )?;

        writeln!(
            details,
            "\n### {name}\n\n`{}`\n\n![{name}]({svg})\n",
            serde_json::to_string(&p)?
        )?;
        writeln!(details, "| theta_i | kind | RMS log error (noise floor) | worst theta_o: model / sim | albedo: model / sim (+- stderr) | component errors (surface+unscattered / single / multiple) |")?;
        writeln!(details, "|---|---|---|---|---|---|")?;
        for (kind_t, kind) in [(false, "R"), (true, "T")] {
            let mut rms = Vec::new();
            let mut alb = Vec::new();
            let mut comp_all = [0.0f64; 3];
            for r in &res {
                let pts: Vec<&Point> = r.points.iter().filter(|p| p.transmission == kind_t).collect();
                let e = rms_log(&pts, nc);
                let floor = noise_floor(&pts, nc);
                rms.push(format!("{e:.3}"));
                let worst = pts
                    .iter()
                    .max_by(|a, b| {
                        log_err(a.model.0[0], a.sim.mean.0[0])
                            .abs()
                            .total_cmp(&log_err(b.model.0[0], b.sim.mean.0[0]).abs())
                    })
                    .expect("points");
                let (ma, sa) = if kind_t {
                    (r.model_t, r.sim_t)
                } else {
                    (r.model_r, r.sim_r)
                };
                let d = ma.mean() - sa.mean.mean();
                alb.push(format!("{d:+.3}"));
                let ce = component_errors(&pts, nc);
                for k in 0..3 {
                    comp_all[k] += ce[k] * ce[k];
                }
                writeln!(
                    details,
                    "| {} | {kind} | {e:.3} ({floor:.3}) | {:+.0}: {:.4} / {:.4} | {:.4} / {:.4} +- {:.4} | {:.3} / {:.3} / {:.3} |",
                    r.theta_i,
                    worst.theta_o,
                    worst.model.mean(),
                    worst.sim.mean.mean(),
                    ma.mean(),
                    sa.mean.mean(),
                    sa.stderr.mean(),
                    ce[0],
                    ce[1],
                    ce[2]
                )?;
            }
            let k = (0..3).max_by(|&a, &b| comp_all[a].total_cmp(&comp_all[b])).unwrap_or(0);
            writeln!(
                summary,
                "| {name} | {kind} | {} | {} | {} |",
                rms.join(" / "),
                alb.join(" / "),
                ORDER_NAMES[k]
            )?;
        }
    }
    if with_slab {
        let path = format!("{out_dir}/{prefix}_slab.md");
        let mut md = String::new();
        writeln!(
            md,
            "# `slab` and `paper` against the Monte Carlo ground truth: `face_scattering = \"{}\"`\n\n\
Generated by `cargo run --release -p paperbsdf-sim --example accuracy -- --slab --face-scattering {} --walks {walks}` \
({walks} walks per incident angle and channel, {:.0} s): the cases and metrics of [{prefix}.md]({prefix}.md), with the numerical \
model `slab` (`paperbsdf_slab::SlabBsdf`, default options) beside the Paper BSDF, against the same simulations. \
RMS log errors over `theta_o = -80..80` step 10; the noise floor is the RMS log error that the simulation's own standard \
errors alone give (an error at the floor is not resolved); albedo: `slab`'s directional albedo against the simulated total. \
Component errors of `slab`, as the Paper BSDF's in the other tables: order 0 (lit face, unscattered light) against its surface + direct, \
order 1 against its `single`, orders 2+ against its `multiple`. Largest `slab` RMS log error: {worst_slab:.3}.\n\n\
| case | theta_i, kind | paper RMS log error | slab RMS log error | noise floor | slab albedo / sim (+- stderr) | slab component errors (order 0 / 1 / 2+) |\n\
|---|---|---|---|---|---|---|\n{slab_rows}",
            faces.name(),
            faces.name(),
            t_start.elapsed().as_secs_f64()
        )?;
        let tmp = format!("{path}.tmp");
        std::fs::write(&tmp, md)?;
        std::fs::rename(&tmp, &path)?;
        eprintln!("wrote {path}");
        return Ok(());
    }
    writeln!(
        md,
        "# Accuracy of the Paper BSDF against the Monte Carlo ground truth: `face_scattering = \"{}\"`\n",
        faces.name()
    )?;
    writeln!(
        md,
        "Generated by `cargo run --release -p paperbsdf-sim --example accuracy -- --face-scattering {}` ({} walks per incident angle and channel, {:.0} s). \
The ground truth is the simulator of `crates/sim` (random walk through the physical slab with the same faces, {}, and the same \
two-lobe HG medium; checked against Mitsuba 3 and adding-doubling in `crates/sim/tests`). The model is \
`paperbsdf_core::paper::PaperBsdf` with its default options and the same `face_scattering`. Both exclude Dirac delta lobes from `f`; the albedos include them. \
The other face mode: [{}]({}).\n",
        faces.name(),
        walks,
        t_start.elapsed().as_secs_f64(),
        match faces {
            paperbsdf_core::FaceScattering::Multiple => "energy-conserving rough faces (the exact random walk on the Smith microsurface, Heitz et al. 2016, in the simulator; \
Walter's lobe plus the tabulated compensation in the model)",
            paperbsdf_core::FaceScattering::Single => "Walter's single-scattering rough faces (Mitsuba's `roughdielectric`)",
        },
        match faces {
            paperbsdf_core::FaceScattering::Multiple => "face_scattering = \"single\"",
            paperbsdf_core::FaceScattering::Single => "face_scattering = \"multiple\" (default)",
        },
        match faces {
            paperbsdf_core::FaceScattering::Multiple => "accuracy_single.md",
            paperbsdf_core::FaceScattering::Single => "accuracy.md",
        },
    )?;
    writeln!(
        md,
        "**Metrics.** RMS log error: `sqrt(mean(ln((f_model + e) / (f_sim + e))^2))`, `e = 1e-3` /sr, over `theta_o = -80..80` step 10 \
(and over colour channels for RGB parameters): 0.1 is about 10% typical error. The noise floor in brackets is the RMS log \
error that the simulation's own standard errors alone would give; errors near it are not resolved. Albedo error: model minus simulated total \
reflectance (R rows) or transmittance (T rows) for collimated light at `theta_i` (channel mean). Component errors: the \
simulator splits `f` by the number of volume scattering events; order 0 (the lit face's reflection and light that crossed \
unscattered, internal reflections included) is compared with the model's surface + direct terms, order 1 with its single \
scattering term, order 2+ with its multiple scattering term; each number is the RMS of `(model_k - sim_k) / (f_sim + e)`, \
so they show which term carries the error. The simulation's own standard errors are about 1-3% (R) and 2-6% (T) per point \
(see the plots' 2-sigma bars).\n"
    )?;
    writeln!(md, "## Summary\n\n{summary}\n## Per case\n{details}")?;
    let path = format!("{out_dir}/{prefix}.md");
    let tmp = format!("{out_dir}/.{prefix}.md.tmp");
    std::fs::write(&tmp, md)?;
    std::fs::rename(&tmp, &path)?;
    eprintln!("wrote {path} in {:.0} s", t_start.elapsed().as_secs_f64());
    Ok(())
}
