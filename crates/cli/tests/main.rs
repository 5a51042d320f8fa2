//! Integration tests of the `evtac` binary: one test binary, one module per subcommand.

mod beyond;
mod check;
mod common;
mod convert;
mod data_loss;
mod doc_examples;
mod evaluate;
mod filter;
mod import;
mod info;
mod jobs;
mod labels;
mod legacy_formats;
mod online;
mod predict;
mod render;
mod render_model;
mod render_mp4;
mod represent;
mod reproduce;
mod sensitivity;
mod simulate;
mod slurm;
mod stats;
mod train;
mod tune;
