//! `evtac render`: what the sensor and the network see, as an animated GIF, an MP4 video
//! (through an `ffmpeg` on the `PATH`) or a PNG contact sheet (`evtac_report::render`
//! draws and encodes).
//!
//! The input is a recording in any format evtac reads, or with `--trial` a dataset folder and
//! one of its trials (its no-contact mask applied to the static representation, as in
//! training). Events go through `--filter`'s filters on the full sensor, then are cropped to the
//! centered 240x240 crop. Each representation setting is
//! `--tau-ms` / `--window-ms` when given, else the `--model`'s (what the network was trained
//! on), else the default. With `--model`, the angles panel shows the model's estimates (the
//! offline prediction's, on the model's own representation and mask) beside the trial's IMU
//! labels and, for simulated data, the truth. The real-valued kinds' panels (`time-surface`,
//! `histogram`, `voxel-grid`) draw the `--model`'s settings when it is of that kind (its panel is
//! then added), else the kind's defaults.

use anyhow::Context;
use evtac_experiments::dataset::{self, Dataset};
use evtac_labels::series::LabelSeries;
use evtac_learn::Model;
use evtac_report::render::{self, Angles, Output, Panel, SHEET_DEFAULT_FRAMES, Scene, Timing};
use evtac_repr::{Mask, ReprConfig};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `evtac render`.
#[derive(Debug, clap::Args)]
pub struct Args {
    // The help is built from the one phrase of readable formats (see `crate::formats`).
    #[arg(help = concat!(
        "A recording (",
        crate::formats::readable_formats!(),
        "), or with `--trial` a dataset folder"
    ))]
    pub input: PathBuf,
    /// Output file: `.gif` (animated), `.mp4` (H.264 video; needs `ffmpeg` on the PATH) or
    /// `.png` (contact sheet of every frame). Written beside and renamed at the end.
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
    /// Frames per second of the output; each frame covers speed / fps seconds of recording
    /// [default: 30; a PNG contact sheet without --fps and --speed shows 24 frames spread over
    /// the range].
    #[arg(long)]
    pub fps: Option<f64>,
    /// Playback speed: recording seconds per second of output (0.1 = ten times slower)
    /// [default: 1].
    #[arg(long)]
    pub speed: Option<f64>,
    /// Panels, comma-separated: events, static, dynamic, combined, time-surface, histogram,
    /// voxel-grid (ON red, OFF blue), features (the pooled features of each frame panel, in a
    /// second row), angles (the model's estimates over time; added whenever --model is given).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "events,static,dynamic,combined"
    )]
    pub panels: Vec<String>,
    /// Static representation: decay time constant in milliseconds [default: the --model's when
    /// it has a static part, else 1000].
    #[arg(long)]
    pub tau_ms: Option<f64>,
    /// Dynamic representation: window length in milliseconds [default: the --model's when it
    /// has a dynamic part, else 640].
    #[arg(long)]
    pub window_ms: Option<f64>,
    /// A model bundle written by `evtac train`: adds the angles panel (its pitch and roll
    /// estimates over the rendered span, every frame interval divided into steps of at most
    /// 10 ms; the trial's IMU labels and simulated truth beside them), and its representation
    /// settings become the frames' defaults.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// With --model: also write the estimates as CSV (t_us,pitch_deg,roll_deg).
    #[arg(long, requires = "model")]
    pub estimates_csv: Option<PathBuf>,
    #[command(flatten)]
    pub inputs: crate::inputs::InputArgs,
}

/// Runs `evtac render`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let output = Output::from_path(&args.out)?;
    let mut panels = args
        .panels
        .iter()
        .map(|p| Panel::parse(p))
        .collect::<Result<Vec<_>, _>>()?;
    let model = match &args.model {
        Some(dir) => Some(
            Model::load(dir)
                .with_context(|| format!("loading the model bundle {}", dir.display()))?,
        ),
        None => None,
    };
    let model_cfg = model.as_ref().map(Model::repr_config);
    // A model of a real-valued kind shows its own frame.
    if let Some(panel) = model_cfg
        .filter(|c| c.dense_part().is_some())
        .and_then(|c| Panel::of_kind(c.kind()))
        && !panels.contains(&panel)
    {
        panels.push(panel);
    }
    if model.is_some() && !panels.contains(&Panel::Angles) {
        panels.push(Panel::Angles);
    }
    let mut static_cfg = model_cfg
        .and_then(|c| c.static_part().copied())
        .unwrap_or_default();
    if let Some(tau) = args.tau_ms {
        static_cfg.tau_ms = tau;
    }
    let mut dynamic_cfg = model_cfg
        .and_then(|c| c.dynamic_part().copied())
        .unwrap_or_default();
    if let Some(window) = args.window_ms {
        dynamic_cfg.window_ms = window;
    }
    let mut reprs = evtac_experiments::exp1::paper_representations(
        ReprConfig::Static(static_cfg),
        ReprConfig::Dynamic(dynamic_cfg),
    );
    for kind in panels.iter().filter_map(|p| p.repr_kind()) {
        if kind.is_dense() {
            reprs.push(match model_cfg {
                Some(c) if c.kind() == kind => c,
                _ => kind.config(Default::default(), Default::default()),
            });
        }
    }
    for c in &reprs {
        c.validate()?;
    }
    // The model's mask for every frame with its static settings (the mask is built from
    // those alone), so a frame like the model's shows what the network saw.
    let model_mask = |c: &ReprConfig| -> Option<Mask> {
        let m = model.as_ref()?;
        let same = c.static_part().is_some() && c.static_part() == m.repr_config().static_part();
        if same { m.mask().cloned() } else { None }
    };

    let mut references: (Option<LabelSeries>, Option<LabelSeries>) = (None, None);
    let (events, masks): (_, Vec<Option<Mask>>) = match &args.trial {
        None => {
            // Filtered on the full sensor, before the crop, as a dataset's recordings are.
            let events = dataset::read_filtered_cropped(&args.input, &args.inputs.filter.filters)
                .with_context(|| format!("reading {}", args.input.display()))?;
            let masks = reprs.iter().map(model_mask).collect();
            (events, masks)
        }
        Some(trial) => {
            let ds = Dataset::open(&args.input, args.inputs.inputs())
                .with_context(|| format!("opening the dataset {}", args.input.display()))?;
            let meta = ds.trial(trial)?;
            let events = ds.events(meta)?;
            let no_contact = ds.no_contact()?;
            let masks = reprs
                .iter()
                .map(|c| match model_mask(c) {
                    Some(m) => Ok(Some(m)),
                    None => ds.mask_for(c, no_contact.as_ref()),
                })
                .collect::<Result<_, _>>()?;
            if model.is_some() {
                let truth = match &meta.truth {
                    Some(file) => {
                        let path = ds.dir.join(file);
                        Some(
                            LabelSeries::read_csv(&path)
                                .with_context(|| format!("reading {}", path.display()))?,
                        )
                    }
                    None => None,
                };
                references = (Some(ds.labels(meta)?), truth);
            }
            (events, masks)
        }
    };
    let mask_refs: Vec<Option<&Mask>> = masks.iter().map(Option::as_ref).collect();
    let timing = match (output, args.fps, args.speed) {
        (Output::Png, None, None) => {
            Timing::spread(&events, args.from_us, args.to_us, SHEET_DEFAULT_FRAMES)
        }
        (_, fps, speed) => Timing::new(
            &events,
            args.from_us,
            args.to_us,
            fps.unwrap_or(30.0),
            speed.unwrap_or(1.0),
        ),
    }
    .with_context(|| format!("rendering {}", args.input.display()))?;

    let started = Instant::now();
    let angles = match &model {
        Some(m) => {
            let mut angles = Angles::estimate(&events, m, &timing)?;
            let (labels, truth) = &references;
            angles.labels = labels.as_ref().map(|s| angles.sample(s));
            angles.truth = truth.as_ref().map(|s| angles.sample(s));
            if let Some(path) = &args.estimates_csv {
                crate::outputs::write_text(path, &angles.estimates_csv())?;
            }
            Some(angles)
        }
        None => None,
    };
    let scene = Scene::new(&panels, timing, angles.as_ref())?;
    render::render(&args.out, output, &events, &reprs, &mask_refs, scene)?;
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
