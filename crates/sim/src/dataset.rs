//! Writing a simulated dataset folder: one AEDAT4 file per trial, the manifest, ground truth,
//! the no-contact recording, the calibration and the simulator's parameters.
//!
//! ```text
//! DIR/trials.csv            the manifest (evtac_events::manifest)
//! DIR/t0000.aedat4 ...      events (640x480) and IMU samples of each trial
//! DIR/truth/t0000.csv ...   t_us,theta_deg,pitch_deg,roll_deg at 1 kHz (pose reached, sensor frame)
//! DIR/no_contact.aedat4     the sensor at rest out of contact (for the static mask)
//! DIR/calibration.json      evtac_labels::geometry::Calibration
//! DIR/simulator.json        protocol, scale, seed and every SimParams value
//! ```
//!
//! Trials run in parallel on the current rayon pool; each trial's randomness comes from its own
//! seed (see [`crate::protocol::trial_seed`]), so the same seed gives the same bytes whatever
//! the number of threads.

use crate::capture::{AsSimulated, Capture};
use evtac_events::layout::{CALIBRATION_FILE, NO_CONTACT_FILE, SIMULATOR_FILE, TRUTH_DIR};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use evtac_events::manifest::{Manifest, ManifestError, TrialMeta};
use evtac_events::{Event, ImuSample, Resolution};
use evtac_formats::aedat::{AedatError, AedatWriter, Compression, WriterConfig};
use rayon::prelude::*;
use serde::Serialize;

use crate::params::SimParams;
use crate::protocol::{Design, Protocol, Scale, TrialSpec, plan_design, trial_seed};
use crate::trial::{Simulator, TrialRecording, TruthSample};

/// The camera name written into every AEDAT4 file.
pub const SOURCE_NAME: &str = "DVXplorer_SIM00000";

/// Errors writing a dataset.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DatasetError {
    /// A file or folder could not be created or written.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The AEDAT4 writer refused the data or failed.
    #[error("cannot write AEDAT4 file {path}: {source}")]
    Aedat {
        /// The recording being written.
        path: PathBuf,
        /// The writer's error.
        #[source]
        source: AedatError,
    },
    /// The manifest could not be written.
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    /// The capture could not save a recording (a filter that does not fit the sensor).
    #[error("{name}: {reason}")]
    Capture {
        /// The recording's file name.
        name: String,
        /// Why.
        reason: String,
    },
    /// A JSON file could not be serialised.
    #[error("cannot serialise {path}: {source}")]
    Json {
        /// The JSON file.
        path: PathBuf,
        /// The serialiser's error.
        #[source]
        source: serde_json::Error,
    },
}

/// What to simulate.
#[derive(Debug, Clone, PartialEq)]
pub struct DatasetConfig {
    /// The protocol.
    pub protocol: Protocol,
    /// How many trials.
    pub scale: Scale,
    /// The dataset's seed: the camera's fixed pattern comes from it alone (the same sensor for
    /// every protocol), the trials from it and the protocol.
    pub seed: u64,
    /// The simulator's parameters.
    pub params: SimParams,
    /// AEDAT4 packet compression.
    pub compression: Compression,
    /// Simulate only the first this many trials of the plan (tests, benchmarks); `None`: all.
    pub limit: Option<usize>,
    /// Passes over the conditions of Experiments 1 and 2 (each with the sensor seated again)
    /// instead of the scale's; `None`: the scale's.
    pub repeats: Option<usize>,
}

impl DatasetConfig {
    /// `protocol` at `scale` with default parameters and LZ4 compression (DV's default).
    pub fn new(protocol: Protocol, scale: Scale, seed: u64) -> Self {
        Self {
            protocol,
            scale,
            seed,
            params: SimParams::default(),
            compression: Compression::Lz4,
            limit: None,
            repeats: None,
        }
    }
}

/// What `simulator.json` holds.
#[derive(Serialize)]
struct SimulatorRecord<'a> {
    generator: String,
    protocol: Protocol,
    scale: Scale,
    seed: u64,
    repeats: usize,
    trials: usize,
    hot_pixels: Vec<(u16, u16, f64)>,
    params: &'a SimParams,
    /// What the capture did to the events before saving them ([`Capture::describe`]), absent
    /// when they are saved as simulated.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    capture: Vec<String>,
}

/// The camera seed of a dataset seed.
fn camera_seed(seed: u64) -> u64 {
    trial_seed(seed, usize::MAX)
}

impl DatasetConfig {
    /// The scale's design, with the repeats asked for.
    pub fn design(&self) -> Design {
        let design = self.scale.design();
        match self.repeats {
            Some(n) => design.with_repeats(n),
            None => design,
        }
    }

    /// The trials to simulate: the plan, cut at the limit.
    pub fn trials(&self) -> Vec<TrialSpec> {
        let design = self.design();
        let mut trials = plan_design(self.protocol, &design, self.seed, &self.params.timeline);
        trials.truncate(self.limit.unwrap_or(usize::MAX));
        trials
    }
}

/// What a dataset and a session share: the sensor and the trials.
pub(crate) struct Setup {
    /// The sensor.
    pub sim: Simulator,
    /// Its camera's resolution.
    pub resolution: Resolution,
    /// The trials.
    pub trials: Vec<TrialSpec>,
}

/// Creates `out_dir` and its truth folder, writes the no-contact recording (as `capture` saves
/// it) and the calibration, and returns the sensor and the trials of `config`.
pub(crate) fn set_up(
    config: &DatasetConfig,
    out_dir: &Path,
    capture: &dyn Capture,
) -> Result<Setup, DatasetError> {
    let truth_dir = out_dir.join(TRUTH_DIR);
    std::fs::create_dir_all(&truth_dir).map_err(|source| DatasetError::Io {
        path: truth_dir.clone(),
        source,
    })?;
    let sim = Simulator::new(config.params.clone(), camera_seed(config.seed));
    let camera = &config.params.camera;
    let resolution = Resolution::new(camera.width, camera.height);
    let rest = captured(
        capture,
        NO_CONTACT_FILE,
        resolution,
        sim.simulate_rest(trial_seed(config.seed, usize::MAX - 1)),
    )?;
    write_recording(
        &out_dir.join(NO_CONTACT_FILE),
        &rest,
        resolution,
        config.compression,
    )?;
    write_json(&out_dir.join(CALIBRATION_FILE), sim.calibration())?;
    Ok(Setup {
        sim,
        resolution,
        trials: config.trials(),
    })
}

/// Simulates `config` into `out_dir` (created if missing; existing files of the same names are
/// replaced). `on_trial_done` is called, from worker threads, after each trial's files are
/// written. Returns the manifest written to `out_dir/trials.csv`.
pub fn simulate_dataset(
    config: &DatasetConfig,
    out_dir: &Path,
    on_trial_done: impl Fn(&TrialMeta) + Sync,
) -> Result<Manifest, DatasetError> {
    simulate_captured(config, out_dir, &AsSimulated, on_trial_done)
}

/// [`simulate_dataset`], every recording's events saved as `capture` saves them (a filtering
/// capture's); `simulator.json` says what it did.
pub fn simulate_captured(
    config: &DatasetConfig,
    out_dir: &Path,
    capture: &dyn Capture,
    on_trial_done: impl Fn(&TrialMeta) + Sync,
) -> Result<Manifest, DatasetError> {
    let Setup {
        sim,
        resolution,
        trials,
    } = set_up(config, out_dir, capture)?;
    let total = config.params.timeline.total_deg;
    let metas = trials
        .par_iter()
        .map(|spec| {
            let file = evtac_events::layout::trial_file(&spec.name);
            let recording = captured(capture, &file, resolution, sim.simulate(spec))?;
            let truth = format!("{TRUTH_DIR}/{}.csv", spec.name);
            write_recording(
                &out_dir.join(&file),
                &recording,
                resolution,
                config.compression,
            )?;
            write_truth(&out_dir.join(&truth), &recording.truth, 0)?;
            let meta = recording.meta(&file, Some(&truth), total);
            on_trial_done(&meta);
            Ok(meta)
        })
        .collect::<Result<Vec<_>, DatasetError>>()?;
    let manifest = Manifest { trials: metas };

    write_json(
        &out_dir.join(SIMULATOR_FILE),
        &SimulatorRecord {
            generator: format!("evtac-sim {}", env!("CARGO_PKG_VERSION")),
            protocol: config.protocol,
            scale: config.scale,
            seed: config.seed,
            repeats: config.design().repeats,
            trials: manifest.trials.len(),
            hot_pixels: sim.pixel_array().hot_pixels(),
            params: &config.params,
            capture: capture.describe(),
        },
    )?;
    manifest.write(out_dir)?;
    Ok(manifest)
}

/// `recording` with its events as `capture` saves them under the name `name`.
fn captured(
    capture: &dyn Capture,
    name: &str,
    resolution: Resolution,
    mut recording: TrialRecording,
) -> Result<TrialRecording, DatasetError> {
    let events = std::mem::take(&mut recording.events);
    recording.events =
        capture
            .save(name, resolution, events)
            .map_err(|reason| DatasetError::Capture {
                name: name.to_string(),
                reason,
            })?;
    Ok(recording)
}

/// Writes a recording's events and IMU samples as an AEDAT4 file of a `resolution` sensor.
pub fn write_recording(
    path: &Path,
    recording: &TrialRecording,
    resolution: Resolution,
    compression: Compression,
) -> Result<(), DatasetError> {
    let mut writer = create_writer(path, resolution, compression)?;
    write_shifted(&mut writer, recording, 0, i64::MAX).map_err(aedat_error(path))?;
    writer.finish().map_err(aedat_error(path))?;
    Ok(())
}

/// The AEDAT4 writer of a simulated `resolution` sensor at `path`.
pub(crate) fn create_writer(
    path: &Path,
    resolution: Resolution,
    compression: Compression,
) -> Result<AedatWriter<BufWriter<File>>, DatasetError> {
    let config = WriterConfig {
        resolution,
        source_name: SOURCE_NAME.into(),
        compression,
    };
    AedatWriter::create(path, config).map_err(aedat_error(path))
}

/// The error of the writer of `path`.
pub(crate) fn aedat_error(path: &Path) -> impl Fn(AedatError) -> DatasetError + '_ {
    move |source| DatasetError::Aedat {
        path: path.to_path_buf(),
        source,
    }
}

/// Writes the events and IMU samples of `recording` before `until_us` (its own clock) into
/// `writer`, `shift_us` later.
pub(crate) fn write_shifted<W: std::io::Write>(
    writer: &mut AedatWriter<W>,
    recording: &TrialRecording,
    shift_us: i64,
    until_us: i64,
) -> Result<(), AedatError> {
    let events = &recording.events[..recording.events.partition_point(|e| e.t < until_us)];
    let mut imu = &recording.imu[..recording.imu.partition_point(|s| s.t < until_us)];
    let mut shifted = Vec::with_capacity(4096);
    let shift_imu = |samples: &[ImuSample]| -> Vec<ImuSample> {
        samples
            .iter()
            .map(|s| ImuSample {
                t: s.t + shift_us,
                ..*s
            })
            .collect()
    };
    // Interleave by time so that readers see IMU and events side by side, as from a camera.
    for chunk in events.chunks(4096) {
        let until = chunk.last().map_or(i64::MIN, |e| e.t);
        let n = imu.partition_point(|s| s.t <= until);
        writer.write_imu(&shift_imu(&imu[..n]))?;
        imu = &imu[n..];
        shifted.clear();
        shifted.extend(chunk.iter().map(|e| Event {
            t: e.t + shift_us,
            ..*e
        }));
        writer.write_events(&shifted)?;
    }
    writer.write_imu(&shift_imu(imu))
}

/// Writes ground truth as `t_us,theta_deg,pitch_deg,roll_deg`, `shift_us` later.
pub fn write_truth(path: &Path, truth: &[TruthSample], shift_us: i64) -> Result<(), DatasetError> {
    let io = |source| DatasetError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut out = std::io::BufWriter::new(file);
    writeln!(out, "t_us,theta_deg,pitch_deg,roll_deg").map_err(io)?;
    for s in truth {
        writeln!(
            out,
            "{},{:.6},{:.6},{:.6}",
            s.t_us + shift_us,
            s.theta_deg,
            s.pitch_deg,
            s.roll_deg
        )
        .map_err(io)?;
    }
    out.flush().map_err(io)
}

pub(crate) fn write_json(path: &Path, value: &impl Serialize) -> Result<(), DatasetError> {
    let text = serde_json::to_string_pretty(value).map_err(|source| DatasetError::Json {
        path: path.to_path_buf(),
        source,
    })?;
    std::fs::write(path, text + "\n").map_err(|source| DatasetError::Io {
        path: path.to_path_buf(),
        source,
    })
}
