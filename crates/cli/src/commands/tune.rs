//! `evtac tune`.

/// Arguments of `evtac tune`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `evtac tune`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("evtac tune is being built")
}
