//! `paperbsdf plot` (being built; see the issue tracker).

/// Arguments of `paperbsdf plot`.
#[derive(clap::Args, Debug)]
pub struct PlotArgs {
    /// Arguments (not yet defined).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub rest: Vec<String>,
}

/// Runs `paperbsdf plot`.
pub fn run(_args: PlotArgs) -> anyhow::Result<()> {
    anyhow::bail!("`paperbsdf plot` is not available in this build yet")
}
