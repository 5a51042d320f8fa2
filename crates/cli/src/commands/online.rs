//! `evtac online`.

/// Arguments of `evtac online`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `evtac online`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("evtac online is being built")
}
