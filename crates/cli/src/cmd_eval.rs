//! `paperbsdf eval` and `paperbsdf albedo`: a model's BSDF values and directional
//! albedo, in the conventions of DESIGN.md section 2.

use anyhow::{bail, Context, Result};
use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::{DVec3, Rgb};
use paperbsdf_io::models::{load_model, LoadedModel};

/// Arguments of `paperbsdf eval`.
#[derive(clap::Args, Debug)]
pub struct EvalArgs {
    /// Model name: rough-dielectric, paper, reduced-multilayer, lambert-glass.
    #[arg(long)]
    pub model: String,
    /// Parameters: a JSON or TOML file, inline JSON (`'{"eta":1.5,...}'`), a FIT.json, or a preset (matte, luster, glossy).
    #[arg(long)]
    pub params: String,
    /// CSV file of direction pairs (columns wi_x,wi_y,wi_z,wo_x,wo_y,wo_z; others are echoed).
    #[arg(long, conflicts_with_all = ["theta_i", "theta_o"])]
    pub dirs: Option<String>,
    /// In-plane incident angles in degrees, comma-separated (e.g. `0,30,60`).
    #[arg(long = "theta-i", value_delimiter = ',', allow_hyphen_values = true)]
    pub theta_i: Vec<f64>,
    /// In-plane viewing angles FROM:TO:STEP in degrees (signed; negative is opposite the light).
    #[arg(long = "theta-o", allow_hyphen_values = true)]
    pub theta_o: Option<String>,
    /// Which component to evaluate: surface, single, multiple, direct or all.
    #[arg(long, default_value = "all")]
    pub component: String,
    /// Write the table to this file (atomically) instead of standard output.
    #[arg(long)]
    pub out: Option<String>,
}

/// Arguments of `paperbsdf albedo`.
#[derive(clap::Args, Debug)]
pub struct AlbedoArgs {
    /// Model name (see `eval`).
    #[arg(long)]
    pub model: String,
    /// Parameters: a JSON or TOML file, inline JSON, a FIT.json, or a preset (matte, luster, glossy).
    #[arg(long)]
    pub params: String,
    /// Incident polar angles in degrees, comma-separated, in [0, 90).
    #[arg(long = "theta-i", value_delimiter = ',', required = true)]
    pub theta_i: Vec<f64>,
    /// Which face the light arrives at: front (from z > 0) or back (from z < 0).
    #[arg(long, default_value = "front")]
    pub side: String,
}

/// Parses `FROM:TO:STEP` (degrees) into the list of angles, TO included when hit.
pub fn parse_range(s: &str, what: &str) -> Result<Vec<f64>> {
    let parts: Vec<&str> = s.split(':').collect();
    if parts.len() != 3 {
        bail!("{what} `{s}`: expected FROM:TO:STEP in degrees, e.g. -80:80:10");
    }
    let num = |p: &str| {
        p.trim()
            .parse::<f64>()
            .with_context(|| format!("{what} `{s}`: `{p}` is not a number"))
    };
    let (from, to, step) = (num(parts[0])?, num(parts[1])?, num(parts[2])?);
    if step.is_nan() || step <= 0.0 || !from.is_finite() || !to.is_finite() {
        bail!("{what} `{s}`: STEP must be positive and FROM, TO finite");
    }
    let n = ((to - from) / step + 1e-9).floor();
    if n < 0.0 {
        bail!("{what} `{s}`: TO is below FROM");
    }
    if n > 100_000.0 {
        bail!("{what} `{s}`: more than 100000 angles");
    }
    Ok((0..=n as usize).map(|k| from + k as f64 * step).collect())
}

/// Checks in-plane angles are within [lo, hi] degrees.
pub fn check_angles(v: &[f64], what: &str, lo: f64, hi: f64) -> Result<()> {
    for a in v {
        if !(a.is_finite() && *a >= lo && *a <= hi) {
            bail!("{what} = {a} is outside the allowed range [{lo}, {hi}] degrees");
        }
    }
    Ok(())
}

fn fmt_value(v: Rgb, rgb: bool) -> String {
    if rgb {
        format!("{:.9e},{:.9e},{:.9e}", v.0[0], v.0[1], v.0[2])
    } else {
        format!("{:.9e}", v.0[0])
    }
}

fn value_header(rgb: bool) -> &'static str {
    if rgb {
        "r,g,b"
    } else {
        "f"
    }
}

fn emit(out: &Option<String>, text: String) -> Result<()> {
    match out {
        Some(p) => paperbsdf_io::write_atomic(p, text.as_bytes())?,
        None => print!("{text}"),
    }
    Ok(())
}

/// Runs `paperbsdf eval`.
pub fn run_eval(a: EvalArgs) -> Result<()> {
    let model = load_model(&a.model, &a.params)?;
    let component = a.component.as_str();
    let eval =
        |wi: DVec3, wo: DVec3| -> Result<Rgb> { model.eval_component(wi, wo, component).map_err(anyhow::Error::msg) };
    // Validate the component name once, before any output.
    eval(DVec3::Z, DVec3::Z)?;
    let rgb = model.is_rgb();
    let mut text = String::new();
    if let Some(path) = &a.dirs {
        let f = paperbsdf_io::dirs::read_dirs(path)?;
        text.push_str(&format!("{},{}\n", f.header.join(","), value_header(rgb)));
        for r in &f.rows {
            let v = eval(r.wi, r.wo)?;
            text.push_str(&format!("{},{}\n", r.fields.join(","), fmt_value(v, rgb)));
        }
    } else {
        let to = match &a.theta_o {
            Some(s) => parse_range(s, "--theta-o")?,
            None => bail!("give either --dirs F.csv or --theta-i LIST with --theta-o FROM:TO:STEP"),
        };
        if a.theta_i.is_empty() {
            bail!("--theta-o needs --theta-i LIST (degrees)");
        }
        check_angles(&a.theta_i, "--theta-i", 0.0, 90.0)?;
        check_angles(&to, "--theta-o", -90.0, 90.0)?;
        text.push_str(&format!("kind,theta_i_deg,theta_o_deg,{}\n", value_header(rgb)));
        for &ti in &a.theta_i {
            for (kind, t) in [("R", false), ("T", true)] {
                for &o in &to {
                    let (wi, wo) = in_plane_directions(ti, o, t);
                    let v = eval(wi, wo)?;
                    text.push_str(&format!("{kind},{ti},{o},{}\n", fmt_value(v, rgb)));
                }
            }
        }
    }
    emit(&a.out, text)
}

/// Runs `paperbsdf albedo`.
pub fn run_albedo(a: AlbedoArgs) -> Result<()> {
    let model = load_model(&a.model, &a.params)?;
    let sign = match a.side.as_str() {
        "front" => 1.0,
        "back" => -1.0,
        s => bail!("--side `{s}`: expected `front` (light from z > 0) or `back` (light from z < 0)"),
    };
    check_angles(&a.theta_i, "--theta-i", 0.0, 90.0)?;
    let rgb = model.is_rgb();
    let mut text = if rgb {
        "theta_i_deg,reflectance_r,reflectance_g,reflectance_b,transmittance_r,transmittance_g,transmittance_b\n"
            .to_string()
    } else {
        "theta_i_deg,reflectance,transmittance\n".to_string()
    };
    for &t in &a.theta_i {
        let th = t.to_radians();
        let w = DVec3::new(th.sin(), 0.0, sign * th.cos());
        let (r, tr) = model.albedo(w);
        text.push_str(&format!("{t},{},{}\n", fmt_value(r, rgb), fmt_value(tr, rgb)));
    }
    print!("{text}");
    Ok(())
}

#[allow(dead_code)]
fn _assert_model_is_used(_: &LoadedModel) {}
