//! `evtac convert`.

/// Arguments of `evtac convert`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `evtac convert`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("evtac convert is being built")
}
