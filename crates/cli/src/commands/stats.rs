//! `evtac stats`: what a recording says about its sensor in the simulator's terms (event rate
//! over time, background rate and ON fraction at rest, hot pixels, the IMU's noise and bias),
//! and with `--sim-params` a simulator parameter file for `evtac simulate --params`, with
//! `--hot-pixels` a mask of the hot pixels for `--filter hot-pixels=MASK`. The work is
//! `evtac_import::sensor_stats`'s; `--filter` measures the recording as those filters leave it.

use std::path::PathBuf;

use anyhow::Context;
use evtac_import::filtering;
use evtac_import::sensor_stats::{SensorStats, fit};

/// Arguments of `evtac stats`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The recording (any format evtac reads that states the sensor's size): a session, a
    /// no-contact recording or a trial; it needs stretches at rest.
    pub recording: PathBuf,
    /// Write the measured fields into a simulator parameter file (JSON, every other field the
    /// default) for `evtac simulate --params`.
    #[arg(long, value_name = "FILE")]
    pub sim_params: Option<PathBuf>,
    /// Write the event rate over time (one row per 50 ms bin) as CSV.
    #[arg(long, value_name = "FILE.csv")]
    pub rates: Option<PathBuf>,
    /// Write the hot pixels as a mask: a uint8 rows x columns NPY array, 255 at each hot pixel
    /// and 0 elsewhere, which `--filter hot-pixels=FILE` removes from any recording of this
    /// sensor.
    #[arg(long, value_name = "MASK.npy")]
    pub hot_pixels: Option<PathBuf>,
    /// Print the statistics as one JSON object instead of text (without the bins).
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub streams: crate::streams::StreamArgs,
    // The recording's events go through these filters before they are measured (the IMU as
    // it is): what a capture that filters them would show.
    #[command(flatten)]
    pub filter: crate::filtering::FilterArgs,
}

/// Runs `evtac stats`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let len = std::fs::metadata(&args.recording)
        .with_context(|| args.recording.display().to_string())?
        .len();
    for output in [&args.sim_params, &args.rates, &args.hot_pixels]
        .into_iter()
        .flatten()
    {
        evtac_events::output::refuse_input(output, &[&args.recording])?;
    }
    let bar = crate::progress::bytes(2 * len, "measuring");
    let selection = args.streams.selection();
    let stats = filtering::measure(&args.recording, &selection, &args.filter.filters, |bytes| {
        bar.set_position(bytes)
    })?;
    bar.finish_and_clear();
    if let Some(path) = &args.rates {
        crate::outputs::write_text(path, &stats.rates_csv())?;
    }
    if args.json {
        let mut shown = stats.clone();
        shown.bins.clear();
        println!("{}", serde_json::to_string_pretty(&shown)?);
    } else {
        print!("{}", render(&stats));
    }
    anyhow::ensure!(
        stats.rest_s > 0.0,
        "{}: no stretch at rest (no 150 ms without motion), so nothing to measure the noise on",
        args.recording.display()
    );
    if let Some(path) = &args.hot_pixels {
        let (w, h) = (stats.resolution.width, stats.resolution.height);
        let mut mask = ndarray::Array2::<u8>::zeros((usize::from(h), usize::from(w)));
        for p in &stats.hot {
            mask[[usize::from(p.y), usize::from(p.x)]] = 255;
        }
        crate::outputs::write_npy(path, &mask)?;
        println!(
            "\nwrote {} ({} hot pixels of {w}x{h})",
            path.display(),
            stats.hot.len()
        );
    }
    if let Some(path) = &args.sim_params {
        let fitted = fit::fit(&stats, evtac_sim::SimParams::default());
        let text = serde_json::to_string_pretty(&fitted.params)?;
        crate::outputs::write_text(path, &(text + "\n"))?;
        println!("\nwrote {} with these fields measured:", path.display());
        for m in &fitted.measured {
            println!("  {:<24} {:>14}  from {}", m.field, m.value, m.from);
        }
        println!("every other field is the simulator's default (docs/simulator.md)");
    }
    Ok(())
}

/// The human-readable statistics.
fn render(s: &SensorStats) -> String {
    let percent = |a: u64, b: u64| 100.0 * a as f64 / b.max(1) as f64;
    let mut out = format!(
        "recording:    {}\nsensor:       {}x{}\nevents:       {} over {:.3} s ({:.0} ev/s, {:.1}% ON)\n",
        s.path.display(),
        s.resolution.width,
        s.resolution.height,
        s.events,
        s.duration_s,
        s.events as f64 / s.duration_s.max(1e-6),
        percent(s.on_events, s.events)
    );
    let mut rates: Vec<u64> = s.bins.iter().map(|b| b.events).collect();
    rates.sort_unstable();
    if let (Some(lo), Some(hi)) = (rates.first(), rates.last()) {
        // Per 50 ms bin, shown per second.
        out += &format!(
            "event rate:   {} .. {} (median {}) ev/s per 50 ms bin (--rates writes them all)\n",
            lo * 20,
            hi * 20,
            rates[rates.len() / 2] * 20
        );
    }
    out += &format!(
        "at rest:      {:.2} s of {:.2} s (bins of at most {} events)\n",
        s.rest_s,
        s.duration_s,
        s.rest_limit.map_or_else(|| "-".into(), |l| l.to_string())
    );
    if let Some(bg) = &s.background {
        out += &format!(
            "background:   {:.5} Hz per pixel ({:.5} ON, {:.5} OFF; ON fraction {}) over {} pixels\n",
            bg.rate_hz(),
            bg.on_rate_hz,
            bg.off_rate_hz,
            bg.on_fraction()
                .map_or_else(|| "-".into(), |f| format!("{f:.3}")),
            bg.pixels
        );
        out += &format!(
            "hot pixels:   {} (at least {} events at rest)",
            s.hot.len(),
            bg.hot_threshold
        );
        let shown: Vec<String> = s
            .hot
            .iter()
            .take(8)
            .map(|h| format!("({}, {}) {:.1} Hz", h.x, h.y, h.rate_hz))
            .collect();
        if !shown.is_empty() {
            let more = if s.hot.len() > shown.len() {
                ", ..."
            } else {
                ""
            };
            out += &format!(": {}{more}", shown.join(", "));
        }
        out += "\n";
    }
    match &s.imu {
        Some(imu) => {
            let [x, y, z] = imu.gyro_mean_deg_s;
            out += &format!(
                "IMU:          {} samples at {:.2} Hz, {} at rest\n\
                 gyroscope:    noise {:.4} deg/s, bias {:.4} deg/s RMS (mean {x:.4}, {y:.4}, \
                 {z:.4}), step {}\n\
                 accelerometer: noise {:.5} g, step {}\ntemperature:  {}\n",
                imu.samples,
                imu.rate_hz,
                imu.rest_samples,
                imu.gyro_noise_deg_s,
                imu.gyro_bias_deg_s,
                imu.gyro_lsb_deg_s
                    .map_or_else(|| "-".into(), |l| format!("{l:.6} deg/s")),
                imu.accel_noise_g,
                imu.accel_lsb_g
                    .map_or_else(|| "-".into(), |l| format!("{l:.7} g")),
                imu.temperature_c
                    .map_or_else(|| "not in the file".into(), |t| format!("{t:.1} C"))
            );
        }
        None => out += "IMU:          no samples at rest\n",
    }
    out
}
