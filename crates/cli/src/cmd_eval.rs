//! `paperbsdf eval` and `paperbsdf albedo`: a model's BSDF values and directional
//! albedo, in the conventions of docs/design.md section 2.

use crate::choices::{self, ComponentChoice};
use anyhow::{bail, Result};
use paperbsdf_core::geometry::in_plane_directions;
use paperbsdf_core::{DVec3, Rgb};
use paperbsdf_io::angles::check_angles;
use paperbsdf_io::dirs::csv_line;
use paperbsdf_io::models::{load_model_with, LoadedModel, SlabSettings};
use paperbsdf_io::DataError;

/// `--slab-nodes`, shared by the commands that load a model (`eval`,
/// `albedo`, `measure`).
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct SlabArgs {
    /// Nodes per hemisphere of the model `slab`'s discretisation (default 32, or what a slab FIT.json given as --params records; 64 converges its values to within 0.2% of twice the nodes on the accuracy cases but one, and builds about 4 times slower). Only with --model slab.
    #[arg(long = "slab-nodes")]
    pub slab_nodes: Option<usize>,
}

impl SlabArgs {
    /// Loads model `name` with parameters from `params` and this
    /// discretisation (an error for a model other than `slab`).
    pub fn load(&self, name: &str, params: &str) -> Result<LoadedModel, DataError> {
        load_model_with(name, params, &SlabSettings { nodes: self.slab_nodes }, "--slab-nodes")
    }
}

/// Arguments of `paperbsdf eval`.
#[derive(clap::Args, Debug)]
pub struct EvalArgs {
    /// Model name: rough-dielectric, paper, reduced-multilayer, slab (the same sheet as paper solved by adding-doubling), lambert-glass, or measured (with --params FILE.bsdf, an RGL measured file).
    #[arg(long)]
    pub model: String,
    /// Parameters: a JSON or TOML file, inline JSON (`'{"eta":1.5,...}'`), a FIT.json, or a preset (matte, luster, glossy); for `measured`, the `.bsdf` file.
    #[arg(long)]
    pub params: String,
    /// CSV file of direction pairs (columns wi_x,wi_y,wi_z,wo_x,wo_y,wo_z; others are echoed).
    #[arg(long, conflicts_with_all = ["theta_i", "theta_o"])]
    pub dirs: Option<String>,
    /// In-plane incident angles in degrees, comma-separated (e.g. `0,30,60`).
    #[arg(long = "theta-i", value_delimiter = ',', allow_hyphen_values = true)]
    pub theta_i: Vec<f64>,
    /// In-plane viewing angles: one angle, or FROM:TO:STEP, in degrees (signed; negative is opposite the light).
    #[arg(long = "theta-o", allow_hyphen_values = true)]
    pub theta_o: Option<String>,
    #[command(flatten)]
    pub slab: SlabArgs,
    /// Which component to evaluate (a component the model lacks is an error).
    #[arg(long, default_value = "all", value_parser = choices::component(), ignore_case = true)]
    pub component: ComponentChoice,
    /// Write the table to this file (atomically) instead of standard output.
    #[arg(long)]
    pub out: Option<String>,
}

/// Arguments of `paperbsdf albedo`: the fractions of the light arriving from
/// polar angle `theta_i` (in the x-z plane) that the model reflects and
/// transmits, i.e. `int f(wi, wo) |cos wo| dwo` over each hemisphere of
/// outgoing directions, delta lobes included.
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
    /// Which face the light arrives at.
    #[arg(long, value_enum, default_value_t = Side::Front, ignore_case = true)]
    pub side: Side,
    #[command(flatten)]
    pub slab: SlabArgs,
}

/// `albedo --side`: the face the light arrives at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Side {
    /// The front face: light from z > 0.
    Front,
    /// The back face: light from z < 0.
    Back,
}

/// Most angles `eval` accepts in `--theta-o` (evaluating is cheap; the limit
/// bounds the output, 2 rows per angle and incident angle).
pub const MAX_EVAL_ANGLES: usize = 100_000;

/// BSDF values in the shortest decimal that reads back as the same f64
/// (Rust's `{:e}`), so other front ends (the Python package) can be checked
/// against the CLI exactly.
fn fmt_eval(v: Rgb, rgb: bool) -> String {
    if rgb {
        format!("{:e},{:e},{:e}", v.0[0], v.0[1], v.0[2])
    } else {
        format!("{:e}", v.0[0])
    }
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

/// Runs `paperbsdf eval`.
pub fn run_eval(a: EvalArgs) -> Result<()> {
    if let Some(out) = &a.out {
        paperbsdf_io::check_output_path(out, "--out")?;
    }
    let model = a.slab.load(&a.model, &a.params)?;
    let component = a.component.0;
    // Before any output.
    model.check_component(component)?;
    let eval = |wi: DVec3, wo: DVec3| -> Result<Rgb> { Ok(model.eval_component(wi, wo, component)?) };
    let rgb = model.is_rgb();
    let mut text = String::new();
    if let Some(path) = &a.dirs {
        let f = paperbsdf_io::dirs::read_dirs(path)?;
        text.push_str(&format!("{},{}\n", csv_line(&f.header), value_header(rgb)));
        for r in &f.rows {
            let v = eval(r.wi, r.wo)?;
            text.push_str(&format!("{},{}\n", csv_line(&r.fields), fmt_eval(v, rgb)));
        }
    } else {
        let to = match &a.theta_o {
            Some(s) => paperbsdf_io::angles::parse_angles(s, "--theta-o", MAX_EVAL_ANGLES)?,
            None => bail!("give either --dirs F.csv or --theta-i LIST with --theta-o FROM:TO:STEP"),
        };
        if a.theta_i.is_empty() {
            bail!("--theta-o needs --theta-i LIST (degrees)");
        }
        check_angles(&a.theta_i, "--theta-i", 0.0..=90.0)?;
        check_angles(&to, "--theta-o", -90.0..=90.0)?;
        text.push_str(&format!("kind,theta_i_deg,theta_o_deg,{}\n", value_header(rgb)));
        for &ti in &a.theta_i {
            for (kind, t) in [("R", false), ("T", true)] {
                for &o in &to {
                    let (wi, wo) = in_plane_directions(ti, o, t);
                    let v = eval(wi, wo)?;
                    text.push_str(&format!("{kind},{ti},{o},{}\n", fmt_eval(v, rgb)));
                }
            }
        }
    }
    crate::emit(a.out.as_deref(), &text)
}

/// Runs `paperbsdf albedo`.
pub fn run_albedo(a: AlbedoArgs) -> Result<()> {
    let model = a.slab.load(&a.model, &a.params)?;
    let sign = match a.side {
        Side::Front => 1.0,
        Side::Back => -1.0,
    };
    // [0, 90), as the help says: at 90 degrees the light grazes the sheet and no flux enters.
    check_angles(&a.theta_i, "--theta-i", 0.0..90.0)?;
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
