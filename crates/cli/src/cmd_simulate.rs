//! `paperbsdf simulate` (being built; see the issue tracker).

/// Arguments of `paperbsdf simulate`.
#[derive(clap::Args, Debug)]
pub struct SimulateArgs {
    /// Arguments (not yet defined).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub rest: Vec<String>,
}

/// Runs `paperbsdf simulate`.
pub fn run(_args: SimulateArgs) -> anyhow::Result<()> {
    anyhow::bail!("`paperbsdf simulate` is not available in this build yet")
}
