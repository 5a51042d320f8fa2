//! Representation settings: [`StaticConfig`], [`DynamicConfig`] and [`ReprConfig`], with the
//! paper's chosen values as defaults and a stable [`ReprConfig::cache_key`].
//!
//! # The paper's reading, and why these defaults
//! The paper builds its static frames with dv-processing's `dv::Accumulator` (exponential decay,
//! lazy decay), tunes tau and "a threshold in event contributions", and picks tau = 1000 ms with
//! a threshold of 2 contributions; the dynamic window is 640 ms with an event-count threshold
//! of 0. It does not state the event contribution, the potential limits or the polarity mode, so
//! evtac keeps dv-processing's constructor defaults (`eta` 0.15, min 0, max 1, neutral 0, signed
//! polarity), which matches the paper's formula (`+ eta * p_k` with `p_k` in {+1, -1}).
//!
//! The threshold is applied to the float32 **potential**, with a strict **`>`**: a pixel is set
//! when `V > threshold * eta`. That mirrors the dynamic rule (`count > threshold`), makes a
//! threshold of 0 mean "any positive potential", and avoids the 8-bit quantisation of
//! `generateFrame`. Two consequences worth knowing (see `DV_ACCUMULATOR.md`): with lazy decay two
//! events `dt` apart give `eta * (1 + exp(-dt / tau)) < 2 * eta`, so the default needs about three
//! recent ON events; and the 8-bit reading ([`ThresholdSpace::U8`]) puts the same threshold at
//! 76.5 on the 0..255 scale, where two events round to at most 76. Both spaces and both
//! comparisons are available for reproducing other readings.

use crate::ReprError;
use crate::dense::{DenseConfig, HistogramConfig, TimeSurfaceConfig, VoxelGridConfig};
use serde::{Deserialize, Serialize};

/// How a pixel's potential relaxes towards the neutral potential between its events
/// (dv-processing's `Accumulator::Decay`; `STEP` is not offered).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Decay {
    /// `V = (V - neutral) * exp(-dt / tau) + neutral` (the paper's choice).
    #[default]
    Exponential,
    /// `V` moves towards neutral by `dt / tau` (one unit of potential per `tau`), stopping at
    /// neutral. dv-processing's decay parameter is then the rate `1 / tau` per microsecond.
    Linear,
    /// No decay: potentials only change by event contributions and the clamp.
    None,
}

/// How event polarity enters the potential.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Polarity {
    /// ON events add `eta`, OFF events subtract it (dv-processing's default).
    #[default]
    Signed,
    /// Every event adds `eta` (dv-processing's `rectifyPolarity` / `ignorePolarity`).
    Ignore,
}

/// Where the static threshold `threshold x eta` is applied.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ThresholdSpace {
    /// On the float32 potential `V` (the default).
    #[default]
    Potential,
    /// On the 8-bit frame of dv-processing's `generateFrame` (`rint(V * s + b)`,
    /// `s = 255 / (max - min)`, `b = -min * s`), against `threshold * eta` mapped by the same
    /// affine map but not rounded (2 x 0.15 with min 0, max 1 gives 76.5).
    U8,
}

/// The comparison that sets a static pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Comparison {
    /// Set when the value is strictly greater than the threshold (the default).
    #[default]
    Gt,
    /// Set when the value is greater than or equal to the threshold.
    Ge,
}

/// Settings of the static representation: the accumulator (bit-for-bit dv-processing) and the
/// binarization threshold.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StaticConfig {
    /// Decay function.
    pub decay: Decay,
    /// Decay time constant in milliseconds (exponential: `tau`; linear: time to move by 1.0).
    pub tau_ms: f64,
    /// Event contribution `eta` added (or subtracted) per event.
    pub eta: f32,
    /// Lower clamp of the potential.
    pub min_potential: f32,
    /// Upper clamp of the potential.
    pub max_potential: f32,
    /// Potential of a pixel without events; decay relaxes towards it.
    pub neutral_potential: f32,
    /// Signed or ignored polarity.
    pub polarity: Polarity,
    /// dv-processing's synchronous decay: every pixel is decayed to the latest event's time each
    /// time a frame is read (costs a full-frame pass per sample). `false` (lazy) is the paper's.
    pub synchronous_decay: bool,
    /// Binarization threshold in event contributions: a pixel is set when its value compares
    /// above `threshold * eta` (see [`ThresholdSpace`], [`Comparison`]).
    pub threshold: f32,
    /// Space the threshold is applied in.
    pub threshold_space: ThresholdSpace,
    /// Comparison against the threshold.
    pub comparison: Comparison,
}

impl Default for StaticConfig {
    /// The paper's chosen static settings: exponential decay, tau 1000 ms, threshold 2
    /// contributions, with dv-processing's defaults for the rest (see the module docs).
    fn default() -> Self {
        Self {
            decay: Decay::Exponential,
            tau_ms: 1000.0,
            eta: 0.15,
            min_potential: 0.0,
            max_potential: 1.0,
            neutral_potential: 0.0,
            polarity: Polarity::Signed,
            synchronous_decay: false,
            threshold: 2.0,
            threshold_space: ThresholdSpace::Potential,
            comparison: Comparison::Gt,
        }
    }
}

/// The accumulation part of a [`StaticConfig`] in the exact form the accumulator computes with:
/// configs with equal `AccumulatorParams` share one accumulator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccumulatorParams {
    /// Decay function.
    pub decay: Decay,
    /// dv-processing's `decayParam` as float32: `tau` in microseconds (exponential), the rate in
    /// potential per microsecond (linear), unused for none.
    pub decay_param: f32,
    /// Event contribution.
    pub eta: f32,
    /// Lower clamp.
    pub min_potential: f32,
    /// Upper clamp.
    pub max_potential: f32,
    /// Neutral potential.
    pub neutral_potential: f32,
    /// Every event counts as ON.
    pub ignore_polarity: bool,
    /// Synchronous decay at read time.
    pub synchronous_decay: bool,
}

fn invalid(field: &'static str, value: impl std::fmt::Display, reason: &'static str) -> ReprError {
    ReprError::InvalidConfig {
        field,
        value: value.to_string(),
        reason,
    }
}

impl StaticConfig {
    /// Checks every field: finite numbers, `tau_ms > 0`, `max_potential > min_potential`.
    pub fn validate(&self) -> Result<(), ReprError> {
        if !(self.tau_ms.is_finite() && self.tau_ms > 0.0) {
            return Err(invalid("tau_ms", self.tau_ms, "must be finite and > 0"));
        }
        for (field, v) in [
            ("eta", self.eta),
            ("min_potential", self.min_potential),
            ("max_potential", self.max_potential),
            ("neutral_potential", self.neutral_potential),
            ("threshold", self.threshold),
        ] {
            if !v.is_finite() {
                return Err(invalid(field, v, "must be finite"));
            }
        }
        if self.max_potential <= self.min_potential {
            return Err(invalid(
                "max_potential",
                self.max_potential,
                "must be greater than min_potential",
            ));
        }
        Ok(())
    }

    /// The accumulator parameters, converted exactly as evtac feeds them to the accumulator
    /// (and to dv-processing in the differential tests).
    pub fn accumulator_params(&self) -> AccumulatorParams {
        let tau_us = self.tau_ms * 1000.0;
        let decay_param = match self.decay {
            Decay::Exponential | Decay::None => tau_us as f32,
            Decay::Linear => (1.0 / tau_us) as f32,
        };
        AccumulatorParams {
            decay: self.decay,
            decay_param,
            eta: self.eta,
            min_potential: self.min_potential,
            max_potential: self.max_potential,
            neutral_potential: self.neutral_potential,
            ignore_polarity: self.polarity == Polarity::Ignore,
            synchronous_decay: self.synchronous_decay,
        }
    }

    fn key(&self) -> String {
        let decay = match self.decay {
            Decay::Exponential => "exp",
            Decay::Linear => "lin",
            Decay::None => "none",
        };
        let polarity = match self.polarity {
            Polarity::Signed => "signed",
            Polarity::Ignore => "ignore",
        };
        let space = match self.threshold_space {
            ThresholdSpace::Potential => "pot",
            ThresholdSpace::U8 => "u8",
        };
        let cmp = match self.comparison {
            Comparison::Gt => "gt",
            Comparison::Ge => "ge",
        };
        let sync = if self.synchronous_decay {
            "sync"
        } else {
            "lazy"
        };
        format!(
            "static_{decay}_tau{}ms_eta{}_min{}_max{}_neutral{}_{polarity}_{sync}_thr{}_{space}_{cmp}",
            self.tau_ms,
            self.eta,
            self.min_potential,
            self.max_potential,
            self.neutral_potential,
            self.threshold
        )
    }
}

/// Settings of the dynamic representation: a sliding-window event count.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DynamicConfig {
    /// Window length in milliseconds: the window at `t_k` is `(t_k - window, t_k]`. Rounded to
    /// whole microseconds.
    pub window_ms: f64,
    /// A pixel is set when its event count (both polarities) in the window is `> count_threshold`.
    pub count_threshold: u32,
}

impl Default for DynamicConfig {
    /// The paper's chosen dynamic settings: a 640 ms window, count threshold 0.
    fn default() -> Self {
        Self {
            window_ms: 640.0,
            count_threshold: 0,
        }
    }
}

impl DynamicConfig {
    /// Checks `window_ms`: finite and at least one microsecond.
    pub fn validate(&self) -> Result<(), ReprError> {
        if !(self.window_ms.is_finite() && self.window_ms >= 0.001) {
            return Err(invalid(
                "window_ms",
                self.window_ms,
                "must be finite and at least 0.001 (one microsecond)",
            ));
        }
        if self.window_ms > 1e12 {
            return Err(invalid("window_ms", self.window_ms, "must be at most 1e12"));
        }
        Ok(())
    }

    /// The window length in microseconds (`window_ms * 1000`, rounded).
    pub fn window_us(&self) -> i64 {
        (self.window_ms * 1000.0).round() as i64
    }

    fn key(&self) -> String {
        format!(
            "dynamic_win{}us_cnt{}",
            self.window_us(),
            self.count_threshold
        )
    }
}

/// One representation: static, dynamic, their pixel-wise OR (the paper's three), or both side
/// by side for a network that learns the fusion (evtac's step beyond the OR, the paper's future
/// work).
///
/// Serialized with a `kind` tag, e.g. `{"kind": "dynamic", "window_ms": 640.0,
/// "count_threshold": 0}`.
///
/// `Stacked` and `Late` have the same features (the static part's pooled frame followed by the
/// dynamic part's: [`ReprConfig::frames`] is 2, so 1800 features on the paper's crop); they
/// differ in the network that reads them (a dense first layer over all 1800, or one 900-input
/// branch per part concatenated before the head: `evtac_learn::Architecture`), so they share
/// one [`ReprConfig::cache_key`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ReprConfig {
    /// Exponential-decay accumulator, masked and thresholded.
    Static(StaticConfig),
    /// Sliding-window event count, thresholded.
    Dynamic(DynamicConfig),
    /// OR of a static and a dynamic binary frame, both built in the same pass.
    Combined {
        /// The static part.
        static_part: StaticConfig,
        /// The dynamic part.
        dynamic_part: DynamicConfig,
    },
    /// Both binary frames pooled side by side (static first), for one dense network over both.
    Stacked {
        /// The static part.
        static_part: StaticConfig,
        /// The dynamic part.
        dynamic_part: DynamicConfig,
    },
    /// The same features as [`ReprConfig::Stacked`], for a network with one branch per part
    /// whose hidden layers are concatenated before the head (late fusion).
    Late {
        /// The static part.
        static_part: StaticConfig,
        /// The dynamic part.
        dynamic_part: DynamicConfig,
    },
    /// A per-polarity time surface, as tonic computes it (a kind the paper did not choose:
    /// [`crate::dense`]).
    #[serde(rename = "time-surface")]
    TimeSurface(TimeSurfaceConfig),
    /// Per-polarity event counts over a window, as tonic's `to_frame_numpy`.
    Histogram(HistogramConfig),
    /// A signed bilinear voxel grid over a window, as tonic's `to_voxel_grid_numpy`.
    #[serde(rename = "voxel-grid")]
    VoxelGrid(VoxelGridConfig),
}

impl Default for ReprConfig {
    /// The combined representation with the paper's chosen static and dynamic settings.
    fn default() -> Self {
        Self::Combined {
            static_part: StaticConfig::default(),
            dynamic_part: DynamicConfig::default(),
        }
    }
}

impl ReprConfig {
    /// The static part, if any.
    pub fn static_part(&self) -> Option<&StaticConfig> {
        match self {
            Self::Static(s)
            | Self::Combined { static_part: s, .. }
            | Self::Stacked { static_part: s, .. }
            | Self::Late { static_part: s, .. } => Some(s),
            Self::Dynamic(_) | Self::TimeSurface(_) | Self::Histogram(_) | Self::VoxelGrid(_) => {
                None
            }
        }
    }

    /// The dynamic part, if any.
    pub fn dynamic_part(&self) -> Option<&DynamicConfig> {
        match self {
            Self::Dynamic(d)
            | Self::Combined {
                dynamic_part: d, ..
            }
            | Self::Stacked {
                dynamic_part: d, ..
            }
            | Self::Late {
                dynamic_part: d, ..
            } => Some(d),
            Self::Static(_) | Self::TimeSurface(_) | Self::Histogram(_) | Self::VoxelGrid(_) => {
                None
            }
        }
    }

    /// The settings of a kind the paper did not choose (time surface, histogram, voxel grid),
    /// as [`crate::DenseExtractor`] takes them; `None` for the binary kinds.
    pub fn dense_part(&self) -> Option<DenseConfig> {
        match *self {
            Self::TimeSurface(c) => Some(DenseConfig::TimeSurface(c)),
            Self::Histogram(c) => Some(DenseConfig::Histogram(c)),
            Self::VoxelGrid(c) => Some(DenseConfig::VoxelGrid(c)),
            Self::Static(_)
            | Self::Dynamic(_)
            | Self::Combined { .. }
            | Self::Stacked { .. }
            | Self::Late { .. } => None,
        }
    }

    /// The config of a real-valued kind's settings.
    pub fn from_dense(dense: DenseConfig) -> Self {
        match dense {
            DenseConfig::TimeSurface(c) => Self::TimeSurface(c),
            DenseConfig::Histogram(c) => Self::Histogram(c),
            DenseConfig::VoxelGrid(c) => Self::VoxelGrid(c),
        }
    }

    /// How many pooled frames the features hold side by side: 2 for [`ReprConfig::Stacked`]
    /// and [`ReprConfig::Late`] (static, then dynamic), the channels of a real-valued kind
    /// ([`DenseConfig::channels`]: 2 polarities, or a voxel grid's bins), 1 otherwise.
    pub fn frames(&self) -> usize {
        match self {
            Self::Stacked { .. } | Self::Late { .. } => 2,
            Self::Static(_) | Self::Dynamic(_) | Self::Combined { .. } => 1,
            Self::TimeSurface(_) | Self::Histogram(_) | Self::VoxelGrid(_) => {
                self.dense_part().map_or(1, |d| d.channels())
            }
        }
    }

    /// The kind's name as the `kind` tag and the CLI's `--repr` spell it (`static`, `dynamic`,
    /// `combined`, `stacked`, `late`).
    pub fn kind_name(&self) -> &'static str {
        self.kind().name()
    }

    /// Checks every field of every part.
    pub fn validate(&self) -> Result<(), ReprError> {
        if let Some(s) = self.static_part() {
            s.validate()?;
        }
        if let Some(d) = self.dynamic_part() {
            d.validate()?;
        }
        if let Some(d) = self.dense_part() {
            d.validate()?;
        }
        Ok(())
    }

    /// A stable, file-name-safe string that identifies the representation's output exactly
    /// (every field that changes a feature is in it), e.g.
    /// `v1_dynamic_win640000us_cnt0`. Numbers print in Rust's shortest round-trip form. The
    /// mask is data, not config: a cache keyed by this string must also key the mask used.
    pub fn cache_key(&self) -> String {
        match self {
            Self::Static(s) => format!("v1_{}", s.key()),
            Self::Dynamic(d) => format!("v1_{}", d.key()),
            Self::Combined {
                static_part,
                dynamic_part,
            } => format!("v1_combined_{}+{}", static_part.key(), dynamic_part.key()),
            // One key for both: the features are the same, only the network differs.
            Self::Stacked {
                static_part,
                dynamic_part,
            }
            | Self::Late {
                static_part,
                dynamic_part,
            } => format!("v1_stacked_{}+{}", static_part.key(), dynamic_part.key()),
            Self::TimeSurface(_) | Self::Histogram(_) | Self::VoxelGrid(_) => {
                let dense = self.dense_part().map(|d| d.cache_key()).unwrap_or_default();
                format!("v1_{dense}")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_papers() {
        let s = StaticConfig::default();
        assert_eq!((s.tau_ms, s.threshold, s.eta), (1000.0, 2.0, 0.15));
        assert_eq!(s.accumulator_params().decay_param, 1e6);
        let d = DynamicConfig::default();
        assert_eq!((d.window_us(), d.count_threshold), (640_000, 0));
        assert!(ReprConfig::default().validate().is_ok());
    }

    #[test]
    fn cache_keys_are_stable_and_distinct() {
        assert_eq!(
            ReprConfig::default().cache_key(),
            "v1_combined_static_exp_tau1000ms_eta0.15_min0_max1_neutral0_signed_lazy_thr2_pot_gt\
             +dynamic_win640000us_cnt0"
        );
        let a = ReprConfig::Static(StaticConfig::default());
        let b = ReprConfig::Static(StaticConfig {
            comparison: Comparison::Ge,
            ..StaticConfig::default()
        });
        assert_ne!(a.cache_key(), b.cache_key());
        assert!(
            a.cache_key()
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "._-+".contains(c))
        );
    }

    #[test]
    fn stacked_and_late_share_their_features_key_and_have_two_frames() {
        let (static_part, dynamic_part) = (StaticConfig::default(), DynamicConfig::default());
        let [stacked, late] = [crate::ReprKind::Stacked, crate::ReprKind::Late]
            .map(|k| k.config(static_part, dynamic_part));
        assert_eq!(stacked.cache_key(), late.cache_key());
        assert_ne!(stacked.cache_key(), ReprConfig::default().cache_key());
        assert_eq!((stacked.frames(), late.frames()), (2, 2));
        assert_eq!(ReprConfig::default().frames(), 1);
        assert_eq!((stacked.kind_name(), late.kind_name()), ("stacked", "late"));
        let json = serde_json::to_string(&late).unwrap();
        assert!(json.contains("\"kind\":\"late\""), "{json}");
        assert_eq!(serde_json::from_str::<ReprConfig>(&json).unwrap(), late);
    }

    #[test]
    fn serde_round_trips_with_a_kind_tag() {
        let c = ReprConfig::default();
        let json = serde_json::to_string(&c).unwrap();
        assert!(json.contains("\"kind\":\"combined\""), "{json}");
        assert_eq!(serde_json::from_str::<ReprConfig>(&json).unwrap(), c);
        let d: ReprConfig = serde_json::from_str(r#"{"kind":"dynamic","window_ms":10}"#).unwrap();
        assert_eq!(d.dynamic_part().unwrap().window_us(), 10_000);
    }

    #[test]
    fn invalid_values_are_rejected() {
        let bad = StaticConfig {
            tau_ms: 0.0,
            ..StaticConfig::default()
        };
        assert!(matches!(
            bad.validate(),
            Err(ReprError::InvalidConfig {
                field: "tau_ms",
                ..
            })
        ));
        let bad = StaticConfig {
            max_potential: 0.0,
            ..StaticConfig::default()
        };
        assert!(bad.validate().is_err());
        let bad = DynamicConfig {
            window_ms: f64::NAN,
            count_threshold: 0,
        };
        assert!(bad.validate().is_err());
    }
}
