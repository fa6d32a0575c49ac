//! `paperbsdf eval` and `paperbsdf albedo`.

/// Arguments of `paperbsdf eval`.
#[derive(clap::Args, Debug)]
pub struct EvalArgs {
    /// Arguments (being defined).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub rest: Vec<String>,
}

/// Arguments of `paperbsdf albedo`.
#[derive(clap::Args, Debug)]
pub struct AlbedoArgs {
    /// Arguments (being defined).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub rest: Vec<String>,
}

/// Runs `paperbsdf eval`.
pub fn run_eval(_args: EvalArgs) -> anyhow::Result<()> {
    anyhow::bail!("not yet")
}

/// Runs `paperbsdf albedo`.
pub fn run_albedo(_args: AlbedoArgs) -> anyhow::Result<()> {
    anyhow::bail!("not yet")
}
