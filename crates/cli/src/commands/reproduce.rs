//! `evtac reproduce`.

/// Arguments of `evtac reproduce`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `evtac reproduce`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("evtac reproduce is being built")
}
