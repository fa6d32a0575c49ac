//! Figures are drawn with text, the measurement in red, components in their
//! colours and extrapolated panels on grey; files are PNG or SVG.

use paperbsdf_core::{DVec3, Rgb};
use paperbsdf_fit::{parse_measurement, Evaluable};
use paperbsdf_plot::*;

struct Two;
impl Evaluable for Two {
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.eval_component(0, wi, wo) + self.eval_component(1, wi, wo)
    }
    fn component_names(&self) -> Vec<&'static str> {
        vec!["surface", "multiple"]
    }
    fn eval_component(&self, i: usize, _wi: DVec3, wo: DVec3) -> Rgb {
        Rgb::splat(if i == 0 { 0.05 + 0.3 * wo.z.abs().powi(8) } else { 0.1 })
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
    Figure {
        title: "test figure".into(),
        rows: vec![Row {
            label: "matte".into(),
            panels,
        }],
        log_y,
    }
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
