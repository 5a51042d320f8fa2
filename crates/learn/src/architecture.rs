//! Which network reads a representation's features: the paper's MLP on one pooled frame, or, for
//! the two frames side by side of a `stacked` or `late` representation (evtac's step beyond the
//! paper's pixel-wise OR, which the paper leaves as future work), a dense MLP over both or one
//! branch per frame joined before the head.
//!
//! | architecture | features | network |
//! | --- | --- | --- |
//! | [`Architecture::Mlp`] | 900 (static, dynamic or combined) | 900-256-128-64-2, the paper's |
//! | [`Architecture::Stacked`] | 1800 (static then dynamic) | 1800-256-128-64-2 |
//! | [`Architecture::Late`] | 1800 (static then dynamic) | two 900-128 branches, concatenated to 256, then the paper's head 256-128-64-2 |
//! | [`Architecture::Channels`] | `C x 900` (a real-valued kind's channels: 2 polarities, or a voxel grid's bins) | `C x 900`-256-128-64-2 |
//!
//! All three are stored and run as one four-layer MLP `inputs-256-128-64-2`. Late fusion is that
//! network with a block-diagonal first layer: the static inputs feed hidden units `0..128`, the
//! dynamic inputs `128..256`, and every other first-layer weight is exactly zero and never
//! trained (its gradient is not formed, so AdamW leaves it at zero: see `backprop.rs`). That is
//! the same function as two `nn.Linear(900, 128)` branches whose ReLU outputs are concatenated
//! before the head, so training, the exact streaming first layer and every kernel serve all
//! three; the bundle stores a late model under its branches' names for PyTorch (`bundle.rs`).
//! The price of sharing: the first layer's forward pass also multiplies the zero blocks (adding
//! exact zeros), as much work as a stacked network.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use evtac_repr::ReprConfig;

/// Features of one pooled frame: 30 x 30 cells of the paper's 240 x 240 crop.
pub const INPUTS: usize = 900;
/// The most pooled frames (channels) a network reads side by side: a voxel grid of up to 8 bins.
pub const MAX_FRAMES: usize = 8;
/// The most features any architecture reads: [`MAX_FRAMES`] pooled frames (7200). The
/// kernels' per-sample buffers are this long, on the stack, and index features as `u16`.
pub const MAX_INPUTS: usize = MAX_FRAMES * INPUTS;
/// Number of outputs: (pitch, roll) in degrees.
pub const OUTPUTS: usize = 2;
/// The hidden layers' widths, the paper's: 256, 128 and 64.
pub const HIDDEN: [usize; 3] = [256, 128, 64];
/// Number of linear layers.
pub const LAYERS: usize = HIDDEN.len() + 1;
/// Width of each late-fusion branch: the two together are the first hidden layer.
pub const BRANCH: usize = HIDDEN[0] / 2;

/// The network behind a representation (see the module docs).
///
/// Serialized as `"mlp"`, `"stacked"`, `"late"`, or `{"channels": C}`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Architecture {
    /// The paper's 900-256-128-64-2 MLP.
    #[default]
    Mlp,
    /// The same MLP over both frames: 1800-256-128-64-2.
    Stacked,
    /// Late fusion: a 900-128 branch per frame, concatenated, then the head 256-128-64-2.
    Late,
    /// The paper's MLP over the `C` pooled channels of a real-valued representation (time
    /// surface, histogram: 2; voxel grid: its bins), side by side: `C x 900`-256-128-64-2.
    Channels(usize),
}

impl Architecture {
    /// The network for `config`'s features: [`Architecture::Stacked`] and
    /// [`Architecture::Late`] for the representations of the same names, the paper's MLP for the
    /// others.
    pub fn for_repr(config: &ReprConfig) -> Self {
        match config {
            ReprConfig::Stacked { .. } => Self::Stacked,
            ReprConfig::Late { .. } => Self::Late,
            ReprConfig::Static(_) | ReprConfig::Dynamic(_) | ReprConfig::Combined { .. } => {
                Self::Mlp
            }
            ReprConfig::TimeSurface(_) | ReprConfig::Histogram(_) | ReprConfig::VoxelGrid(_) => {
                Self::Channels(config.frames())
            }
        }
    }

    /// Its name, as `config.json` spells it (`mlp`, `stacked`, `late`, `channels`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Mlp => "mlp",
            Self::Stacked => "stacked",
            Self::Late => "late",
            Self::Channels(_) => "channels",
        }
    }

    /// Features per sample: 900, 1800 for two frames, `C x 900` for `C` channels.
    pub fn inputs(self) -> usize {
        match self {
            Self::Mlp => INPUTS,
            Self::Stacked | Self::Late => 2 * INPUTS,
            Self::Channels(c) => c * INPUTS,
        }
    }

    /// Whether the architecture is one evtac's kernels run: at most [`MAX_INPUTS`] features
    /// (`Channels` of 1 to [`MAX_FRAMES`]).
    pub fn is_supported(self) -> bool {
        (1..=MAX_INPUTS).contains(&self.inputs())
    }

    /// Whether `self` and `other` are the same network (the same layer sizes and the same
    /// first-layer blocks): a two-channel network and a stacked one are, and a file of weights
    /// does not say which it was trained for.
    pub fn same_network(self, other: Self) -> bool {
        self.layer_sizes() == other.layer_sizes()
            && self.first_layer_blocks() == other.first_layer_blocks()
    }

    /// Layer widths from input to output, as stored (`inputs-256-128-64-2`).
    pub fn layer_sizes(self) -> [usize; LAYERS + 1] {
        [self.inputs(), HIDDEN[0], HIDDEN[1], HIDDEN[2], OUTPUTS]
    }

    /// The inputs that first-layer unit `unit` reads: all of them, or for late fusion its
    /// branch's frame (units below [`BRANCH`] the static frame, the others the dynamic one).
    pub fn first_layer_inputs(self, unit: usize) -> Range<usize> {
        match self {
            Self::Mlp | Self::Stacked | Self::Channels(_) => 0..self.inputs(),
            Self::Late if unit < BRANCH => 0..INPUTS,
            Self::Late => INPUTS..2 * INPUTS,
        }
    }

    /// The first layer's (units, inputs) blocks: which units read which inputs, every weight
    /// outside them zero (one block for the MLPs; late fusion's two branches).
    pub fn first_layer_blocks(self) -> Vec<(Range<usize>, Range<usize>)> {
        match self {
            Self::Mlp | Self::Stacked | Self::Channels(_) => vec![(0..HIDDEN[0], 0..self.inputs())],
            Self::Late => vec![
                (0..BRANCH, 0..INPUTS),
                (BRANCH..HIDDEN[0], INPUTS..2 * INPUTS),
            ],
        }
    }

    /// Whether first-layer weight (`unit`, `input`) is part of the network (late fusion's
    /// cross-branch weights are not: they are zero and stay zero).
    #[inline]
    pub fn connects(self, unit: usize, input: usize) -> bool {
        self != Self::Late || (unit < BRANCH) == (input < INPUTS)
    }

    /// The layer sizes as a text, e.g. `900-256-128-64-2` or
    /// `2x(900-128)-256-128-64-2` for late fusion.
    pub fn describe(self) -> String {
        match self {
            Self::Mlp | Self::Stacked | Self::Channels(_) => {
                let s = self.layer_sizes().map(|w| w.to_string());
                s.join("-")
            }
            Self::Late => format!(
                "2x({INPUTS}-{BRANCH})-{}-{}-{}-{OUTPUTS}",
                HIDDEN[0], HIDDEN[1], HIDDEN[2]
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_repr::{DynamicConfig, StaticConfig};

    #[test]
    fn each_representation_has_its_network() {
        let (static_part, dynamic_part) = (StaticConfig::default(), DynamicConfig::default());
        let cases = [
            (ReprConfig::Static(static_part), Architecture::Mlp, 900),
            (ReprConfig::default(), Architecture::Mlp, 900),
            (
                ReprConfig::Stacked {
                    static_part,
                    dynamic_part,
                },
                Architecture::Stacked,
                1800,
            ),
            (
                ReprConfig::Late {
                    static_part,
                    dynamic_part,
                },
                Architecture::Late,
                1800,
            ),
        ];
        for (config, arch, inputs) in cases {
            assert_eq!(Architecture::for_repr(&config), arch);
            assert_eq!(arch.inputs(), inputs);
            assert_eq!(arch.inputs(), config.frames() * INPUTS);
        }
        assert_eq!(Architecture::Mlp.describe(), "900-256-128-64-2");
        let voxel = ReprConfig::VoxelGrid(evtac_repr::VoxelGridConfig {
            window_ms: 100.0,
            bins: 5,
        });
        let channels = Architecture::for_repr(&voxel);
        assert_eq!(channels, Architecture::Channels(5));
        assert_eq!(channels.describe(), "4500-256-128-64-2");
        assert!(channels.is_supported() && !Architecture::Channels(9).is_supported());
        let histogram = ReprConfig::Histogram(evtac_repr::HistogramConfig { window_ms: 10.0 });
        let two = Architecture::for_repr(&histogram);
        assert!(two.same_network(Architecture::Stacked) && !two.same_network(Architecture::Late));
        let json = serde_json::to_string(&channels).unwrap();
        assert_eq!(json, r#"{"channels":5}"#);
        assert_eq!(
            serde_json::from_str::<Architecture>(&json).unwrap(),
            channels
        );
        assert_eq!(Architecture::Late.describe(), "2x(900-128)-256-128-64-2");
    }

    #[test]
    fn late_fusion_connects_each_branch_to_its_frame_only() {
        let late = Architecture::Late;
        assert_eq!(late.first_layer_inputs(0), 0..900);
        assert_eq!(late.first_layer_inputs(127), 0..900);
        assert_eq!(late.first_layer_inputs(128), 900..1800);
        for unit in [0, 127, 128, 255] {
            for input in [0, 899, 900, 1799] {
                assert_eq!(
                    late.connects(unit, input),
                    late.first_layer_inputs(unit).contains(&input)
                );
                let block = late
                    .first_layer_blocks()
                    .iter()
                    .any(|(units, inputs)| units.contains(&unit) && inputs.contains(&input));
                assert_eq!(block, late.connects(unit, input));
                assert!(Architecture::Stacked.connects(unit, input));
            }
        }
    }
}
