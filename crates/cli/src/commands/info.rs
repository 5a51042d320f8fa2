//! `evtac info`.

/// Arguments of `evtac info`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `evtac info`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("evtac info is being built")
}
