//! Where a dataset's calibration and no-contact mask come from. Both files are required: a
//! dataset without `calibration.json` or `no_contact.aedat4` is refused unless the caller opts out
//! explicitly (`--identity-calibration`, `--no-mask`), because running a real sensor's data with
//! the identity rotation or without a mask changes the labels and the static features without a
//! word. The report states which were used (`evtac_experiments::results::RunInfo`).

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

/// The calibration and mask a dataset is opened with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Inputs {
    /// The IMU-to-sensor rotation.
    pub calibration: CalibrationSource,
    /// The no-contact mask.
    pub mask: MaskSource,
}

impl Inputs {
    /// Both from the dataset's files (what simulated datasets have).
    pub const FROM_FILES: Inputs = Inputs {
        calibration: CalibrationSource::File,
        mask: MaskSource::NoContact,
    };

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
    }
}
