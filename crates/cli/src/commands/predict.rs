//! `evtac predict`.

/// Arguments of `evtac predict`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `evtac predict`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("evtac predict is being built")
}
