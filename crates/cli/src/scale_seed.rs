//! `--scale` and `--seed`: the size and the master seed of what a command simulates (and,
//! where it trains, of its training plan), one pair of flags with one meaning in `simulate`,
//! `reproduce` and `sensitivity`.

use evtac_sim::Scale;

/// The size and seed flags, flattened into each command that simulates.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct ScaleSeed {
    /// Size of the datasets (and of the training plan, where the command trains): tiny
    /// (tests), small or paper (the paper's trial counts).
    #[arg(long, default_value = "small")]
    pub scale: Scale,
    /// Master seed (the simulation; the splits and training too, where the command trains):
    /// the same seed gives the same datasets, byte for byte.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}
