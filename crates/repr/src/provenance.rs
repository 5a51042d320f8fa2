//! What made a feature matrix, so that a model refuses features it was not trained on.
//!
//! Pooled features are bare float32 columns: combined features fed to a static model have the
//! right shape (900 columns) and give confident, wrong angles (33 deg pitch on a 20 deg trial).
//! So features carry a [`FeatureProvenance`]: the representation with every setting that
//! changes a feature ([`ReprConfig::cache_key`]), the crop they were pooled from, and the
//! no-contact mask (its SHA-256, since the mask is data, not config), and the event filters the
//! recording went through first (their SPECs, in order; left out of the JSON when there are
//! none, so files from before filters read the same). `evtac represent` writes it
//! beside the NPY ([`FeatureProvenance::sidecar`]: `features.npy.json`); the Python package
//! attaches it to the array; `evtac predict` and `Model.predict` compare it with the model's
//! and refuse a mismatch, naming both.

use std::fmt;
use std::path::{Path, PathBuf};

use evtac_events::Resolution;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::{Mask, ReprConfig};

/// The settings, crop and mask a feature matrix was computed with.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct FeatureProvenance {
    /// The representation with every setting that changes a feature
    /// ([`ReprConfig::cache_key`], e.g. `v1_dynamic_win640000us_cnt0`).
    pub representation: String,
    /// The centered crop the features are pooled from (`240x240`).
    pub crop: String,
    /// The no-contact mask's SHA-256 (hex, over its size and pixels), `None` without a mask.
    pub mask: Option<String>,
    /// The event filters applied before the representation, as SPECs in order
    /// (`background-activity=10ms`); empty for unfiltered events.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub filters: Vec<String>,
}

impl FeatureProvenance {
    /// The provenance of features computed with `config` on the centered `crop`, masked with
    /// `mask`.
    pub fn new(config: &ReprConfig, crop: Resolution, mask: Option<&Mask>) -> Self {
        Self {
            representation: config.cache_key(),
            crop: crop.to_string(),
            mask: mask.map(mask_digest),
            filters: Vec::new(),
        }
    }

    /// The same provenance for events that went through `filters` (SPECs, in order) first.
    pub fn with_filters(self, filters: Vec<String>) -> Self {
        Self { filters, ..self }
    }

    /// Where `evtac represent` writes the provenance of the features in `features`: beside it,
    /// with `.json` appended (`features.npy.json`).
    pub fn sidecar(features: &Path) -> PathBuf {
        let mut name = features.file_name().unwrap_or_default().to_os_string();
        name.push(".json");
        features.with_file_name(name)
    }

    /// `None` when features made as `self` are what a model expecting `expected` reads; else
    /// what differs, naming both sides (`representation: the features are ..., the model reads
    /// ...`).
    pub fn mismatch(&self, expected: &Self) -> Option<String> {
        let mut parts = Vec::new();
        if self.representation != expected.representation {
            parts.push(format!(
                "representation: the features are {}, the model reads {}",
                self.representation, expected.representation
            ));
        }
        if self.crop != expected.crop {
            parts.push(format!(
                "crop: the features are pooled from {}, the model's from {}",
                self.crop, expected.crop
            ));
        }
        if self.mask != expected.mask {
            let show = |m: &Option<String>| match m {
                Some(digest) => format!("mask sha256 {}", &digest[..16.min(digest.len())]),
                None => "no mask".to_string(),
            };
            parts.push(format!(
                "mask: the features were made with {}, the model with {}",
                show(&self.mask),
                show(&expected.mask)
            ));
        }
        if self.filters != expected.filters {
            let show = |f: &[String]| match f {
                [] => "no filter".to_string(),
                specs => specs.join(" then "),
            };
            parts.push(format!(
                "filters: the features' events went through {}, the model's through {}",
                show(&self.filters),
                show(&expected.filters)
            ));
        }
        (!parts.is_empty()).then(|| parts.join("; "))
    }
}

impl fmt::Display for FeatureProvenance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} on {}", self.representation, self.crop)?;
        match &self.mask {
            Some(d) => write!(f, ", mask sha256 {}", &d[..16.min(d.len())]),
            None => write!(f, ", no mask"),
        }?;
        if !self.filters.is_empty() {
            write!(f, ", filtered by {}", self.filters.join(" then "))?;
        }
        Ok(())
    }
}

/// SHA-256 over the mask's width, height (little-endian `u16`) and pixels, as hex.
fn mask_digest(mask: &Mask) -> String {
    let size = mask.resolution();
    let mut hash = Sha256::new();
    hash.update(size.width.to_le_bytes());
    hash.update(size.height.to_le_bytes());
    hash.update(mask.pixels());
    hash.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CROP, DynamicConfig, StaticConfig};

    #[test]
    fn the_same_settings_match_and_every_difference_is_named() {
        let static_ = ReprConfig::Static(StaticConfig::default());
        let combined = ReprConfig::Combined {
            static_part: StaticConfig::default(),
            dynamic_part: DynamicConfig::default(),
        };
        let mut pixels = vec![0u8; 240 * 240];
        let a = FeatureProvenance::new(&static_, CROP, None);
        assert_eq!(a.mismatch(&a.clone()), None);
        let b = FeatureProvenance::new(&combined, CROP, None);
        let why = b.mismatch(&a).unwrap();
        assert!(why.contains("the features are v1_combined_"), "{why}");
        assert!(why.contains("the model reads v1_static_"), "{why}");
        pixels[7] = 1;
        let mask = Mask::from_pixels(CROP, &pixels).unwrap();
        let masked = FeatureProvenance::new(&static_, CROP, Some(&mask));
        let why = a.mismatch(&masked).unwrap();
        assert!(
            why.starts_with("mask: the features were made with no mask"),
            "{why}"
        );
        pixels[7] = 0;
        pixels[8] = 1;
        let other = Mask::from_pixels(CROP, &pixels).unwrap();
        assert!(
            masked
                .mismatch(&FeatureProvenance::new(&static_, CROP, Some(&other)))
                .is_some()
        );
        let small = FeatureProvenance::new(&static_, Resolution::new(160, 160), None);
        assert!(small.mismatch(&a).unwrap().contains("pooled from 160x160"));
        let filtered = a
            .clone()
            .with_filters(vec!["background-activity=10ms".into()]);
        let why = filtered.mismatch(&a).unwrap();
        assert_eq!(
            why,
            "filters: the features' events went through background-activity=10ms, the model's \
             through no filter"
        );
    }

    #[test]
    fn unfiltered_provenance_reads_and_writes_as_before_filters() {
        let a = FeatureProvenance::new(&ReprConfig::Static(StaticConfig::default()), CROP, None);
        let json = serde_json::to_string(&a).unwrap();
        assert!(!json.contains("filters"), "{json}");
        let old = r#"{"representation":"x","crop":"240x240","mask":null}"#;
        let read: FeatureProvenance = serde_json::from_str(old).unwrap();
        assert!(read.filters.is_empty());
        let filtered = a.with_filters(vec!["polarity=on".into()]);
        let back: FeatureProvenance =
            serde_json::from_str(&serde_json::to_string(&filtered).unwrap()).unwrap();
        assert_eq!(back, filtered);
    }

    #[test]
    fn the_sidecar_is_beside_the_features() {
        assert_eq!(
            FeatureProvenance::sidecar(Path::new("out/f.npy")),
            PathBuf::from("out/f.npy.json")
        );
    }
}
