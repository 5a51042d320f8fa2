//! The phrase naming every recording format evtac reads, for the help texts that list them.
//!
//! One phrase, so that a format the readers learn (`evtac_formats::Format`) is added to every
//! command's help at once instead of leaving some of them stale.

/// The formats `evtac_formats::open` reads, as help texts name them.
///
/// A macro rather than a `const`: clap's `help = ...` attributes are built with `concat!`, which
/// takes literals and macros expanding to them, but not constants.
macro_rules! readable_formats {
    () => {
        "AEDAT 4.0, 3.1 or 2.0, EVT 2.0/2.1/3.0 raw, CSV, NPY, NPZ, HDF5, the NeuroTac lab's \
         pickles, ROS 1 bags or ROS 2 MCAP"
    };
}
pub(crate) use readable_formats;

#[cfg(test)]
mod tests {
    use evtac_formats::Format;

    /// Each format the readers know, by a word the phrase must hold for it.
    fn named_in_phrase(format: Format) -> &'static str {
        // A match without a wildcard: a new format fails to compile here until it is named.
        match format {
            Format::Aedat4 => "AEDAT 4.0",
            Format::Aedat31 => "3.1",
            Format::Aedat2 => "2.0,",
            Format::Evt2 => "EVT 2.0",
            Format::Evt21 => "2.1",
            Format::Evt3 => "3.0 raw",
            Format::Csv => "CSV",
            Format::Npy => "NPY",
            Format::Npz => "NPZ",
            Format::Hdf5 => "HDF5",
            Format::Neurotac => "NeuroTac",
            Format::RosBag => "ROS 1 bags",
            Format::Mcap => "ROS 2 MCAP",
        }
    }

    #[test]
    fn the_phrase_names_every_readable_format() {
        let phrase = readable_formats!();
        for format in [
            Format::Aedat4,
            Format::Aedat31,
            Format::Aedat2,
            Format::Evt2,
            Format::Evt21,
            Format::Evt3,
            Format::Csv,
            Format::Npy,
            Format::Npz,
            Format::Hdf5,
            Format::Neurotac,
            Format::RosBag,
            Format::Mcap,
        ] {
            let word = named_in_phrase(format);
            assert!(
                phrase.contains(word),
                "{word:?} ({}) missing",
                format.name()
            );
        }
    }
}
