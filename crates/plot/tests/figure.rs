//! Figures are drawn with text, the measurement in red, components in their
//! colours and extrapolated panels on grey; files are PNG or SVG.

use paperbsdf_core::{Bsdf, BsdfFlags, BsdfSample, Component, DVec3, Rgb};
use paperbsdf_fit::{parse_measurement, ComponentModel};
use paperbsdf_plot::*;

/// A two-component model (a surface peak and a flat body) for the plots; the
/// figures only evaluate it, so it does not sample.
struct Two;
impl Bsdf for Two {
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.eval_component(wi, wo, Component::Surface) + self.eval_component(wi, wo, Component::Multiple)
    }
    fn sample(&self, _wo: DVec3, _uc: f64, _u: [f64; 2]) -> Option<BsdfSample> {
        None
    }
    fn pdf(&self, _wi: DVec3, _wo: DVec3) -> f64 {
        0.0
    }
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::REFLECTION | BsdfFlags::TRANSMISSION | BsdfFlags::DIFFUSE | BsdfFlags::GLOSSY
    }
}
impl ComponentModel for Two {
    fn eval_component(&self, _wi: DVec3, wo: DVec3, c: Component) -> Rgb {
        match c {
            Component::Surface => Rgb::splat(0.05 + 0.3 * wo.z.abs().powi(8)),
            Component::Multiple => Rgb::splat(0.1),
            _ => Rgb::ZERO,
        }
    }
    fn is_rgb(&self) -> bool {
        false
    }
    fn components(&self) -> &'static [Component] {
        &[Component::Surface, Component::Multiple]
    }
}

fn figure(log_y: bool) -> Figure {
    let mut text = String::from("kind,theta_i_deg,theta_o_deg,f\n");
    for ti in [0, 45] {
        for k in ["R", "T"] {
            for to in (-80..=80).step_by(20) {
                text += &format!("{k},{ti},{to},{}\n", 0.2 + 0.001 * to as f64);
            }
        }
    }
    let m = parse_measurement(&text, "t").unwrap();
    let panels = panels_for(&m.points, Some(&Two), Some(&[0.0]));
    assert_eq!(panels.len(), 4);
    assert!(!panels[0].extrapolated && panels[2].extrapolated);
    let mut fig = Figure::new(
        "test figure",
        vec![Row {
            label: "matte".into(),
            panels,
        }],
    );
    fig.log_y = log_y;
    fig
}

fn count(buf: &[u8], pred: impl Fn(u8, u8, u8) -> bool) -> usize {
    buf.chunks(3).filter(|p| pred(p[0], p[1], p[2])).count()
}

#[test]
fn pixels_show_series_background_and_text() {
    for log_y in [false, true] {
        let fig = figure(log_y);
        let (buf, w, h) = render_rgb(&fig).unwrap();
        assert_eq!((w, h), figure_size(&fig));
        let red = count(&buf, |r, g, b| r > 200 && g < 60 && b < 60);
        let orange = count(&buf, |r, g, b| r > 240 && (120..160).contains(&g) && b < 20);
        let blue = count(&buf, |r, g, b| r < 50 && g < 80 && b > 200);
        let grey = count(&buf, |r, g, b| r == 222 && g == 222 && b == 222);
        assert!(
            red > 200 && orange > 100 && blue > 100 && grey > 10_000,
            "{red} {orange} {blue} {grey}"
        );
        // Text: the title strip (top 24 px, left 300 px) has dark anti-aliased glyph pixels.
        let mut dark = 0;
        for y in 0..24 {
            for x in 0..300 {
                let i = 3 * (y * w as usize + x);
                if buf[i] < 100 && buf[i + 1] < 100 && buf[i + 2] < 100 {
                    dark += 1;
                }
            }
        }
        assert!(dark > 50, "title text not rendered ({dark} dark pixels)");
    }
}

#[test]
fn writes_png_and_svg_atomically() {
    let d = tempfile::tempdir().unwrap();
    let fig = figure(false);
    for name in ["f.png", "f.svg"] {
        let p = d.path().join(name);
        draw_figure(&fig, &p).unwrap();
        let bytes = std::fs::read(&p).unwrap();
        if name.ends_with("png") {
            assert_eq!(&bytes[1..4], b"PNG");
        } else {
            let s = String::from_utf8(bytes).unwrap();
            assert!(s.contains("<svg") && s.contains("BRDF"));
        }
    }
    assert_eq!(
        std::fs::read_dir(d.path()).unwrap().count(),
        2,
        "no temporary files left"
    );
    let e = draw_figure(&fig, &d.path().join("f.jpg")).unwrap_err().to_string();
    assert!(e.contains(".jpg"), "{e}");
}

/// Tick labels without float noise, in plain or scientific notation.
#[test]
fn tick_labels_are_clean() {
    assert_eq!(tick_label(0.30000000000000004, 2), "0.3");
    assert_eq!(tick_label(0.7000000000000001, 2), "0.7");
    assert_eq!(tick_label(10f64.powf(0.05f64.log10()), 2), "0.05");
    assert_eq!(tick_label(-80.0, 2), "-80");
    assert_eq!(tick_label(2e-4, 2), "2e-4");
    assert_eq!(tick_label(1500.0, 2), "1500");
    assert_eq!(tick_label(0.0, 2), "0");
}

/// A log axis over a narrow range (transmission 0.03 to 0.06) still gets at
/// least two labelled ticks, all at round values; a wide one gets decades.
#[test]
fn log_ticks_label_narrow_and_wide_ranges() {
    let t = log_ticks(0.03f64.log10(), 0.06f64.log10());
    let l: Vec<String> = t.iter().map(|v| tick_label(10f64.powf(*v), 2)).collect();
    assert_eq!(l, ["0.03", "0.04", "0.05", "0.06"]);
    let t = log_ticks(-4.2, 1.3);
    let l: Vec<String> = t.iter().map(|v| tick_label(10f64.powf(*v), 2)).collect();
    assert_eq!(l, ["1e-4", "0.001", "0.01", "0.1", "1", "10"]);
    let t = log_ticks(-1.5, 0.4);
    let l: Vec<String> = t.iter().map(|v| tick_label(10f64.powf(*v), 2)).collect();
    assert_eq!(l, ["0.05", "0.1", "0.2", "0.5", "1", "2"]);
    let l: Vec<String> = linear_ticks(0.0, 0.43, 4).iter().map(|v| tick_label(*v, 2)).collect();
    assert_eq!(l, ["0", "0.1", "0.2", "0.3", "0.4"]);
}

/// The grid layout: per paper a BRDF line over a BTDF line, one column per
/// incident angle; the row layout keeps all panels in one line.
#[test]
fn grid_and_row_layouts() {
    let mut fig = figure(false);
    let lines = fig.lines();
    assert_eq!(lines.len(), 2);
    assert_eq!(lines[0].0, "matte: BRDF");
    assert_eq!(lines[1].0, "matte: BTDF");
    assert!(lines.iter().all(|l| l.1.len() == 2 && l.1.iter().all(|c| c.is_some())));
    assert_eq!(lines[1].1[1].unwrap().kind, paperbsdf_fit::Kind::T);
    assert_eq!(lines[1].1[1].unwrap().theta_i, 45.0);
    let (pw, ph) = DEFAULT_PANEL_SIZE;
    assert_eq!(figure_size(&fig), (30 + 2 * pw, 60 + 2 * ph));
    fig.layout = Layout::Row;
    fig.panel_size = (200, 150);
    assert_eq!(figure_size(&fig), (30 + 4 * 200, 60 + 150));
    let (_, w, h) = render_rgb(&fig).unwrap();
    assert_eq!((w, h), (830, 210));
}

/// Measurements with a stderr column get error bars: more drawn elements than
/// the same figure without them, and a legend entry saying what they are.
#[test]
fn error_bars_from_stderr() {
    let mut text = String::from("kind,theta_i_deg,theta_o_deg,f,stderr\n");
    for to in (-80..=80).step_by(20) {
        text += &format!("R,0,{to},0.2,0.02\n");
    }
    let m = parse_measurement(&text, "t").unwrap();
    let panels = panels_for(&m.points, Some(&Two), None);
    assert_eq!(panels[0].series[0].stderr, vec![0.02; 9]);
    let fig = Figure::new(
        "bars",
        vec![Row {
            label: "x".into(),
            panels,
        }],
    );
    let with = svg_string(&fig, "t.svg").unwrap();
    let mut bare = fig.clone();
    bare.rows[0].panels[0].series[0].stderr.clear();
    let without = svg_string(&bare, "t.svg").unwrap();
    let n = |s: &str| s.matches("<line").count() + s.matches("<polyline").count();
    assert!(n(&with) >= n(&without) + 9, "{} vs {}", n(&with), n(&without));
    assert!(with.contains("standard error") && !without.contains("standard error"));
}

#[test]
fn writes_pdf() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("f.pdf");
    draw_figure(&figure(true), &p).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    assert_eq!(&bytes[..5], b"%PDF-");
    assert!(bytes.len() > 5000, "{} bytes", bytes.len());
    assert_eq!(
        std::fs::read_dir(d.path()).unwrap().count(),
        1,
        "no temporary files left"
    );
}

#[test]
fn figures_need_the_bundled_papers() {
    let dir = tempfile::tempdir().unwrap();
    let opts = figures::FiguresOptions {
        layout: Layout::Grid,
        panel_size: DEFAULT_PANEL_SIZE,
        data_dir: dir.path().to_path_buf(),
        out_dir: dir.path().join("out"),
        fit_theta_i: figures::DEFAULT_FIT_THETA_I.to_vec(),
        fit: Default::default(),
    };
    let e = figures::make_figures(&opts).unwrap_err();
    assert!(matches!(e, PlotError::MissingData { paper: "matte", .. }), "{e:?}");
    let want = format!(
        "{}: missing (the bundled matte paper measurement)",
        dir.path().join("matte.csv").display()
    );
    assert_eq!(e.to_string(), want);
}
