//! `evtac render`: what the sensor and the network see, as an animated GIF or a PNG contact
//! sheet (`evtac_experiments::render` draws and encodes).
//!
//! The input is a recording in any format evtac reads, or with `--trial` a dataset folder and
//! one of its trials (its no-contact mask applied to the static representation, as in
//! training). Events are cropped to the centered 240x240 crop. The representations use the
//! default settings unless `--tau-ms` / `--window-ms` say otherwise.

use anyhow::Context;
use evtac_experiments::dataset::{self, Dataset};
use evtac_experiments::render::{self, Output, Panel, Timing};
use evtac_repr::{DynamicConfig, Mask, ReprConfig, StaticConfig};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `evtac render`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A recording (AEDAT4, EVT2/EVT3 raw, CSV or NPY), or with `--trial` a dataset folder.
    pub input: PathBuf,
    /// Output file: `.gif` (animated) or `.png` (contact sheet of every frame).
    #[arg(long)]
    pub out: PathBuf,
    /// Render this trial of the dataset INPUT.
    #[arg(long)]
    pub trial: Option<String>,
    /// Start of the range, in the recording's microseconds [default: the first event].
    #[arg(long, allow_hyphen_values = true)]
    pub from_us: Option<i64>,
    /// End of the range, in the recording's microseconds [default: the last event].
    #[arg(long, allow_hyphen_values = true)]
    pub to_us: Option<i64>,
    /// Frames per second of the output; each frame covers speed / fps seconds of recording.
    #[arg(long, default_value_t = 30.0)]
    pub fps: f64,
    /// Playback speed: recording seconds per second of output (0.1 = ten times slower).
    #[arg(long, default_value_t = 1.0)]
    pub speed: f64,
    /// Panels, comma-separated: events, static, dynamic, combined, features (the pooled
    /// features of each frame panel, in a second row).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "events,static,dynamic,combined"
    )]
    pub panels: Vec<String>,
    /// Static representation: decay time constant in milliseconds [default: 1000].
    #[arg(long)]
    pub tau_ms: Option<f64>,
    /// Dynamic representation: window length in milliseconds [default: 640].
    #[arg(long)]
    pub window_ms: Option<f64>,
    #[command(flatten)]
    pub inputs: crate::inputs::InputArgs,
}

/// Runs `evtac render`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let output = Output::from_path(&args.out)?;
    let panels = args
        .panels
        .iter()
        .map(|p| Panel::parse(p))
        .collect::<Result<Vec<_>, _>>()?;
    let mut static_cfg = StaticConfig::default();
    if let Some(tau) = args.tau_ms {
        static_cfg.tau_ms = tau;
    }
    let mut dynamic_cfg = DynamicConfig::default();
    if let Some(window) = args.window_ms {
        dynamic_cfg.window_ms = window;
    }
    let reprs = evtac_experiments::exp1::representations(
        ReprConfig::Static(static_cfg),
        ReprConfig::Dynamic(dynamic_cfg),
    );
    for (_, c) in &reprs {
        c.validate()?;
    }

    let (events, masks): (_, Vec<Option<Mask>>) = match &args.trial {
        None => {
            let events = dataset::read_cropped(&args.input)
                .with_context(|| format!("reading {}", args.input.display()))?;
            (events, vec![None; reprs.len()])
        }
        Some(trial) => {
            let ds = Dataset::open(&args.input, args.inputs.inputs())
                .with_context(|| format!("opening the dataset {}", args.input.display()))?;
            let meta = ds.trial(trial)?;
            let events = ds.events(meta)?;
            let no_contact = ds.no_contact_events()?;
            let masks = reprs
                .iter()
                .map(|(_, c)| ds.mask_for(c, no_contact.as_deref()))
                .collect::<Result<_, _>>()?;
            (events, masks)
        }
    };
    let mask_refs: Vec<Option<&Mask>> = masks.iter().map(Option::as_ref).collect();
    let timing = Timing::new(&events, args.from_us, args.to_us, args.fps, args.speed)
        .with_context(|| format!("rendering {}", args.input.display()))?;

    let started = Instant::now();
    render::render(
        &args.out, output, &events, &reprs, &mask_refs, &panels, &timing,
    )?;
    let took = started.elapsed().as_secs_f64();
    let span = timing.count as f64 * timing.step_us as f64 / 1e6;
    eprintln!(
        "wrote {} frames ({span:.2} s of recording) to {} in {took:.2} s ({:.1}x real time)",
        timing.count,
        args.out.display(),
        span / took.max(1e-9)
    );
    Ok(())
}
