//! The registry: every format family evtac knows, in the order their signatures are tried, and
//! the detection that walks it. A new format is a folder with its reader, writer and
//! `family.rs`, a [`Format`] variant and one line in [`FAMILIES`].

use std::fs::File;
use std::io::Read;
use std::path::Path;

use crate::family::{Family, extension};
use crate::{Error, Format};

/// The families, in the order their signatures are tried: magic numbers first; NeuroTac
/// before NPY (an NPY array of Python objects is a NeuroTac file); the text headers; CSV, known
/// by its extension alone, last.
pub(crate) static FAMILIES: &[&dyn Family] = &[
    &crate::aedat::family::Aedat4,
    &crate::hdf5::family::Hdf5,
    &crate::ros::family::Ros,
    &crate::neurotac::family::Neurotac,
    &crate::npy::family::Npy,
    &crate::aedat_legacy::family::Legacy,
    &crate::evt::family::Evt,
    &crate::csv::family::Csv,
];

/// The family that reads `format`.
pub(crate) fn family(format: Format) -> &'static dyn Family {
    FAMILIES
        .iter()
        .copied()
        .find(|f| f.formats().contains(&format))
        // Every variant of `Format` is some family's (tested below).
        .expect("a Format no family reads")
}

/// Recognises the format of the file at `path`: by its first bytes, else by its extension; a
/// folder by the family that reads folders.
pub(crate) fn detect(path: &Path) -> Result<Format, Error> {
    let io = |error| Error::Io {
        path: path.to_path_buf(),
        error,
    };
    if path.is_dir() {
        return FAMILIES
            .iter()
            .find_map(|f| f.sniff_folder(path))
            .unwrap_or_else(|| {
                Err(Error::UnknownFormat {
                    path: path.to_path_buf(),
                    reason: "a folder, and no format reads folders".into(),
                })
            });
    }
    let mut head = Vec::with_capacity(64);
    File::open(path)
        .map_err(io)?
        .take(4096)
        .read_to_end(&mut head)
        .map_err(io)?;
    if let Some(found) = FAMILIES.iter().find_map(|f| f.sniff(path, &head)) {
        return found;
    }
    Err(unrecognised(path, &head))
}

/// Why the file at `path`, starting with `head`, is no format evtac reads.
fn unrecognised(path: &Path, head: &[u8]) -> Error {
    let extension = extension(path);
    let reason = if head.is_empty() {
        "the file is empty".to_string()
    } else if let Some(signature) = FAMILIES
        .iter()
        .flat_map(|f| f.extensions())
        .find(|e| e.extension == extension)
        .and_then(|e| e.signature)
    {
        let first = String::from_utf8_lossy(&head[..head.len().min(14)]).into_owned();
        format!(
            "the extension says `.{extension}` but the first bytes (at byte offset 0) are \
             {first:?}, not {signature}"
        )
    } else {
        "no AEDAT4, NPY, HDF5, EVT, ROS bag or MCAP signature, and the extension is not .csv \
         (nor .npz for a zip)"
            .to_string()
    };
    Error::UnknownFormat {
        path: path.to_path_buf(),
        reason,
    }
}

/// The format an output path's extension asks for (one a family writes), or why none.
pub(crate) fn for_writing(path: &Path) -> Result<Format, Error> {
    let extension = extension(path);
    let named = FAMILIES.iter().find_map(|family| {
        family
            .extensions()
            .iter()
            .find(|e| e.extension == extension)
            .map(|e| (*family, e.format))
    });
    match named {
        Some((family, format)) if family.writes(format) => Ok(format),
        Some((_, format)) => Err(Error::NotWritable {
            path: path.to_path_buf(),
            format,
        }),
        None => Err(Error::UnknownFormat {
            path: path.to_path_buf(),
            reason: format!("the extension `{extension}` is not .aedat4, .csv or .npy"),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_format_has_one_family() {
        for format in Format::ALL {
            let owners = FAMILIES
                .iter()
                .filter(|f| f.formats().contains(format))
                .count();
            assert_eq!(owners, 1, "{format}");
        }
    }

    #[test]
    fn an_extension_names_one_format() {
        let mut seen = std::collections::HashSet::new();
        for e in FAMILIES.iter().flat_map(|f| f.extensions()) {
            assert!(seen.insert(e.extension), "{}", e.extension);
        }
    }
}
