//! `evtac labels`.

/// Arguments of `evtac labels`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `evtac labels`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("evtac labels is being built")
}
