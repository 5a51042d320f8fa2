//! `evtac represent`: static, dynamic, combined, stacked or late binary frames, potentials or
//! pooled features of a recording at the sample times listed in a text file, written as NPY; or
//! the real-valued frames and pooled features of a time surface, histogram or voxel grid.
//!
//! Events are cropped to the ROI (default: the centered 240x240 crop of the paper) and fed once,
//! in time order, to `evtac_repr::FeatureExtractor`. `--mask` takes either an `.npy` mask (uint8
//! or bool, `height x width` of the crop, non-zero = masked) or a no-contact recording, which is
//! cropped the same way and run through the same static accumulator settings
//! (`evtac_repr::Mask::from_recording`: pixels whose 8-bit frame value differs from the neutral
//! level at the end of the recording).

use anyhow::{Context, bail, ensure};
use evtac_events::{Event, Resolution, Roi};
use evtac_learn::Model;
use evtac_repr::{
    Comparison, Decay, DenseSettings, DynamicConfig, FeatureExtractor, FeatureProvenance, Mask,
    Polarity, ReprConfig, ReprKind, StaticConfig, ThresholdSpace,
};
use ndarray::{Array2, Array3, Array4};

use crate::outputs::write_npy;
use std::path::{Path, PathBuf};

/// What to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum What {
    /// Binary frames: uint8 N x H x W, 0 or 1 (stacked and late: N x 2H x W, the static frame
    /// above the dynamic one). Time surfaces, histograms and voxel grids: float32
    /// N x C x H x W, channels in tonic's order (OFF then ON; voxel bins in time order).
    Frames,
    /// 8x8 mean-pooled features: float32 N x (C * H/8 * W/8), 900 per channel for 240x240
    /// (1800 for stacked and late, the two polarities of a time surface or histogram; 900 per
    /// voxel bin).
    Features,
    /// The static accumulator's potentials: float32 N x H x W (every kind with a static part).
    Potential,
}

/// Threshold space of the static representation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Space {
    /// On the float32 potential.
    Potential,
    /// On dv-processing's 8-bit `generateFrame` values.
    U8,
}

/// Comparison against the static threshold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Cmp {
    /// Strictly greater.
    Gt,
    /// Greater or equal.
    Ge,
}

/// Polarity handling of the static representation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PolarityArg {
    /// ON adds eta, OFF subtracts it.
    Signed,
    /// Every event adds eta.
    Ignore,
}

/// Decay function of the static representation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DecayArg {
    /// Exponential decay with time constant tau (the paper's).
    Exponential,
    /// Linear decay by one unit of potential per tau.
    Linear,
    /// No decay.
    None,
}

/// Arguments of `evtac represent`.
#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("settings").multiple(true)))]
pub struct Args {
    // The help is built from the one phrase of readable formats (see `crate::formats`).
    #[arg(help = concat!("The event recording (", crate::formats::readable_formats!(), ")"))]
    pub events: PathBuf,
    /// Text file of sample times t_k in microseconds, one per line, non-decreasing (blank lines
    /// and lines starting with `#` are skipped).
    #[arg(long)]
    pub samples: PathBuf,
    /// Representation to build.
    #[arg(long, value_parser = crate::kinds::parser(), default_value = "combined", group = "settings")]
    pub repr: ReprKind,
    /// What to write: binary frames, pooled features or static potentials.
    #[arg(long, value_enum, default_value = "features")]
    pub what: What,
    /// Output NPY file. Features are written with `OUTPUT.json` beside them, saying what made
    /// them (representation and settings, crop, mask, --filter's filters), which `evtac
    /// predict` checks against the model.
    #[arg(long, short)]
    pub output: PathBuf,
    /// Make the features a model reads: its representation and settings, its crop and its
    /// no-contact mask (instead of --repr, the settings, --roi and --mask).
    #[arg(long, value_name = "MODEL_DIR", conflicts_with = "settings")]
    pub model: Option<PathBuf>,
    #[command(flatten)]
    pub sensor: crate::sensor::SensorArgs,
    #[command(flatten)]
    pub streams: crate::streams::StreamArgs,
    // Applied to the recording and to a no-contact recording given as --mask (clap shows only
    // FilterArgs' own help; --mask and --output say what filters mean here).
    #[command(flatten)]
    pub filters: crate::filtering::FilterArgs,
    /// Crop: a centered WIDTHxHEIGHT region, or `none` for the whole sensor [default: 240x240].
    #[arg(long, group = "settings")]
    pub roi: Option<String>,
    /// No-contact mask: an `.npy` mask (non-zero = masked, crop-sized) or a no-contact recording
    /// run through the same static settings (and the same --filter filters).
    #[arg(long, group = "settings")]
    pub mask: Option<PathBuf>,
    /// Static: decay function [default: exponential].
    #[arg(long, value_enum, group = "settings")]
    pub decay: Option<DecayArg>,
    /// Static: decay time constant in milliseconds [default: 1000]. Time surface: its tau
    /// [default: 100].
    #[arg(long, group = "settings")]
    pub tau_ms: Option<f64>,
    /// Static: event contribution eta [default: 0.15].
    #[arg(long, group = "settings")]
    pub eta: Option<f32>,
    /// Static: threshold in event contributions; set when value > threshold x eta [default: 2].
    /// Time surface: binarize, 1 where the value is > this, in (0, 1) [default: continuous].
    #[arg(long, group = "settings")]
    pub threshold: Option<f64>,
    /// Static: where the threshold applies [default: potential].
    #[arg(long, value_enum, group = "settings")]
    pub threshold_space: Option<Space>,
    /// Static: comparison against the threshold [default: gt].
    #[arg(long, value_enum, group = "settings")]
    pub cmp: Option<Cmp>,
    /// Static: lower clamp of the potential [default: 0].
    #[arg(long, allow_hyphen_values = true, group = "settings")]
    pub min_potential: Option<f32>,
    /// Static: upper clamp of the potential [default: 1].
    #[arg(long, allow_hyphen_values = true, group = "settings")]
    pub max_potential: Option<f32>,
    /// Static: neutral potential, the decay target [default: 0].
    #[arg(long, allow_hyphen_values = true, group = "settings")]
    pub neutral_potential: Option<f32>,
    /// Static: polarity handling [default: signed].
    #[arg(long, value_enum, group = "settings")]
    pub polarity: Option<PolarityArg>,
    /// Static: dv-processing's synchronous decay (every pixel decays at each sample).
    #[arg(long, group = "settings")]
    pub synchronous_decay: bool,
    /// Dynamic, histogram, voxel grid: window length in milliseconds [default: 640].
    #[arg(long, group = "settings")]
    pub window_ms: Option<f64>,
    /// Voxel grid: temporal bins [default: 5].
    #[arg(long, group = "settings")]
    pub bins: Option<u32>,
    /// Dynamic: set when the window's event count is > this [default: 0].
    #[arg(long, group = "settings")]
    pub count_threshold: Option<u32>,
}

impl Args {
    fn static_config(&self) -> StaticConfig {
        let d = StaticConfig::default();
        StaticConfig {
            decay: match self.decay {
                Some(DecayArg::Exponential) => Decay::Exponential,
                Some(DecayArg::Linear) => Decay::Linear,
                Some(DecayArg::None) => Decay::None,
                None => d.decay,
            },
            tau_ms: self.tau_ms.unwrap_or(d.tau_ms),
            eta: self.eta.unwrap_or(d.eta),
            min_potential: self.min_potential.unwrap_or(d.min_potential),
            max_potential: self.max_potential.unwrap_or(d.max_potential),
            neutral_potential: self.neutral_potential.unwrap_or(d.neutral_potential),
            polarity: match self.polarity {
                Some(PolarityArg::Signed) => Polarity::Signed,
                Some(PolarityArg::Ignore) => Polarity::Ignore,
                None => d.polarity,
            },
            synchronous_decay: self.synchronous_decay,
            threshold: self.threshold.map_or(d.threshold, |t| t as f32),
            threshold_space: match self.threshold_space {
                Some(Space::Potential) => ThresholdSpace::Potential,
                Some(Space::U8) => ThresholdSpace::U8,
                None => d.threshold_space,
            },
            comparison: match self.cmp {
                Some(Cmp::Gt) => Comparison::Gt,
                Some(Cmp::Ge) => Comparison::Ge,
                None => d.comparison,
            },
        }
    }

    fn dynamic_config(&self) -> DynamicConfig {
        let d = DynamicConfig::default();
        DynamicConfig {
            window_ms: self.window_ms.unwrap_or(d.window_ms),
            count_threshold: self.count_threshold.unwrap_or(d.count_threshold),
        }
    }

    /// The flags given that only the static and dynamic parts take.
    fn binary_only_flags(&self) -> Vec<&'static str> {
        let given = [
            ("--decay", self.decay.is_some()),
            ("--eta", self.eta.is_some()),
            ("--threshold-space", self.threshold_space.is_some()),
            ("--cmp", self.cmp.is_some()),
            ("--min-potential", self.min_potential.is_some()),
            ("--max-potential", self.max_potential.is_some()),
            ("--neutral-potential", self.neutral_potential.is_some()),
            ("--polarity", self.polarity.is_some()),
            ("--synchronous-decay", self.synchronous_decay),
            ("--count-threshold", self.count_threshold.is_some()),
        ];
        given
            .into_iter()
            .filter_map(|(flag, on)| on.then_some(flag))
            .collect()
    }

    fn config(&self) -> anyhow::Result<ReprConfig> {
        let flags = self.binary_only_flags();
        ensure!(
            !self.repr.is_dense() || flags.is_empty(),
            "{} set the static or dynamic part; --repr {} has neither",
            flags.join(", "),
            self.repr.name()
        );
        let settings = DenseSettings {
            tau_ms: self.tau_ms,
            threshold: self.threshold,
            window_ms: self.window_ms,
            bins: self.bins,
        };
        match crate::kinds::dense_config(self.repr, settings)? {
            Some(config) => Ok(config),
            None => Ok(self
                .repr
                .config(self.static_config(), self.dynamic_config())),
        }
    }
}

/// Runs `evtac represent`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let model = match &args.model {
        Some(dir) => Some(
            Model::load(dir)
                .with_context(|| format!("loading the model bundle {}", dir.display()))?,
        ),
        None => None,
    };
    let config = match &model {
        Some(m) => m.repr_config(),
        None => args.config()?,
    };
    config.validate()?;
    let inputs: Vec<&Path> = [&args.events, &args.samples]
        .into_iter()
        .chain(args.mask.as_ref())
        .map(PathBuf::as_path)
        .collect();
    evtac_events::output::refuse_input(&args.output, &inputs)?;
    let sidecar = FeatureProvenance::sidecar(&args.output);
    if args.what == What::Features {
        evtac_events::output::refuse_input(&sidecar, &inputs)?;
    }
    if args.what == What::Potential && config.static_part().is_none() {
        bail!("--what potential needs a static part: --repr static, combined, stacked or late");
    }
    let samples = read_samples(&args.samples)?;

    let (sensor, events) = read_events(&args.events, &args)?;
    let roi = match &model {
        Some(m) => Roi::centered(sensor, m.representation().frame).with_context(|| {
            format!(
                "the model's {} crop does not fit inside the {sensor} sensor of {}",
                m.representation().frame,
                args.events.display()
            )
        })?,
        None => parse_roi(args.roi.as_deref(), sensor)?,
    };
    let mut cropped = Vec::new();
    roi.crop_into(&events, &mut cropped);
    drop(events);
    let frame = roi.size;

    let mask = match (&model, &args.mask) {
        (Some(m), _) => m.mask().cloned(),
        (None, None) => None,
        (None, Some(path)) => Some(read_mask(path, &args, &config, frame)?),
    };

    if mask.is_some() && config.dense_part().is_some() {
        bail!(
            "--mask applies to the static part: --repr {} has none",
            config.kind_name()
        );
    }
    let mut fx = FeatureExtractor::new(&[config], frame, mask.as_ref())?;
    let (n, h, w) = (
        samples.len(),
        usize::from(frame.height),
        usize::from(frame.width),
    );
    // Stacked and late frames are the static frame above the dynamic one; a real-valued kind's
    // are its channels, one after the other.
    let dense = config.dense_part().is_some();
    let (frame_h, channels) = if dense {
        (h, config.frames())
    } else {
        (h * config.frames(), 1)
    };
    let per_sample = match args.what {
        What::Features => fx.feature_len(0),
        What::Frames => channels * frame_h * w,
        What::Potential => h * w,
    };
    let mut bytes = Vec::new();
    let mut floats = Vec::new();
    match args.what {
        What::Frames if !dense => bytes.reserve(n * per_sample),
        What::Frames | What::Features | What::Potential => floats.reserve(n * per_sample),
    }
    let bar = crate::progress::bar(n as u64, "represent");
    let mut values = Vec::new();
    fx.run(&cropped, &samples, |_, fx| {
        match args.what {
            What::Frames if dense => {
                fx.frame_values_into(0, &mut values);
                floats.extend_from_slice(&values);
            }
            What::Frames => bytes.extend_from_slice(fx.frame(0)),
            What::Features => floats.extend_from_slice(fx.features(0)),
            What::Potential => floats.extend_from_slice(fx.potentials(0).unwrap_or_default()),
        }
        bar.inc(1);
    })
    .with_context(|| {
        format!(
            "building {} at the sample times of {} from {} (event indices count cropped events)",
            config.cache_key(),
            args.samples.display(),
            args.events.display()
        )
    })?;
    bar.finish_and_clear();

    let out = &args.output;
    match args.what {
        What::Frames if dense => {
            let shape = (n, channels, frame_h, w);
            write_npy(out, &Array4::from_shape_vec(shape, floats)?)?;
        }
        What::Frames => write_npy(out, &Array3::from_shape_vec((n, frame_h, w), bytes)?)?,
        What::Potential => write_npy(out, &Array3::from_shape_vec((n, h, w), floats)?)?,
        What::Features => {
            write_npy(out, &Array2::from_shape_vec((n, per_sample), floats)?)?;
            let filters = args.filters.filters.iter().map(|f| f.to_string()).collect();
            let made = FeatureProvenance::new(&config, frame, mask.as_ref()).with_filters(filters);
            crate::outputs::write_text(&sidecar, &(serde_json::to_string_pretty(&made)? + "\n"))?;
        }
    }
    eprintln!(
        "wrote {} samples of {} ({} events in the {} crop) to {}",
        n,
        config.cache_key(),
        cropped.len(),
        frame,
        out.display()
    );
    Ok(())
}

/// Reads a recording and its sensor size (the file's, which `--sensor` must agree with, or
/// `--sensor` for a file that states none), through `--filter`'s filters.
fn read_events(path: &Path, args: &Args) -> anyhow::Result<(Resolution, Vec<Event>)> {
    let resolution = args.sensor.sensor;
    let rec = evtac_formats::open_with(path, &args.streams.selection())
        .and_then(evtac_formats::EventReader::into_recording)
        .with_context(|| format!("reading events from {}", path.display()))?;
    if let (Some(given), Some(found)) = (resolution, rec.resolution) {
        ensure!(
            given == found,
            "{} states a {found} sensor, but --sensor says {given}",
            path.display()
        );
    }
    let sensor = resolution.or(rec.resolution).with_context(|| {
        format!(
            "{} does not state its sensor resolution: pass --sensor WIDTHxHEIGHT",
            path.display()
        )
    })?;
    let events = args.filters.apply(path, sensor, rec.events)?;
    Ok((sensor, events))
}

fn parse_roi(roi: Option<&str>, sensor: Resolution) -> anyhow::Result<Roi> {
    match roi.map(str::trim) {
        Some(s) if s.eq_ignore_ascii_case("none") => Ok(Roi::full(sensor)),
        other => {
            let size: Resolution = other
                .unwrap_or("240x240")
                .parse()
                .map_err(|e: String| anyhow::anyhow!("--roi: {e}"))?;
            Roi::centered(sensor, size)
                .with_context(|| format!("--roi {size} does not fit inside the {sensor} sensor"))
        }
    }
}

fn read_samples(path: &Path) -> anyhow::Result<Vec<i64>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading sample times from {}", path.display()))?;
    let mut samples = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let t: i64 = line.parse().with_context(|| {
            format!(
                "{} line {}: `{line}` is not a time in whole microseconds",
                path.display(),
                i + 1
            )
        })?;
        if let Some(&prev) = samples.last() {
            ensure!(
                t >= prev,
                "{} line {}: sample time {t} us is before the previous one ({prev} us)",
                path.display(),
                i + 1
            );
        }
        samples.push(t);
    }
    Ok(samples)
}

fn read_mask(
    path: &Path,
    args: &Args,
    config: &ReprConfig,
    frame: Resolution,
) -> anyhow::Result<Mask> {
    let is_npy = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"));
    if is_npy {
        let pixels: Array2<u8> = match ndarray_npy::read_npy(path) {
            Ok(a) => a,
            Err(_) => ndarray_npy::read_npy::<_, Array2<bool>>(path)
                .with_context(|| format!("reading {} as a uint8 or bool 2-D mask", path.display()))?
                .mapv(u8::from),
        };
        let flat: Vec<u8> = pixels.iter().copied().collect();
        return Mask::from_grid(frame, pixels.dim(), &flat)
            .with_context(|| format!("the mask {}", path.display()));
    }
    let Some(static_config) = config.static_part() else {
        bail!("--mask applies to the static part: it needs --repr static or combined");
    };
    let (sensor, events) = read_events(path, args)
        .with_context(|| format!("reading the no-contact recording {}", path.display()))?;
    let roi = parse_roi(args.roi.as_deref(), sensor)?;
    Mask::from_recording(&roi, static_config, &events)
        .with_context(|| format!("building the no-contact mask from {}", path.display()))
}
