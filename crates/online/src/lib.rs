//! Online contact-angle estimation from live or replayed event streams, with measured latency.
//!
//! A robot needs the contact angle while it moves. This crate runs a trained model (an
//! [`evtac_learn::Model`]: weights, representation settings, no-contact mask) on an event
//! stream and emits `(pitch, roll)` at a fixed interval of event time, stamping each estimate
//! with its latency and its processing time.
//!
//! - [`input`]: where events come from: a recording replayed as fast as possible or at
//!   recorded pace ([`input::Paced`]), a live DV network stream with reconnection and backoff,
//!   a ROS 2 event topic over DDS ([`input::Ros2Source`]), standard input, or memory.
//! - [`Estimator`]: the single-threaded core (crop, representation, MLP, latency and
//!   processing-time stamps).
//! - [`pipeline::run`]: ingestion and estimation on two threads with a bounded queue between.
//! - [`Summary`]: estimates, median/P99/max latency and processing time, late estimates,
//!   dropped events.
//! - [`ros2`]: each estimate published on a ROS 2 topic (`geometry_msgs/msg/Vector3Stamped`,
//!   pure Rust over DDS, never holding estimation up).
//! - [`mcap_log`]: the same messages logged to an MCAP file that Foxglove and `rosbags` open,
//!   with the representation's [`frames`] as images when asked for.
//!
//! The exact definition of latency is in `docs/online.md`; in short, it runs from the moment the
//! ingestion thread received the chunk that made an estimate's time final to the end of that
//! estimate's forward pass. The processing time is the estimator's own work for an estimate,
//! without any wait: what a replay as fast as possible can report, its latency being mostly
//! queueing behind a reader that runs ahead.
//!
//! ```no_run
//! use evtac_online::input::{self, OpenOptions, SourceSpec};
//! use evtac_online::pipeline::{self, Output, PipelineConfig};
//! use evtac_learn::Model;
//! use evtac_online::Estimator;
//! use std::ops::ControlFlow;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let model = Model::load("model/".as_ref())?;
//! let spec: SourceSpec = "recording.aedat4".parse()?;
//! let opened = input::open(&spec, &OpenOptions::default(), &mut |notice| eprintln!("{notice}"))?;
//! let sensor = opened.resolution.ok_or("the recording does not state its sensor size")?;
//! let estimator = Estimator::for_model(&model, sensor, 1000)?;
//! let summary = pipeline::run(opened.source, estimator, &PipelineConfig::default(), |out| {
//!     if let Output::Estimate(e) = out {
//!         println!("{} {} {}", e.t_us, e.pitch_deg, e.roll_deg);
//!     }
//!     ControlFlow::Continue(())
//! })?;
//! eprintln!("{summary}");
//! # Ok(()) }
//! ```

mod backoff;
mod estimator;
pub mod frames;
pub mod image_msg;
pub mod input;
mod latency;
pub mod mcap_log;
mod notice;
pub mod pipeline;
pub mod ros2;
mod schedule;
mod summary;

pub use backoff::Backoff;
pub use estimator::{Counters, Error as EstimatorError, Estimate, Estimator};
pub use latency::LatencyStats;
pub use notice::Notice;
pub use schedule::{Error as ScheduleError, Schedule};
pub use summary::Summary;
