//! `paperbsdf render` (being built; see the issue tracker).

/// Arguments of `paperbsdf render`.
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// Arguments (not yet defined).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub rest: Vec<String>,
}

/// Runs `paperbsdf render`.
pub fn run(_args: RenderArgs) -> anyhow::Result<()> {
    anyhow::bail!("`paperbsdf render` is not available in this build yet")
}
