//! `evtac simulate`.

/// Arguments of `evtac simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `evtac simulate`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("evtac simulate is being built")
}
