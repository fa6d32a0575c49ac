//! `paperbsdf`: the command-line tool over the project's crates.
//!
//! Each subcommand lives in its own module (`cmd_*.rs`); this file only parses
//! arguments and reports errors. Errors are printed as `error: ...` with their
//! chain of causes and exit code 2; nothing panics on bad input.

use clap::{Parser, Subcommand};

mod cmd_eval;
mod cmd_fit;
mod cmd_measure;
mod cmd_plot;
mod cmd_render;
mod cmd_simulate;

/// The Paper BSDF (Papas, de Mesa, Jensen, EGSR 2014): evaluate, simulate, fit, plot, render.
#[derive(Parser, Debug)]
#[command(name = "paperbsdf", version, about, long_about = None)]
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
    /// Fit a model to in-plane BSDF measurements.
    Fit(cmd_fit::FitArgs),
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
        Command::Measure(a) => cmd_measure::run_measure(a),
        Command::Edge(a) => cmd_measure::run_edge(a),
        Command::FromDatasheet(a) => cmd_measure::run_datasheet(a),
    };
    if let Err(e) = result {
        eprintln!("error: {e}");
        for cause in e.chain().skip(1) {
            eprintln!("  caused by: {cause}");
        }
        std::process::exit(2);
    }
}
