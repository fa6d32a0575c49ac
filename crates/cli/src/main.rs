//! `paperbsdf`: the command-line tool over the project's crates.
//!
//! Each subcommand lives in its own module (`cmd_*.rs`); this file only parses
//! arguments and reports errors. Errors are printed as `error: ...` with their
//! chain of causes (a cause whose text the message already shows is not
//! repeated) and exit code 2; nothing panics on bad input. An interrupted run
//! (Ctrl-C) exits with 130 and leaves no temporary file behind.

use clap::{Parser, Subcommand};

mod choices;
mod cmd_convert;
mod cmd_eval;
mod cmd_fit;
mod cmd_list;
mod cmd_measure;
mod cmd_plot;
mod cmd_render;
mod cmd_simulate;

/// The conventions every subcommand follows, printed by `paperbsdf --help`.
const CONVENTIONS: &str = "\
Conventions:
  frame     local frame, +z the normal of the front face (z = 0); the back face is z = -d.
            f(wi, wo) is the BSDF without the cosine; wi points toward the light, wo toward
            the viewer (unit vectors). Reflection: wi.z, wo.z of one sign; transmission: opposite.
  in-plane  light at theta_i (degrees, 0..90) in the x-z plane on the +x side; theta_o signed,
            positive on the light's side. R rows look from z > 0, T rows from z < 0 with
            theta_o measured from -z (straight through at theta_i = 30 is T, theta_o = -30).
  units     lengths in mm (d), coefficients in 1/mm (sigma_a, sigma_s), angles in degrees.
  params    --params FILE.json|FILE.toml, inline JSON '{...}', a FIT.json of `paperbsdf fit`,
            or a preset name (matte, luster, glossy). Paper parameters: d, sigma_a, sigma_s,
            g_f, g_b, w_b, eta_f, eta_b, m_f, m_b, dist_f, dist_b [, face_scattering, name];
            `paperbsdf list` prints every model's parameters and ranges and the presets.
  output    eval: kind,theta_i_deg,theta_o_deg,f (or the --dirs columns then f); the value
            column f becomes r,g,b when sigma_a or sigma_s (k_d, k_t) is an RGB triple.
            simulate adds stderr; albedo prints theta_i_deg,reflectance,transmittance.";

/// The Paper BSDF (Papas, de Mesa, Jensen, EGSR 2014): evaluate, simulate, fit, plot, render.
#[derive(Parser, Debug)]
#[command(name = "paperbsdf", version, about, long_about = None, after_help = CONVENTIONS)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Evaluate a model's BSDF f(wi, wo) (without cosine) for given directions or in-plane angles.
    Eval(cmd_eval::EvalArgs),
    /// Directional albedo: the fractions of the light arriving at given polar angles that a model reflects and transmits (integral over outgoing directions).
    Albedo(cmd_eval::AlbedoArgs),
    /// Ground truth: Monte Carlo simulation of the physical paper slab.
    Simulate(cmd_simulate::SimulateArgs),
    /// Fit a model to in-plane BSDF measurements or a measured RGL .bsdf file.
    Fit(cmd_fit::FitArgs),
    /// Sample a measured RGL .bsdf file on in-plane angles into the measurement CSV that fit and plot read.
    Convert(cmd_convert::ConvertArgs),
    /// In-plane plots of measurements and models, like the supplement's figures.
    Plot(cmd_plot::PlotArgs),
    /// Render a paper scene (a TOML scene file or a built-in scene name).
    Render(cmd_render::RenderArgs),
    /// Predict what paper makers measure: ISO/TAPPI opacity, ISO brightness, gloss, Kubelka-Munk, scatter distance.
    Measure(cmd_measure::MeasureArgs),
    /// Plot the reflected light across a shadow edge (scatter distance, supplement Figure 2).
    Edge(cmd_measure::EdgeArgs),
    /// Find Paper BSDF parameters that reproduce a paper datasheet (grammage, caliper, opacity, ...).
    FromDatasheet(cmd_measure::DatasheetArgs),
    /// List the models with their parameters and the paper presets with their values.
    List(cmd_list::ListArgs),
}

/// The error of a run stopped by Ctrl-C after writing what it had (exit code 130).
#[derive(Debug)]
pub struct Interrupted(pub String);

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Interrupted {}

/// Exit code of a run stopped by SIGINT (128 + 2, as shells report it).
pub const EXIT_INTERRUPTED: i32 = 130;

/// Writes a command's output `text` to the file `out` (atomically) or, without
/// one, to standard output.
pub fn emit(out: Option<&str>, text: &str) -> anyhow::Result<()> {
    match out {
        Some(p) => paperbsdf_io::write_atomic(p, text.as_bytes())?,
        None => print!("{text}"),
    }
    Ok(())
}

/// The lines printed for an error: the message, then each cause not already shown.
fn error_lines(e: &anyhow::Error) -> Vec<String> {
    let mut lines = vec![format!("error: {e}")];
    let mut shown = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if shown.contains(&c) {
            continue;
        }
        lines.push(format!("  caused by: {c}"));
        shown.push_str(&c);
    }
    lines
}

fn main() {
    let cli = Cli::parse();
    if !matches!(cli.command, Command::Render(_)) {
        // Render has its own handler (first Ctrl-C: stop and write the partial image).
        let _ = ctrlc::set_handler(|| {
            paperbsdf_io::atomic::remove_temp_files();
            eprintln!("\ninterrupted");
            std::process::exit(EXIT_INTERRUPTED);
        });
    }
    let result = match cli.command {
        Command::Eval(a) => cmd_eval::run_eval(a),
        Command::Albedo(a) => cmd_eval::run_albedo(a),
        Command::Simulate(a) => cmd_simulate::run(a),
        Command::Fit(a) => cmd_fit::run(a),
        Command::Convert(a) => cmd_convert::run(a),
        Command::Plot(a) => cmd_plot::run(a),
        Command::Render(a) => cmd_render::run(a),
        Command::Measure(a) => cmd_measure::run_measure(a),
        Command::Edge(a) => cmd_measure::run_edge(a),
        Command::FromDatasheet(a) => cmd_measure::run_datasheet(a),
        Command::List(a) => cmd_list::run(a),
    };
    if let Err(e) = result {
        if let Some(i) = e.downcast_ref::<Interrupted>() {
            eprintln!("{i}");
            std::process::exit(EXIT_INTERRUPTED);
        }
        for l in error_lines(&e) {
            eprintln!("{l}");
        }
        std::process::exit(2);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn causes_already_in_the_message_are_not_repeated() {
        // Issue 16: `x.json: No such file` was followed by `caused by: No such file`.
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file or directory (os error 2)");
        let e: anyhow::Error = paperbsdf_io::DataError::Io {
            file: "x.json".into(),
            source: io,
        }
        .into();
        assert_eq!(
            error_lines(&e),
            ["error: x.json: No such file or directory (os error 2)"]
        );
        // A cause with new information is still shown.
        let e = anyhow::anyhow!("disk full").context("writing out.csv");
        assert_eq!(error_lines(&e), ["error: writing out.csv", "  caused by: disk full"]);
    }
}
