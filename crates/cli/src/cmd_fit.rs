//! `paperbsdf fit` (being built; see the issue tracker).

/// Arguments of `paperbsdf fit`.
#[derive(clap::Args, Debug)]
pub struct FitArgs {
    /// Arguments (not yet defined).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub rest: Vec<String>,
}

/// Runs `paperbsdf fit`.
pub fn run(_args: FitArgs) -> anyhow::Result<()> {
    anyhow::bail!("`paperbsdf fit` is not available in this build yet")
}
