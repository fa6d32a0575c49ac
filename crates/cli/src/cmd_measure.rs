//! `paperbsdf measure`, `paperbsdf edge` and `paperbsdf from-datasheet`: what
//! paper makers measure (opacity, brightness, gloss, Kubelka-Munk, scatter
//! distance), predicted from a model or the simulator, and parameters from a
//! datasheet. The physics is in crate `paperbsdf-metrics`; definitions in
//! `docs/paper_metrics.md`.

use anyhow::{bail, Context, Result};
use paperbsdf_core::models::ModelKind;
use paperbsdf_core::PaperParams;
use paperbsdf_io::models::LoadedModel;
use paperbsdf_metrics::edge::{model_edge, truth_edge, EdgeProfile, ScatterDistance, SUPPLEMENT_BLUR_MM};
use paperbsdf_metrics::instrument::Quality;
use paperbsdf_metrics::{
    fit_datasheet, measure_model, measure_truth, Datasheet, DatasheetError, Measurements, Selection, TruthConfig,
};

/// Arguments of `paperbsdf measure`.
#[derive(clap::Args, Debug)]
pub struct MeasureArgs {
    /// Parameters: a JSON or TOML file, or inline JSON.
    #[arg(long)]
    pub params: String,
    /// Model name: paper, reduced-multilayer, slab, lambert-glass, rough-dielectric.
    #[arg(long, default_value = "paper")]
    pub model: String,
    #[command(flatten)]
    pub slab: crate::cmd_eval::SlabArgs,
    /// Print JSON (keys as in docs/paper_metrics.md) instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Measure the physical sheet with the Monte Carlo simulator instead of the model (paper parameters).
    #[arg(long)]
    pub truth: bool,
    /// Grammage in g/m^2, for the Kubelka-Munk coefficients.
    #[arg(long, allow_hyphen_values = true)]
    pub grammage: Option<f64>,
    /// Only these metrics (comma-separated JSON keys); default all.
    #[arg(long)]
    pub metrics: Option<String>,
    /// Photons per simulation and channel with --truth (scales every simulation).
    #[arg(long, default_value_t = 1 << 17)]
    pub samples: u64,
    /// Seed of the simulation with --truth.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// Arguments of `paperbsdf edge`.
#[derive(clap::Args, Debug)]
pub struct EdgeArgs {
    /// Paper BSDF parameters: a JSON or TOML file, or inline JSON.
    #[arg(long)]
    pub params: String,
    /// Output image (PNG, or SVG when the name ends in .svg), written atomically.
    #[arg(long)]
    pub out: String,
    /// Also simulate the exact profile (the simulator tracking lateral positions).
    #[arg(long)]
    pub truth: bool,
    /// Walks for the exact profile.
    #[arg(long, default_value_t = 1 << 18)]
    pub samples: u64,
    /// Half width of the plotted range, mm.
    #[arg(long, default_value_t = 1.5)]
    pub range: f64,
}

/// Arguments of `paperbsdf from-datasheet`.
#[derive(clap::Args, Debug)]
pub struct DatasheetArgs {
    /// Grammage, g/m^2.
    #[arg(long, allow_hyphen_values = true)]
    pub grammage: f64,
    /// Caliper (thickness), mm; used as the model's d.
    #[arg(long, allow_hyphen_values = true)]
    pub caliper: f64,
    /// ISO 2471 opacity, %, in (0, 100].
    #[arg(long, allow_hyphen_values = true)]
    pub opacity: f64,
    /// ISO 2470-1 brightness R457, %.
    #[arg(long, allow_hyphen_values = true)]
    pub brightness: Option<f64>,
    /// TAPPI T480 75-degree gloss, GU.
    #[arg(long, allow_hyphen_values = true)]
    pub gloss75: Option<f64>,
    /// Relative pad reflectance R,G,B, each in (0, 1] (e.g. 1,0.97,0.9 for a cream paper).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub tint: Option<Vec<f64>>,
    /// Output parameter file (JSON), written atomically.
    #[arg(long)]
    pub out: String,
}

fn paper_params(source: &str) -> Result<PaperParams> {
    let l = paperbsdf_io::load_params::<PaperParams>(source)?;
    l.value.validate().map_err(|e| l.param_error(e))?;
    Ok(l.value)
}

fn table(m: &Measurements) -> String {
    let mut s = format!("# predicted by the {}\n", m.source);
    let row = |s: &mut String, k: &str, v: Option<f64>, unit: &str| {
        if let Some(v) = v {
            s.push_str(&format!("{k:<22} {v:>9.2} {unit}\n"));
        }
    };
    row(&mut s, "opacity_iso2471", m.opacity_iso2471, "%");
    row(&mut s, "opacity_tappi_t425", m.opacity_tappi_t425, "%");
    row(&mut s, "r457", m.r457, "% (blue-channel estimate)");
    for g in &paperbsdf_metrics::gloss::GEOMETRIES {
        row(&mut s, g.key, m.value(g.key), "GU");
    }
    if let Some(k) = m.kubelka_munk {
        s.push_str(&format!(
            "{:<22} s = {:.1} m^2/kg, k = {:.3} m^2/kg (grammage {} g/m^2)\n",
            "kubelka_munk", k.s_m2_per_kg, k.k_m2_per_kg, k.grammage_g_m2
        ));
    }
    if let Some(d) = m.scatter_distance_mm {
        s.push_str(&format!(
            "{:<22} {:.3} mm ({:.3} mm with a {SUPPLEMENT_BLUR_MM} mm instrument blur)\n",
            "scatter_distance_mm", d.width_mm, d.width_blurred_mm
        ));
    }
    s
}

/// Runs `paperbsdf measure`.
pub fn run_measure(a: MeasureArgs) -> Result<()> {
    let sel = match &a.metrics {
        Some(list) => Selection::parse(list).map_err(anyhow::Error::msg)?,
        None => Selection::all(),
    };
    if let Some(g) = a.grammage {
        if !(g.is_finite() && g > 0.0) {
            bail!("--grammage {g}: must be positive (g/m^2)");
        }
    }
    let m = if a.truth {
        if a.model != ModelKind::Paper.name() {
            bail!(
                "--truth simulates the physical paper sheet: it needs --model paper (got `{}`)",
                a.model
            );
        }
        if a.slab.slab_nodes.is_some() {
            bail!("--slab-nodes sets the discretisation of the model `slab`; --truth simulates the sheet instead");
        }
        let p = paper_params(&a.params)?;
        let s = a.samples.max(1024);
        let cfg = TruthConfig {
            pad_samples: s,
            gloss_samples: (s / 4).max(1024),
            lateral_samples: s * 2,
            seed: a.seed,
            progress: true,
        };
        measure_truth(&p, a.grammage, &sel, &cfg).map_err(anyhow::Error::msg)?
    } else {
        let model = a.slab.load(&a.model, &a.params)?;
        let params = match &model {
            LoadedModel::Paper(_) => Some(paper_params(&a.params)?),
            _ => None,
        };
        measure_model(model.model(), params.as_ref(), a.grammage, &sel, &Quality::default())
    };
    if a.json {
        println!("{}", serde_json::to_string_pretty(&m)?);
    } else {
        print!("{}", table(&m));
    }
    Ok(())
}

/// Runs `paperbsdf edge`.
pub fn run_edge(a: EdgeArgs) -> Result<()> {
    if !(a.range.is_finite() && a.range > 0.0 && a.range <= 5.0) {
        bail!("--range {}: must be in (0, 5] mm", a.range);
    }
    let p = paper_params(&a.params)?;
    let model = paperbsdf_core::paper::PaperBsdf::new(&p)?;
    let me = model_edge(&model, &p, 3.0, 1201).context("nothing scatters in this sheet: no edge profile")?;
    let mut curves = vec![
        ("model (multipole R(r))".to_string(), me.clone(), (40, 90, 200)),
        (
            format!("model, {SUPPLEMENT_BLUR_MM} mm blur"),
            me.blurred(SUPPLEMENT_BLUR_MM),
            (130, 170, 240),
        ),
    ];
    let mut report = vec![("model", ScatterDistance::of(&me))];
    if a.truth {
        let slab = paperbsdf_sim::Slab::from_params(&p)?;
        let cfg = paperbsdf_sim::LateralConfig {
            samples: a.samples,
            progress: true,
            ..Default::default()
        };
        let prof = paperbsdf_sim::simulate_exit_profile(&slab, paperbsdf_core::DVec3::Z, &cfg)?;
        let te = truth_edge(&prof).context("the simulated sheet reflects nothing")?;
        report.push(("simulator", ScatterDistance::of(&te)));
        curves.push(("simulator (exact)".into(), te.clone(), (200, 60, 40)));
        curves.push((
            format!("simulator, {SUPPLEMENT_BLUR_MM} mm blur"),
            te.blurred(SUPPLEMENT_BLUR_MM),
            (240, 150, 120),
        ));
    }
    let bytes = plot_edges(&curves, a.range, a.out.to_ascii_lowercase().ends_with(".svg"))?;
    paperbsdf_io::write_atomic(&a.out, &bytes)?;
    for (who, d) in report {
        println!(
            "{who}: 5-95% width {:.3} mm, with {SUPPLEMENT_BLUR_MM} mm blur {:.3} mm",
            d.width_mm, d.width_blurred_mm
        );
    }
    println!("wrote {}", a.out);
    Ok(())
}

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        static FONT: &[u8] = include_bytes!("../../plot/fonts/DejaVuSans.ttf");
        let _ = plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, FONT);
    });
}

/// The edge responses `1 - F(x)` like the supplement's Figure 2, as PNG or SVG bytes.
fn plot_edges(curves: &[(String, EdgeProfile, (u8, u8, u8))], range: f64, svg: bool) -> Result<Vec<u8>> {
    use plotters::prelude::*;
    register_font();
    let (w, h) = (900u32, 560u32);
    fn draw<DB: DrawingBackend>(
        root: DrawingArea<DB, plotters::coord::Shift>,
        curves: &[(String, EdgeProfile, (u8, u8, u8))],
        range: f64,
    ) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
        let mut chart = ChartBuilder::on(&root)
            .caption("Shadow edge at normal incidence: reflected light", ("sans-serif", 22))
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(56)
            .build_cartesian_2d(-range..range, -0.02f64..1.05f64)
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .x_desc("position across the edge, mm (lit for x < 0)")
            .y_desc("reflected light / lit level")
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        for y in [0.05, 0.95] {
            chart
                .draw_series(LineSeries::new(vec![(-range, y), (range, y)], BLACK.mix(0.3)))
                .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        for (label, prof, (r, g, b)) in curves {
            let col = RGBColor(*r, *g, *b);
            let pts: Vec<(f64, f64)> = prof
                .xs()
                .into_iter()
                .zip(prof.edge_response())
                .filter(|(x, _)| x.abs() <= range)
                .collect();
            let d = ScatterDistance::of(prof).width_mm;
            chart
                .draw_series(LineSeries::new(pts, col.stroke_width(2)))
                .map_err(|e| anyhow::anyhow!("{e}"))?
                .label(format!("{label}: 5-95% {d:.3} mm"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
        Ok(())
    }
    if svg {
        let mut s = String::new();
        draw(
            SVGBackend::with_string(&mut s, (w, h)).into_drawing_area(),
            curves,
            range,
        )?;
        Ok(s.into_bytes())
    } else {
        let mut buf = vec![0u8; (w * h * 3) as usize];
        draw(
            BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area(),
            curves,
            range,
        )?;
        let img = image_png(&buf, w, h)?;
        Ok(img)
    }
}

fn image_png(rgb: &[u8], w: u32, h: u32) -> Result<Vec<u8>> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out).write_image(rgb, w, h, image::ExtendedColorType::Rgb8)?;
    Ok(out)
}

/// Runs `paperbsdf from-datasheet`.
pub fn run_datasheet(a: DatasheetArgs) -> Result<()> {
    let tint = match &a.tint {
        None => None,
        Some(v) if v.len() == 3 => Some([v[0], v[1], v[2]]),
        Some(v) => bail!("--tint: expected three values R,G,B, got {}", v.len()),
    };
    let ds = Datasheet {
        grammage: a.grammage,
        caliper: a.caliper,
        opacity: a.opacity,
        brightness: a.brightness,
        gloss75: a.gloss75,
        tint,
    };
    let fit = match fit_datasheet(&ds) {
        Ok(f) => f,
        Err(DatasheetError::BadInput(m)) => bail!("{m}"),
        Err(DatasheetError::Impossible(m) | DatasheetError::Unreachable(m)) => {
            bail!("no sheet can meet this datasheet: {m}")
        }
    };
    let text = serde_json::to_string_pretty(&fit.params)?;
    paperbsdf_io::write_atomic(&a.out, format!("{text}\n").as_bytes())?;
    for n in &fit.notes {
        println!("note: {n}");
    }
    println!("{:<22} {:>9} {:>9} {:>8}", "target", "asked", "achieved", "diff");
    for (name, t, got) in &fit.targets {
        println!("{name:<22} {t:>9.2} {got:>9.2} {:>+8.2}", got - t);
    }
    if let Some(k) = fit.measured.kubelka_munk {
        println!(
            "kubelka_munk: s = {:.1} m^2/kg, k = {:.3} m^2/kg",
            k.s_m2_per_kg, k.k_m2_per_kg
        );
    }
    println!("wrote {}", a.out);
    Ok(())
}
