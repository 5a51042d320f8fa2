//! Binary frames and how they combine: the static threshold rule ([`StaticThreshold`]), the
//! dynamic count rule, and the pixel-wise OR of the combined representation, as per-pixel
//! functions (what the streaming [`crate::FeatureExtractor`] applies at each flip) and as
//! straightforward whole-frame functions (what the tests and one-shot users call).

use crate::accumulator::FrameMap;
use crate::config::{Comparison, DynamicConfig, StaticConfig, ThresholdSpace};
use crate::mask::Mask;

/// The static binarization rule of one [`StaticConfig`], precomputed: a pixel is set when it is
/// not masked and its value (potential, or 8-bit frame value) compares above
/// `threshold * eta` (mapped to the 8-bit scale, unrounded, in [`ThresholdSpace::U8`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticThreshold {
    space: ThresholdSpace,
    comparison: Comparison,
    map: FrameMap,
    /// The threshold in the space's units.
    value: f32,
}

impl StaticThreshold {
    /// The rule of `config`.
    pub fn new(config: &StaticConfig) -> Self {
        let map = FrameMap::new(config.min_potential, config.max_potential);
        let potential = config.threshold * config.eta;
        let value = match config.threshold_space {
            ThresholdSpace::Potential => potential,
            ThresholdSpace::U8 => map.scaled(potential),
        };
        Self {
            space: config.threshold_space,
            comparison: config.comparison,
            map,
            value,
        }
    }

    /// The threshold in the space's units (a potential, or a value on the 0..255 scale).
    pub fn value(&self) -> f32 {
        self.value
    }

    /// Whether a pixel of potential `v` is set (before masking).
    #[inline]
    pub fn is_set(&self, v: f32) -> bool {
        let x = match self.space {
            ThresholdSpace::Potential => v,
            ThresholdSpace::U8 => f32::from(self.map.value(v)),
        };
        match self.comparison {
            Comparison::Gt => x > self.value,
            Comparison::Ge => x >= self.value,
        }
    }
}

/// Whether a pixel with `count` events in the window is set: `count > count_threshold`.
#[inline]
pub fn dynamic_is_set(config: &DynamicConfig, count: u32) -> bool {
    count > config.count_threshold
}

/// The static binary frame (0/1) of a potential surface: threshold, then zero masked pixels.
pub fn static_frame(config: &StaticConfig, potentials: &[f32], mask: Option<&Mask>) -> Vec<u8> {
    let rule = StaticThreshold::new(config);
    potentials
        .iter()
        .enumerate()
        .map(|(p, &v)| u8::from(rule.is_set(v) && !mask.is_some_and(|m| m.is_masked(p))))
        .collect()
}

/// The dynamic binary frame (0/1) of window counts.
pub fn dynamic_frame(config: &DynamicConfig, counts: &[u32]) -> Vec<u8> {
    counts
        .iter()
        .map(|&c| u8::from(dynamic_is_set(config, c)))
        .collect()
}

/// The combined frame: pixel-wise OR of two binary frames of equal length (0/1 out).
pub fn or_frames(a: &[u8], b: &[u8]) -> Vec<u8> {
    a.iter()
        .zip(b)
        .map(|(&x, &y)| u8::from(x != 0 || y != 0))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_rule_needs_more_than_two_contributions() {
        let rule = StaticThreshold::new(&StaticConfig::default());
        assert!(!rule.is_set(0.3));
        assert!(rule.is_set(0.30001));
        let ge = StaticThreshold::new(&StaticConfig {
            comparison: Comparison::Ge,
            ..StaticConfig::default()
        });
        assert!(ge.is_set(0.3));
    }

    #[test]
    fn u8_rule_thresholds_at_76_5() {
        let rule = StaticThreshold::new(&StaticConfig {
            threshold_space: ThresholdSpace::U8,
            ..StaticConfig::default()
        });
        assert_eq!(rule.value(), 76.5);
        // 0.3 maps to 76.5, rounds to 76 (ties to even): not set even though 0.3 >= 2 * eta.
        assert!(!rule.is_set(0.3));
        assert!(rule.is_set(0.302));
    }

    #[test]
    fn or_is_pixelwise() {
        assert_eq!(or_frames(&[0, 1, 0, 1], &[0, 0, 1, 1]), [0, 1, 1, 1]);
    }
}
