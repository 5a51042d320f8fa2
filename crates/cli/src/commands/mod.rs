//! One module per subcommand: its clap arguments (`Args`) and its `run`.

pub mod check;
pub mod convert;
pub mod evaluate;
pub mod filter;
pub mod import;
pub mod info;
pub mod jobs;
pub mod labels;
pub mod online;
pub mod predict;
pub mod render;
pub mod represent;
pub mod reproduce;
pub mod sensitivity;
pub mod simulate;
pub mod stats;
pub mod train;
pub mod tune;
