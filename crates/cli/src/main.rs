//! `paperbsdf`: the command-line tool over the project's crates.
//!
//! Each subcommand lives in its own module (`cmd_*.rs`); this file only parses
//! arguments and reports errors. Errors are printed as `error: ...` with their
//! chain of causes and exit code 2; nothing panics on bad input.

use clap::{Parser, Subcommand};

mod cmd_eval;
mod cmd_fit;
mod cmd_list;
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
    /// Directional albedo (reflectance, transmittance) of a model for light at given polar angles.
    Albedo(cmd_eval::AlbedoArgs),
    /// Ground truth: Monte Carlo simulation of the physical paper slab.
    Simulate(cmd_simulate::SimulateArgs),
    /// Fit a model to in-plane BSDF measurements.
    Fit(cmd_fit::FitArgs),
    /// In-plane plots of measurements and models, like the supplement's figures.
    Plot(cmd_plot::PlotArgs),
    /// Render a paper scene (a TOML scene file or a built-in scene name).
    Render(cmd_render::RenderArgs),
    /// List the models with their parameters and the paper presets with their values.
    List(cmd_list::ListArgs),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Eval(a) => cmd_eval::run_eval(a),
        Command::Albedo(a) => cmd_eval::run_albedo(a),
        Command::Simulate(a) => cmd_simulate::run(a),
        Command::Fit(a) => cmd_fit::run(a),
        Command::Plot(a) => cmd_plot::run(a),
        Command::Render(a) => cmd_render::run(a),
        Command::List(a) => cmd_list::run(a),
    };
    if let Err(e) = result {
        eprintln!("error: {e}");
        for cause in e.chain().skip(1) {
            eprintln!("  caused by: {cause}");
        }
        std::process::exit(2);
    }
}
