//! `evtac train`.

/// Arguments of `evtac train`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `evtac train`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("evtac train is being built")
}
