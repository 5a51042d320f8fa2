//! Event representations for contact-angle estimation: static (dv-processing-compatible
//! exponential decay), dynamic (sliding-window count) and combined (pixel-wise OR), binarized
//! and 8x8 mean-pooled to 900 features, incrementally at each sample time.
//!
//! This is the paper's "Representation processing" section:
//! - **static** ([`StaticAccumulator`]): dv-processing's `dv::Accumulator` bit for bit (float32
//!   potentials, lazy exponential decay, `T` starting at 0, min/max/neutral potential, signed or
//!   ignored polarity, optional synchronous decay), then the no-contact [`Mask`], then a
//!   threshold of `threshold x eta` ([`StaticThreshold`]; the threshold space and comparison are
//!   explicit options, see [`config`] for the default reading and why);
//! - **dynamic** ([`SlidingWindow`]): events per pixel over `(t_k - window, t_k]`, both
//!   polarities, kept incrementally, set when `count > count_threshold`;
//! - **combined**: the OR of both binary frames, built in the same pass;
//! - **pooling** ([`Pool8`]): 8x8 mean pooling to `(w / 8) x (h / 8)` features (30 x 30 = 900
//!   for the paper's 240x240 crop), row-major, updated from pixel flips.
//!
//! [`ReprKind`] is the one list of kinds (and of learned fusions, `stacked` and `late`, whose
//! features are both frames side by side), with their names on the command line and in reports.
//!
//! Beyond the paper ([`dense`]): time surfaces, polarity histograms and voxel grids as tonic 1.7
//! computes them, real-valued frames of several channels pooled 8x8 per channel, run by
//! [`DenseExtractor`].
//!
//! [`FeatureExtractor`] runs any number of [`ReprConfig`]s over one event stream in one pass,
//! sharing accumulators and windows between configs that can share them.
//!
//! ```
//! use evtac_events::{Event, Resolution};
//! use evtac_repr::{DynamicConfig, FeatureExtractor, ReprConfig, StaticConfig};
//!
//! // A tau x threshold grid and the paper's dynamic setting, in one pass.
//! let mut configs = Vec::new();
//! for tau_ms in [250.0, 1000.0] {
//!     for threshold in [0.0, 2.0] {
//!         configs.push(ReprConfig::Static(StaticConfig { tau_ms, threshold, ..Default::default() }));
//!     }
//! }
//! configs.push(ReprConfig::Dynamic(DynamicConfig::default()));
//! let mut fx = FeatureExtractor::new(&configs, Resolution::new(240, 240), None)?;
//!
//! let events: Vec<Event> = (0..3)
//!     .map(|i| Event { t: 1_000 + i, x: 100, y: 50, polarity: true })
//!     .collect();
//! fx.push(&events)?;
//! fx.advance_to(999)?; // before the first event: nothing set
//! assert!(fx.features(0).iter().all(|&f| f == 0.0));
//! fx.advance_to(1_002)?;
//! // Three quick ON events give 0.45 > 2 x 0.15: set in every static config, and in the window.
//! assert!((0..configs.len()).all(|i| fx.frame(i)[50 * 240 + 100] == 1));
//! assert_eq!(fx.features(4)[(50 / 8) * 30 + 100 / 8], 1.0 / 64.0);
//! # Ok::<(), evtac_repr::ReprError>(())
//! ```

pub mod accumulator;
mod check;
pub mod combine;
pub mod config;
mod crop;
pub mod dense;
mod error;
pub mod expf;
pub mod extractor;
mod fifo;
pub mod kind;
pub mod mask;
pub mod pool;
mod prefetch;
mod provenance;
pub mod window;

pub use accumulator::{FrameMap, StaticAccumulator};
pub use combine::{StaticThreshold, dynamic_frame, or_frames, static_frame};
pub use config::{
    AccumulatorParams, Comparison, Decay, DynamicConfig, Polarity, ReprConfig, StaticConfig,
    ThresholdSpace,
};
pub use crop::{CROP, SensorTooSmall, centered_crop};
pub use dense::{
    DenseConfig, DenseExtractor, HistogramConfig, TimeSurfaceConfig, VoxelGridConfig,
    extract_dense_features,
};
pub use error::ReprError;
pub use extractor::{FeatureExtractor, extract_features};
pub use kind::{DenseSettings, ReprKind, UnknownKind, kind_name};
pub use mask::Mask;
pub use pool::{Pool8, pool8};
pub use provenance::FeatureProvenance;
pub use window::SlidingWindow;
