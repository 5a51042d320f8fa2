//! `evtac evaluate`.

/// Arguments of `evtac evaluate`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `evtac evaluate`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("evtac evaluate is being built")
}
