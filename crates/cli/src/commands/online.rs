//! `evtac online`: a trained model on a live or replayed event stream, one estimate per
//! interval of event time, with latency figures.
//!
//! A recording replayed as fast as possible is read far ahead of the estimator, so its latency
//! would be mostly time spent queueing; its summary reports the processing time per estimate
//! instead and says that latency needs `--realtime`.
//!
//! With `--input ros2:///TOPIC` the events come from a ROS 2 camera driver's topic over DDS
//! (`evtac_online::input::Ros2Source`).
//!
//! With `--ros2 TOPIC` every estimate is also published on ROS 2 (`evtac_online::ros2`), without
//! holding the estimation up; the CSV output goes on alongside. With `--mcap FILE` the same
//! messages are logged to an MCAP file (`evtac_online::mcap_log`) that Foxglove and `rosbags`
//! open.

use anyhow::Context;
use evtac_events::output::{OutputFile, refuse_input};
use evtac_formats::ros::EventMessage;
use evtac_learn::Model;
use evtac_online::input::{self, NetworkOptions, OpenOptions, Ros2InputOptions, SourceSpec};
use evtac_online::mcap_log::{self, McapLog};
use evtac_online::pipeline::{self, Output, PipelineConfig};
use evtac_online::ros2::{self, Ros2Options, Ros2Publisher};
use evtac_online::{Backoff, Estimator, Summary};
use std::io::Write;
use std::net::IpAddr;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Arguments of `evtac online`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Model bundle folder (from `evtac train`): weights, representation settings, mask.
    #[arg(long)]
    pub model: PathBuf,
    // The help is built from the one phrase of readable formats (see `crate::formats`).
    #[arg(long, help = concat!(
        "Event source: a recording (any format evtac reads: ", crate::formats::readable_formats!(),
        "), a live DV network stream `tcp://HOST:PORT`, a ROS 2 topic `ros2:///TOPIC` \
         (event_camera_msgs/msg/EventPacket or dvs_msgs/msg/EventArray, over DDS, no ROS \
         installation needed; see docs/online.md), or `-` for standard input (AEDAT4 or CSV)"
    ))]
    pub input: String,
    /// Interval between estimates, in milliseconds of event time.
    #[arg(long, default_value_t = 1.0)]
    pub interval_ms: f64,
    /// Replay a recording at its recorded pace instead of as fast as possible.
    #[arg(long)]
    pub realtime: bool,
    /// Length of the slices a `--realtime` replay releases at once, in microseconds.
    #[arg(long, default_value_t = 1000)]
    pub slice_us: i64,
    /// CSV file for the estimates (`t_us,pitch_deg,roll_deg,latency_us`); standard output when
    /// absent.
    #[arg(long)]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub sensor: crate::sensor::SensorArgs,
    #[command(flatten)]
    pub streams: crate::streams::StreamArgs,
    /// Chunks the queue between ingestion and estimation holds.
    #[arg(long, default_value_t = PipelineConfig::default().queue_chunks)]
    pub queue_chunks: usize,
    /// Drop incoming chunks while the estimator is behind instead of waiting (counted in the
    /// summary).
    #[arg(long)]
    pub drop_when_behind: bool,
    /// Keep the estimation thread spinning on the queue instead of sleeping between chunks: it
    /// occupies a core, and estimates no longer wait for the thread to wake (lower latency
    /// tails, see docs/online.md).
    #[arg(long)]
    pub busy_poll: bool,
    /// Reconnection attempts in a row for a network input before the run ends (for a ROS 2
    /// input: waits for a silent topic, each as long as the reconnection delay).
    #[arg(long, default_value_t = Backoff::default().attempts)]
    pub reconnect_attempts: u32,
    /// First reconnection delay in milliseconds (doubling up to `--reconnect-max-ms`).
    #[arg(long, default_value_t = Backoff::default().initial.as_millis() as u64)]
    pub reconnect_initial_ms: u64,
    /// Longest reconnection delay in milliseconds.
    #[arg(long, default_value_t = Backoff::default().max.as_millis() as u64)]
    pub reconnect_max_ms: u64,
    /// Seconds without data after which a network stream counts as stalled and is reopened (a
    /// ROS 2 input: reported lost and waited for).
    #[arg(long, default_value_t = NetworkOptions::default().stall_timeout.as_secs_f64())]
    pub stall_timeout_s: f64,
    /// Seconds to wait for a network input's connection, or for a ROS 2 input's publisher and
    /// first sample, before the reconnection attempts begin.
    #[arg(long, default_value_t = NetworkOptions::default().connect_timeout.as_secs_f64())]
    pub connect_timeout_s: f64,
    /// Stop after this many seconds of wall-clock time (checked at each estimate).
    #[arg(long)]
    pub max_duration_s: Option<f64>,
    /// Also publish every estimate on this ROS 2 topic (e.g. `/contact_angle`) as
    /// `geometry_msgs/msg/Vector3Stamped`: x = pitch, y = roll in radians, stamped with the
    /// estimate's event time (see docs/online.md). Needs no ROS installation.
    #[arg(long, value_name = "TOPIC")]
    pub ros2: Option<String>,
    /// `header.frame_id` of the ROS 2 messages and of the MCAP log's (default `neurotac`).
    #[arg(long)]
    pub frame_id: Option<String>,
    /// ROS 2 (DDS) domain id, 0 to 232, of `--ros2` and of a `ros2://` input; `ROS_DOMAIN_ID`
    /// when absent, else 0.
    #[arg(long)]
    pub ros_domain: Option<u16>,
    /// Use only the network interface with this address for ROS 2 discovery and data (e.g.
    /// `127.0.0.1` to stay on this host), for `--ros2` and a `ros2://` input; repeat for
    /// several. Every interface when absent.
    #[arg(long, value_name = "ADDR")]
    pub ros_interface: Vec<IpAddr>,
    /// The message type of a `ros2://` input, `event_camera_msgs/msg/EventPacket` or
    /// `dvs_msgs/msg/EventArray`, instead of the type its publisher is discovered with (the
    /// reader is then best effort; see docs/online.md).
    #[arg(long, value_name = "TYPE", value_parser = parse_event_message)]
    pub ros_event_type: Option<EventMessage>,
    /// Before reading the input, wait until this many ROS 2 subscribers are matched (so that
    /// none misses the first estimates), for at most `--ros2-wait-timeout-s`.
    #[arg(long, value_name = "COUNT", requires = "ros2")]
    pub ros2_wait_subscribers: Option<usize>,
    /// Longest wait for `--ros2-wait-subscribers`; the run fails when they are not there by then.
    #[arg(long, default_value_t = 30.0, requires = "ros2_wait_subscribers")]
    pub ros2_wait_timeout_s: f64,
    /// Also log every estimate to this MCAP file, as the `--ros2` messages
    /// (`geometry_msgs/msg/Vector3Stamped`, CDR) on the `--ros2` topic or `/contact_angle`,
    /// logged at the estimate's event time; Foxglove and rosbags open it (see docs/online.md).
    /// Replaying a dataset's trial, the log also holds the trial's labels and truth at each
    /// estimate's time, on `<topic>/label` and `<topic>/truth`.
    #[arg(long, value_name = "FILE")]
    pub mcap: Option<PathBuf>,
    /// Also log the representation's binary frames to the --mcap file, HZ times per second of
    /// event time (at the estimate times), as `sensor_msgs/msg/Image` (mono8, 0 and 255) on
    /// `<topic>/frames/static`, `/dynamic` and `/combined`: the parts the model's
    /// representation has. E.g. 30 for a video-like log.
    #[arg(long, value_name = "HZ", requires = "mcap")]
    pub mcap_frames: Option<f64>,
    // Every event goes through these on the full sensor before the crop; they must be the
    // filters the model's training recordings went through (the bundle records them), or the
    // run is refused. `hot-pixels=auto` learns from a replayed recording; a live input has
    // nothing to learn from beforehand.
    #[command(flatten)]
    pub filter: crate::filtering::FilterArgs,
}

impl Args {
    /// `--frame-id`, or `neurotac`.
    fn frame_id(&self) -> &str {
        self.frame_id.as_deref().unwrap_or("neurotac")
    }
}

/// `--ros-event-type`: a ROS 2 event message type in any spelling.
fn parse_event_message(s: &str) -> Result<EventMessage, String> {
    EventMessage::of(s).ok_or_else(|| {
        format!(
            "`{s}` is not an event message type evtac reads ({} or {})",
            EventMessage::EventPacket,
            EventMessage::EventArray
        )
    })
}

/// The ROS 2 domain: `--ros-domain`, else `ROS_DOMAIN_ID`, else 0.
fn ros_domain(args: &Args) -> anyhow::Result<u16> {
    Ok(match args.ros_domain {
        Some(domain) => domain,
        None => ros2::domain_from_env()?.unwrap_or(0),
    })
}

fn seconds(what: &str, s: f64) -> anyhow::Result<Duration> {
    Duration::try_from_secs_f64(s)
        .ok()
        .filter(|d| !d.is_zero())
        .with_context(|| format!("{what} must be a positive number of seconds (got {s})"))
}

/// A flag that the first Ctrl-C (or SIGTERM) sets, so that the run ends with its summary; a
/// second one ends the process at once.
fn stop_on_interrupt() -> anyhow::Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::Relaxed) {
            // 128 + SIGINT, as a shell reports a process ended by Ctrl-C.
            std::process::exit(130);
        }
        eprintln!("evtac online: stopping (press Ctrl-C again to quit at once)");
    })
    .context("installing the Ctrl-C handler")?;
    Ok(stop)
}

/// The ROS 2 publisher of `--ros2 TOPIC`, once its subscribers are there when asked to wait.
fn ros2_publisher(
    args: &Args,
    topic: &str,
    say: &dyn Fn(&dyn std::fmt::Display),
) -> anyhow::Result<Ros2Publisher> {
    let domain = ros_domain(args)?;
    let publisher = Ros2Publisher::new(Ros2Options {
        topic: topic.to_owned(),
        frame_id: args.frame_id().to_owned(),
        domain,
        interfaces: args.ros_interface.clone(),
    })?;
    say(&format_args!(
        "publishing on ROS 2 topic {topic} (DDS topic {}, domain {domain})",
        publisher.dds_topic()
    ));
    if let Some(count) = args.ros2_wait_subscribers {
        let timeout = seconds("--ros2-wait-timeout-s", args.ros2_wait_timeout_s)?;
        say(&format_args!("waiting for {count} ROS 2 subscriber(s)"));
        if !publisher.wait_for_subscribers(count, timeout) {
            anyhow::bail!(
                "{} of {count} ROS 2 subscriber(s) matched on {topic} in domain {domain} within \
                 {:.1} s (same domain? discovery reaches them? see docs/online.md, ROS 2)",
                publisher.subscribers(),
                timeout.as_secs_f64()
            );
        }
    }
    Ok(publisher)
}

/// Runs `evtac online`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let interval_us = (args.interval_ms * 1000.0).round();
    if !(1.0..=3.6e9).contains(&interval_us) {
        anyhow::bail!(
            "--interval-ms must be from 0.001 to 3600000 (got {})",
            args.interval_ms
        );
    }
    let interval_us = interval_us as i64;
    let spec: SourceSpec = args.input.parse()?;
    let ros2_input = matches!(spec, SourceSpec::Ros2 { .. });
    if (args.ros_domain.is_some() || !args.ros_interface.is_empty())
        && args.ros2.is_none()
        && !ros2_input
    {
        anyhow::bail!(
            "--ros-domain and --ros-interface are for --ros2 and ros2:// inputs: give either"
        );
    }
    if args.ros_event_type.is_some() && !ros2_input {
        anyhow::bail!("--ros-event-type is the message type of a ros2:// input: give one");
    }
    // A file without --realtime is the one source that runs ahead of the estimator; live
    // streams (network, standard input) come at their own pace.
    let paced = args.realtime || !matches!(spec, SourceSpec::File(_));
    let model = Model::load(&args.model)?;
    let options = OpenOptions {
        realtime: args.realtime,
        slice_us: args.slice_us,
        sensor: args.sensor.sensor,
        network: NetworkOptions {
            backoff: Backoff {
                initial: Duration::from_millis(args.reconnect_initial_ms),
                max: Duration::from_millis(args.reconnect_max_ms.max(args.reconnect_initial_ms)),
                attempts: args.reconnect_attempts,
            },
            stall_timeout: seconds("--stall-timeout-s", args.stall_timeout_s)?,
            connect_timeout: seconds("--connect-timeout-s", args.connect_timeout_s)?,
        },
        streams: args.streams.selection(),
        ros2: Ros2InputOptions {
            domain: if ros2_input { ros_domain(&args)? } else { 0 },
            interfaces: args.ros_interface.clone(),
            message: args.ros_event_type,
        },
    };
    let max_duration = args
        .max_duration_s
        .map(|s| seconds("--max-duration-s", s))
        .transpose()?;
    if args.frame_id.is_some() && args.ros2.is_none() && args.mcap.is_none() {
        anyhow::bail!(
            "--frame-id names the frame of the --ros2 messages and the --mcap log: give either"
        );
    }
    if let (Some(mcap), Some(output)) = (&args.mcap, &args.output)
        && mcap == output
    {
        anyhow::bail!(
            "--mcap and --output are both {}: give the log and the CSV different names",
            mcap.display()
        );
    }
    let say = |what: &dyn std::fmt::Display| eprintln!("evtac online: {what}");
    // Before the input opens: a live stream does not wait while subscribers are awaited.
    let publisher = match &args.ros2 {
        Some(topic) => Some(ros2_publisher(&args, topic, &say)?),
        None => None,
    };
    // Every input error names the input (`reading X: ...`, `could not connect to X: ...`).
    let opened = input::open(&spec, &options, &mut |n| say(&n))?;
    let sensor = opened.resolution.with_context(|| {
        format!("{spec} does not state the sensor size: give it with --sensor WIDTHxHEIGHT")
    })?;
    let mut estimator = Estimator::for_model(&model, sensor, interval_us)
        .with_context(|| format!("setting up the estimator for {}", args.model.display()))?;
    let trained = &model.representation().filters;
    let given: Vec<String> = args.filter.filters.iter().map(|f| f.to_string()).collect();
    if &given != trained {
        let words = |specs: &[String]| match specs {
            [] => "no filter".to_string(),
            _ => specs.join(" "),
        };
        let flags: Vec<String> = trained.iter().map(|f| format!("--filter {f}")).collect();
        anyhow::bail!(
            "the model {} was trained on events through {}, and this run's go through {}: {}",
            args.model.display(),
            words(trained),
            words(&given),
            match flags.is_empty() {
                true => "give no --filter".to_string(),
                false => format!("give its filters ({})", flags.join(" ")),
            }
        );
    }
    if !args.filter.filters.is_empty() {
        let chain = match &spec {
            SourceSpec::File(path) => args.filter.chain(path, &args.streams.selection(), sensor)?,
            live => evtac_filters::Chain::build(&args.filter.filters, sensor)
                .with_context(|| format!("{live}: the {sensor} sensor"))?,
        };
        estimator.filter_with(chain);
    }
    if let Some(hz) = args.mcap_frames {
        if !(hz.is_finite() && hz > 0.0 && hz <= 1e6) {
            anyhow::bail!("--mcap-frames {hz}: give frames per second, above 0 and at most 1e6");
        }
        estimator.capture_frames((1e6 / hz).round() as i64)?;
    }

    let to_stdout = args.output.is_none();
    // The file appears when the run ends without error (Ctrl-C included): a run that fails
    // leaves no estimates file that looks complete.
    let mut file = match &args.output {
        Some(path) => {
            if let SourceSpec::File(input) = &spec {
                refuse_input(path, &[input])?;
            }
            Some(
                OutputFile::buffered(path)
                    .with_context(|| format!("creating {}", path.display()))?,
            )
        }
        None => None,
    };
    // Like the CSV file, the log appears when the run ends without error.
    let mut log = match &args.mcap {
        Some(path) => {
            let inputs = match &spec {
                SourceSpec::File(input) => vec![input.clone()],
                _ => Vec::new(),
            };
            let topic = args.ros2.as_deref().unwrap_or(mcap_log::DEFAULT_TOPIC);
            let mut log = McapLog::create(path, &inputs, topic, args.frame_id())?;
            // A replayed dataset trial: its labels and truth beside the estimates.
            for input in &inputs {
                for (name, reference) in crate::trial_references::references(input) {
                    log.add_reference(name, reference)?;
                    say(&format_args!(
                        "logging the trial's {name} on {}/{name}",
                        topic.trim_end_matches('/')
                    ));
                }
            }
            Some(log)
        }
        None => None,
    };
    let mut log_error = None;
    let mut stdout = None;
    let out: &mut dyn Write = match &mut file {
        Some(f) => f,
        None => stdout.insert(std::io::BufWriter::new(std::io::stdout().lock())),
    };
    // Where the estimates go, for the errors of writing them.
    let destination = args.output.as_ref().map_or_else(
        || "standard output".to_string(),
        |p| p.display().to_string(),
    );
    writeln!(out, "t_us,pitch_deg,roll_deg,latency_us")
        .with_context(|| format!("writing the estimates to {destination}"))?;
    let stop = stop_on_interrupt()?;
    let started = Instant::now();
    let mut write_error = None;
    let result = pipeline::run_until(
        opened.source,
        estimator,
        &PipelineConfig {
            queue_chunks: args.queue_chunks,
            drop_when_behind: args.drop_when_behind,
            busy_poll: args.busy_poll,
        },
        &stop,
        |output| {
            match output {
                Output::Estimate(e) => {
                    // First: the write only hands the message to the DDS writer, never waiting.
                    if let Some(publisher) = &publisher {
                        publisher.publish(&e);
                    }
                    if let Some(log) = &mut log
                        && let Err(e) = log.write(&e)
                    {
                        log_error = Some(e);
                        return ControlFlow::Break(());
                    }
                    let written = writeln!(
                        out,
                        "{},{},{},{:.3}",
                        e.t_us,
                        e.pitch_deg,
                        e.roll_deg,
                        e.latency.as_secs_f64() * 1e6
                    )
                    // A live consumer reading standard output wants each row as it happens.
                    .and_then(|()| if to_stdout { out.flush() } else { Ok(()) });
                    if let Err(e) = written {
                        write_error = Some(e);
                        return ControlFlow::Break(());
                    }
                }
                Output::Frames(frames) => {
                    if let Some(log) = &mut log
                        && let Err(e) = log.write_frames(&frames)
                    {
                        log_error = Some(e);
                        return ControlFlow::Break(());
                    }
                }
                Output::Notice(n) => say(&n),
            }
            if max_duration.is_some_and(|d| started.elapsed() >= d) {
                return ControlFlow::Break(());
            }
            ControlFlow::Continue(())
        },
    );
    let flushed = out.flush();
    let ros2 = publisher.map(Ros2Publisher::finish);
    let ros2_input = opened
        .ros2_input
        .as_ref()
        .map(input::Ros2InputReport::stats);
    let with_pace = |mut summary: Summary| {
        summary.paced = paced;
        summary.ros2 = ros2;
        summary.ros2_input = ros2_input;
        summary
    };
    let summary = match result {
        Ok(summary) => with_pace(summary),
        Err(pipeline::Error::Input { source, summary }) => {
            eprintln!("{}", with_pace(*summary));
            return Err(source).with_context(|| format!("reading {spec}"));
        }
        Err(pipeline::Error::Estimator { source, summary }) => {
            eprintln!("{}", with_pace(*summary));
            return Err(source).context("estimating");
        }
        Err(e) => return Err(e.into()),
    };
    eprintln!("{summary}");
    if let Some(e) = write_error {
        return Err(e).with_context(|| format!("writing the estimates to {destination}"));
    }
    flushed.with_context(|| format!("writing the estimates to {destination}"))?;
    if let Some(e) = log_error {
        return Err(e.into());
    }
    if let Some(log) = log {
        let written = log.written();
        let frame_sets = log.frame_sets_written();
        log.finish()?;
        if let Some(path) = &args.mcap {
            let frames = if args.mcap_frames.is_some() {
                format!(" and {frame_sets} frame set(s)")
            } else {
                String::new()
            };
            say(&format_args!(
                "logged {written} estimate(s){frames} to {}",
                path.display()
            ));
        }
    }
    if let (Some(file), Some(path)) = (file, &args.output) {
        OutputFile::commit_buffered(file).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}
