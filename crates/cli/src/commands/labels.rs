//! `evtac labels`: contact-angle labels for every trial of a dataset, from each trial's IMU.
//!
//! Writes `DATASET_DIR/labels/<trial>.csv` (`t_us,theta_deg,pitch_deg,roll_deg` on the IMU's
//! time base) and prints the validation: the integrated tilt at each commanded stop against the
//! commanded angle (the paper: -0.01 +- 0.04 deg) and, where the dataset has ground truth, the
//! labels' RMS error against it.

use std::path::PathBuf;

use anyhow::Context as _;
use evtac_events::manifest::Manifest;
use evtac_labels::dataset::IDENTITY_CALIBRATION_FLAG;
use evtac_labels::dataset::{DatasetLabels, label_and_write};
use evtac_labels::{CalibrationSource, LabelConfig, LabelSource, ScaleMethod, dataset_calibration};
use rayon::prelude::*;

/// Arguments of `evtac labels`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The dataset folder (holding `trials.csv`, `calibration.json` and the recordings).
    pub dataset_dir: PathBuf,
    /// Print the per-trial reports and summaries as JSON on stdout instead of text.
    #[arg(long)]
    pub json: bool,
    /// A JSON file with label settings (`evtac_labels::LabelConfig`); unset fields keep their
    /// defaults.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Butterworth low-pass cutoff in Hz (overrides the config).
    #[arg(long, value_name = "HZ")]
    pub cutoff_hz: Option<f64>,
    /// How the gyroscope's scale is calibrated: total-rotation, commanded-speed or none
    /// (overrides the config).
    #[arg(long, value_name = "METHOD", value_parser = parse_scale)]
    pub scale: Option<ScaleMethod>,
    /// Label with the identity IMU-to-sensor rotation instead of the dataset's calibration.json
    /// (which may then be absent). Only right when the IMU's axes are the sensor's.
    #[arg(long = IDENTITY_CALIBRATION_FLAG)]
    pub identity_calibration: bool,
}

/// `--scale`: a scale method by its name in label configs (`total-rotation`, ...).
fn parse_scale(s: &str) -> Result<ScaleMethod, String> {
    use serde::Deserialize;
    use serde::de::IntoDeserializer;
    let name: serde::de::value::StrDeserializer<'_, serde::de::value::Error> =
        s.into_deserializer();
    ScaleMethod::deserialize(name).map_err(|_| {
        format!("unknown scale method `{s}`: use total-rotation, commanded-speed or none")
    })
}

/// Runs `evtac labels`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let dir = &args.dataset_dir;
    let mut config = match &args.config {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read the label config {}", path.display()))?;
            serde_json::from_str::<LabelConfig>(&text)
                .with_context(|| format!("invalid label config {}", path.display()))?
        }
        None => LabelConfig::default(),
    };
    if let Some(cutoff_hz) = args.cutoff_hz {
        config.cutoff_hz = cutoff_hz;
    }
    if let Some(scale) = args.scale {
        config.scale = scale;
    }
    let manifest = Manifest::read(dir)?;
    let source = if args.identity_calibration {
        CalibrationSource::Identity
    } else {
        CalibrationSource::File
    };
    let calibration = dataset_calibration(dir, source)?;
    anyhow::ensure!(
        !manifest.trials.is_empty(),
        "{} lists no trials",
        Manifest::path(dir).display()
    );
    let bar = crate::progress::bar(manifest.trials.len() as u64, "labels");
    // Trials are independent: label them in parallel, keeping manifest order in the output.
    let reports = manifest
        .trials
        .par_iter()
        .map(|meta| {
            let report = label_and_write(dir, meta, &calibration, &config);
            bar.inc(1);
            report
        })
        .collect::<Result<Vec<_>, _>>()?;
    bar.finish_and_clear();
    let summary = DatasetLabels::from_reports(reports);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_text(dir, &summary, LabelSource::of(dir)?);
    }
    Ok(())
}

fn print_text(dir: &std::path::Path, s: &DatasetLabels, source: LabelSource) {
    println!(
        "labelled {} trials into {}",
        s.trials.len(),
        dir.join(evtac_events::layout::LABELS_DIR).display()
    );
    if source == LabelSource::Commanded {
        // No gyroscope was read: no scale, no bias, and a stop check would compare the command
        // with itself.
        println!(
            "labels: the commanded motion from trials.csv (label_source.json), not the IMU: no \
             stop check, no gyroscope scale"
        );
    }
    match &s.stop_error_deg {
        _ if source == LabelSource::Commanded => {}
        Some(stop) => println!(
            "stop check, integrated tilt minus commanded stop angle (deg): {stop}  \
             [paper: -0.01 +- 0.04]"
        ),
        None => println!("stop check: no trial has a commanded stop"),
    }
    if let Some(rms) = &s.truth_rms_deg {
        let worst = s
            .trials
            .iter()
            .filter_map(|r| r.truth.map(|t| (t.rms_deg, &r.trial)))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        print!(
            "labels vs ground truth, per-trial RMS over pitch and roll (deg): mean {:.4}, \
             max {:.4}",
            rms.mean, rms.max
        );
        match worst {
            Some((_, trial)) => println!(" ({trial}), n = {}", rms.n),
            None => println!(", n = {}", rms.n),
        }
    }
    if let Some(scale) = s
        .scale_factor
        .as_ref()
        .filter(|_| source == LabelSource::Imu)
    {
        println!(
            "gyroscope scale factors: {:.4} .. {:.4} (mean {:.4})",
            scale.min, scale.max, scale.mean
        );
    }
}
