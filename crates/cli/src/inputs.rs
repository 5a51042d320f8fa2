//! `--identity-calibration` and `--no-mask`: the explicit opt-outs of a dataset's
//! `calibration.json` and `no_contact.aedat4`, flattened into each command that opens a dataset
//! (`evtac_import::inputs` says why they are not silent fallbacks), with `--filter SPEC`: the
//! event filters every recording of the dataset goes through before the representations.

use evtac_import::inputs::{IDENTITY_CALIBRATION_FLAG, Inputs, MaskSource, NO_MASK_FLAG};
use evtac_labels::CalibrationSource;

/// The opt-out flags.
#[derive(Debug, Clone, clap::Args)]
pub struct InputArgs {
    /// Use the identity IMU-to-sensor rotation instead of the dataset's calibration.json (which
    /// may then be absent). Only right when the IMU's axes are the sensor's.
    #[arg(long = IDENTITY_CALIBRATION_FLAG)]
    pub identity_calibration: bool,
    /// Build the static representation without a no-contact mask instead of from the dataset's
    /// no_contact.aedat4 (which may then be absent).
    #[arg(long = NO_MASK_FLAG)]
    pub no_mask: bool,
    // Every recording of the dataset (its trials and no_contact.aedat4) goes through these on
    // the full sensor before the crop; the features are cached apart from unfiltered ones and
    // a model records them.
    #[command(flatten)]
    pub filter: crate::filtering::FilterArgs,
}

impl InputArgs {
    /// These flags as command-line words (`--identity-calibration`, `--no-mask`).
    pub fn words(&self) -> Vec<String> {
        let mut flags = Vec::new();
        if self.identity_calibration {
            flags.push(format!("--{IDENTITY_CALIBRATION_FLAG}"));
        }
        if self.no_mask {
            flags.push(format!("--{NO_MASK_FLAG}"));
        }
        for spec in &self.filter.filters {
            flags.extend(["--filter".to_string(), spec.to_string()]);
        }
        flags
    }

    /// The flags that ask for `inputs`.
    pub fn of(inputs: &Inputs) -> InputArgs {
        InputArgs {
            identity_calibration: inputs.calibration == CalibrationSource::Identity,
            no_mask: inputs.mask == MaskSource::Unmasked,
            filter: crate::filtering::FilterArgs {
                filters: inputs.filters.clone(),
            },
        }
    }

    /// The inputs these flags ask for.
    pub fn inputs(&self) -> Inputs {
        Inputs::from_flags(self.identity_calibration, self.no_mask)
            .with_filters(self.filter.filters.clone())
    }
}
