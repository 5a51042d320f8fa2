//! `evtac represent`.

/// Arguments of `evtac represent`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `evtac represent`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("evtac represent is being built")
}
