//! `paperbsdf convert`: samples a measured RGL `.bsdf` file on in-plane angles
//! and writes the measurement CSV that `fit` and `plot` read
//! (`kind,theta_i_deg,theta_o_deg,r,g,b`, reflection only; docs/design.md section 2).

use crate::cmd_eval::MAX_EVAL_ANGLES;
use anyhow::{bail, Result};
use paperbsdf_fit::measured::{sample_in_plane, PointFilter};
use paperbsdf_io::angles::check_angles;

/// Arguments of `paperbsdf convert`.
#[derive(clap::Args, Debug)]
pub struct ConvertArgs {
    /// The measured RGL `.bsdf` file (RGB variant).
    pub file: String,
    /// In-plane incident angles in degrees, comma-separated, in [0, 90).
    #[arg(long = "theta-i", value_delimiter = ',', required = true, allow_hyphen_values = true)]
    pub theta_i: Vec<f64>,
    /// In-plane viewing angles FROM:TO:STEP in degrees (signed; negative is opposite the light), within (-90, 90).
    #[arg(long = "theta-o", required = true, allow_hyphen_values = true)]
    pub theta_o: String,
    /// Leave out points whose viewer is within DEG degrees of the light.
    #[arg(long = "exclude-retro", value_name = "DEG")]
    pub exclude_retro: Option<f64>,
    /// Leave out points whose light or viewer is more than DEG degrees from the normal.
    #[arg(long = "max-theta", value_name = "DEG")]
    pub max_theta: Option<f64>,
    /// Write the CSV to this file (atomically) instead of standard output.
    #[arg(long)]
    pub out: Option<String>,
}

/// Runs `paperbsdf convert`.
pub fn run(a: ConvertArgs) -> Result<()> {
    let to = paperbsdf_io::angles::parse_angles(&a.theta_o, "--theta-o", MAX_EVAL_ANGLES)?;
    check_angles(&a.theta_i, "--theta-i", 0.0..=89.999)?;
    check_angles(&to, "--theta-o", -89.999..=89.999)?;
    let filter = PointFilter {
        exclude_retro_deg: a.exclude_retro,
        max_theta_deg: a.max_theta,
    };
    filter.validate()?;
    let b = paperbsdf_io::MeasuredBsdf::load(&a.file)?;
    let mut text = format!(
        "# measured BSDF {} (\"{}\"), RGL tensor file, sampled by paperbsdf convert; f without cosine, reflection only\n",
        a.file, b.description
    );
    text.push_str("kind,theta_i_deg,theta_o_deg,r,g,b\n");
    let points = sample_in_plane(&b, &a.theta_i, &to, &filter);
    for p in &points {
        let (ti, o, v) = (p.theta_i, p.theta_o.unwrap_or_default(), p.f);
        text.push_str(&format!("R,{ti},{o},{:.9e},{:.9e},{:.9e}\n", v.0[0], v.0[1], v.0[2]));
    }
    let rows = points.len();
    if rows == 0 {
        bail!("every angle pair was left out by --exclude-retro / --max-theta: nothing to write");
    }
    crate::emit(a.out.as_deref(), &text)?;
    if let Some(p) = &a.out {
        eprintln!("wrote {p} ({rows} rows)");
    }
    Ok(())
}
