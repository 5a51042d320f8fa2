//! Where a dataset's calibration and no-contact mask come from. Both files are required: a
//! dataset without `calibration.json` or `no_contact.aedat4` is refused unless the caller opts out
//! explicitly (`--identity-calibration`, `--no-mask`), because running a real sensor's data with
//! the identity rotation or without a mask changes the labels and the static features without a
//! word. The report states which were used (`evtac_experiments::results::RunInfo`). The event
//! filters every recording of the dataset goes through are part of the same record: they
//! change what every representation sees, so they travel with the dataset wherever it is opened
//! (a training job, a cache key, a model bundle's provenance).

use evtac_labels::CalibrationSource;
use serde::{Deserialize, Serialize};

pub use evtac_labels::dataset::IDENTITY_CALIBRATION_FLAG;

/// The command-line flag (without its dashes) that runs without the no-contact mask; errors
/// about a missing `no_contact.aedat4` name it.
pub const NO_MASK_FLAG: &str = "no-mask";

/// Where the static representation's mask comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MaskSource {
    /// Built from the dataset's `no_contact.aedat4`, which must exist.
    NoContact,
    /// No mask, asked for explicitly.
    Unmasked,
}

/// The calibration, mask and event filters a dataset is opened with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Inputs {
    /// The IMU-to-sensor rotation.
    pub calibration: CalibrationSource,
    /// The no-contact mask.
    pub mask: MaskSource,
    /// The event filters every recording of the dataset (its trials and its no-contact
    /// recording) goes through on the full sensor, before the crop, in order. Absent from
    /// files written before filters: none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub filters: Vec<evtac_filters::FilterSpec>,
}

impl Inputs {
    /// Both from the dataset's files (what simulated datasets have), no filter.
    pub const FROM_FILES: Inputs = Inputs {
        calibration: CalibrationSource::File,
        mask: MaskSource::NoContact,
        filters: Vec::new(),
    };

    /// These inputs with the recordings through `filters`.
    pub fn with_filters(self, filters: Vec<evtac_filters::FilterSpec>) -> Inputs {
        Inputs { filters, ..self }
    }

    /// The filters in words, for the report: the SPECs in order, or `none`.
    pub fn filters_text(&self) -> String {
        if self.filters.is_empty() {
            return "none".to_string();
        }
        let specs: Vec<String> = self.filters.iter().map(|f| format!("`{f}`")).collect();
        specs.join(", ")
    }

    /// The inputs the two opt-out flags ask for.
    pub fn from_flags(identity_calibration: bool, no_mask: bool) -> Inputs {
        Inputs {
            calibration: if identity_calibration {
                CalibrationSource::Identity
            } else {
                CalibrationSource::File
            },
            mask: if no_mask {
                MaskSource::Unmasked
            } else {
                MaskSource::NoContact
            },
            filters: Vec::new(),
        }
    }

    /// The calibration in words, for the report.
    pub fn calibration_text(&self) -> String {
        match self.calibration {
            CalibrationSource::File => evtac_events::layout::CALIBRATION_FILE.to_string(),
            CalibrationSource::Identity => {
                format!("identity (--{IDENTITY_CALIBRATION_FLAG})")
            }
        }
    }

    /// The mask in words, for the report.
    pub fn mask_text(&self) -> String {
        match self.mask {
            MaskSource::NoContact => evtac_events::layout::NO_CONTACT_FILE.to_string(),
            MaskSource::Unmasked => format!("none (--{NO_MASK_FLAG})"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_flag_opts_out_of_its_own_input() {
        for (c, m) in [(false, false), (true, false), (false, true), (true, true)] {
            let inputs = Inputs::from_flags(c, m);
            assert_eq!(inputs.calibration == CalibrationSource::Identity, c);
            assert_eq!(inputs.mask == MaskSource::Unmasked, m);
        }
        assert_eq!(Inputs::from_flags(false, false), Inputs::FROM_FILES);
    }

    #[test]
    fn texts_name_the_file_or_the_flag() {
        assert_eq!(Inputs::FROM_FILES.calibration_text(), "calibration.json");
        assert_eq!(Inputs::FROM_FILES.mask_text(), "no_contact.aedat4");
        let out = Inputs::from_flags(true, true);
        assert!(out.calibration_text().contains("--identity-calibration"));
        assert!(out.mask_text().contains("--no-mask"));
        assert_eq!(Inputs::FROM_FILES.filters_text(), "none");
        let filtered =
            Inputs::FROM_FILES.with_filters(vec!["background-activity=10ms".parse().unwrap()]);
        assert_eq!(filtered.filters_text(), "`background-activity=10ms`");
    }

    #[test]
    fn filters_are_absent_from_the_json_when_there_are_none() {
        let plain = serde_json::to_string(&Inputs::FROM_FILES).unwrap();
        assert!(!plain.contains("filters"), "{plain}");
        let filtered = Inputs::FROM_FILES.with_filters(vec!["polarity=on".parse().unwrap()]);
        let json = serde_json::to_string(&filtered).unwrap();
        assert!(json.ends_with(r#","filters":["polarity=on"]}"#), "{json}");
        assert_eq!(serde_json::from_str::<Inputs>(&json).unwrap(), filtered);
        assert_eq!(
            serde_json::from_str::<Inputs>(&plain).unwrap(),
            Inputs::FROM_FILES
        );
    }
}
