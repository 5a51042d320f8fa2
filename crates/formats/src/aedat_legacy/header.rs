//! The `#` text header of AEDAT 2.0 and 3.1 files.
//!
//! The first line names the version (`#!AER-DAT2.0`, `#!AER-DAT3.1`). AEDAT 2.0 (jAER) headers
//! end at the first line that does not start with `#`, and name the camera class on a line
//! `# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C`; AEDAT 3.1 (cAER) headers end with
//! `#!END-HEADER`, name the data encoding on `#Format: RAW` and each camera on
//! `#Source 1: DAVIS240C`. Lines end with CR LF (a lone LF is accepted too).

use super::LegacyError;
use crate::Resolution;

/// The AEDAT versions this module reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Version {
    /// AEDAT 2.0 (jAER): big-endian address / timestamp records.
    Aedat2,
    /// AEDAT 3.1 (cAER): little-endian typed event packets.
    Aedat31,
}

impl Version {
    /// The version as the first line writes it after `#!AER-DAT`.
    pub fn number(self) -> &'static str {
        match self {
            Self::Aedat2 => "2.0",
            Self::Aedat31 => "3.1",
        }
    }
}

impl std::fmt::Display for Version {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Aedat2 => "AEDAT 2.0",
            Self::Aedat31 => "AEDAT 3.1",
        })
    }
}

/// A parsed AEDAT 2.0 / 3.1 header.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header {
    /// The version from the first line.
    pub version: Version,
    /// The camera the header names (`# AEChip:` class, or the first `#Source` of AEDAT 3.1).
    pub camera: Option<String>,
    /// The sensor size of that camera, when evtac knows it. AEDAT 2.0 files that name no camera
    /// are taken to be from a DAVIS240 (the first NeuroTac's camera).
    pub resolution: Option<Resolution>,
    /// Every header line without its `#` and line break, in file order.
    pub lines: Vec<String>,
    /// Length of the header in bytes: the offset of the first data byte.
    pub len: u64,
}

/// Whether `head` (the first bytes of a file) starts like an AEDAT 2.0 / 3.1 header, and which.
pub fn sniff(head: &[u8]) -> Option<Result<Version, String>> {
    let rest = head.strip_prefix(b"#!AER-DAT")?;
    let end = rest
        .iter()
        .position(|&b| b == b'\r' || b == b'\n')
        .unwrap_or(rest.len().min(16));
    let version = String::from_utf8_lossy(&rest[..end]).trim().to_string();
    Some(match version.as_str() {
        "2.0" => Ok(Version::Aedat2),
        "3.1" => Ok(Version::Aedat31),
        _ => Err(version),
    })
}

/// The sensor size of a camera named by a header (DAVIS240A/B/C, DAVIS346, DVS128).
fn known_camera(name: &str) -> Option<Resolution> {
    let name = name.to_ascii_lowercase();
    if name.contains("davis240") {
        Some(Resolution::new(240, 180))
    } else if name.contains("davis346") {
        Some(Resolution::new(346, 260))
    } else if name.contains("dvs128") {
        Some(Resolution::new(128, 128))
    } else {
        None
    }
}

/// Parses the header lines (each without its `#` and line break); `len` is the header's size.
pub(crate) fn parse(lines: Vec<String>, len: u64) -> Result<Header, LegacyError> {
    let first = lines.first().map(|l| format!("#{l}")).unwrap_or_default();
    let version = match sniff(first.as_bytes()) {
        None => return Err(LegacyError::NotAedat),
        Some(Err(version)) => return Err(LegacyError::UnsupportedVersion { version }),
        Some(Ok(v)) => v,
    };
    // `sniff` reads up to the first line break; the version line must hold nothing more (a
    // damaged line break would otherwise swallow the next header line unnoticed).
    let written = first["#!AER-DAT".len()..].trim();
    if written != version.number() {
        return Err(LegacyError::UnsupportedVersion {
            version: written.escape_debug().to_string(),
        });
    }
    // The first line with `key:`, as (1-based line number, trimmed value).
    let value = |key: &str| {
        lines.iter().enumerate().find_map(|(i, l)| {
            let (k, v) = l.split_once(':')?;
            (k.trim() == key).then(|| (i + 1, v.trim().to_string()))
        })
    };
    let (camera, resolution) = match version {
        Version::Aedat2 => {
            let camera = value("AEChip");
            let resolution = match &camera {
                None => Resolution::new(240, 180),
                Some((line, chip)) => match known_camera(chip) {
                    Some(r) if !chip.to_ascii_lowercase().contains("dvs128") => r,
                    _ => {
                        return Err(LegacyError::UnsupportedChip {
                            line: *line,
                            chip: chip.clone(),
                        });
                    }
                },
            };
            (camera.map(|(_, chip)| chip), Some(resolution))
        }
        Version::Aedat31 => {
            if lines.last().is_none_or(|l| l != "!END-HEADER") {
                return Err(LegacyError::TruncatedHeader { offset: len });
            }
            match value("Format") {
                Some((_, f)) if f.eq_ignore_ascii_case("RAW") => {}
                None => {}
                Some((line, value)) => return Err(LegacyError::UnsupportedFormat { line, value }),
            }
            let camera = lines.iter().find_map(|l| {
                let (k, v) = l.split_once(':')?;
                k.trim()
                    .starts_with("Source ")
                    .then(|| v.trim().to_string())
            });
            let resolution = camera.as_deref().and_then(known_camera);
            (camera, resolution)
        }
    };
    Ok(Header {
        version,
        camera,
        resolution,
        lines,
        len,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(ls: &[&str]) -> Vec<String> {
        ls.iter().map(|l| l.to_string()).collect()
    }

    #[test]
    fn versions_cameras_and_sizes() {
        let h = parse(lines(&["!AER-DAT2.0", " AEChip: ch.DAVIS346B"]), 10).unwrap();
        assert_eq!(h.version, Version::Aedat2);
        assert_eq!(h.resolution, Some(Resolution::new(346, 260)));
        let h = parse(lines(&["!AER-DAT2.0", " a comment"]), 10).unwrap();
        assert_eq!(
            (h.camera, h.resolution),
            (None, Some(Resolution::new(240, 180)))
        );
        let h = parse(
            lines(&[
                "!AER-DAT3.1",
                "Format: RAW",
                "Source 1: DAVIS240C",
                "!END-HEADER",
            ]),
            10,
        )
        .unwrap();
        assert_eq!(h.camera.as_deref(), Some("DAVIS240C"));
        assert_eq!(h.resolution, Some(Resolution::new(240, 180)));
        let h = parse(lines(&["!AER-DAT3.1", "Source 2: Foo", "!END-HEADER"]), 1).unwrap();
        assert_eq!(h.resolution, None);
    }

    #[test]
    fn bad_headers_are_named() {
        let err = |ls: &[&str]| parse(lines(ls), 5).unwrap_err().to_string();
        assert!(err(&["!AER-DAT1.0"]).contains("`1.0`"));
        assert!(err(&["hello"]).contains("#!AER-DAT"));
        assert!(
            err(&[
                "!AER-DAT2.0",
                " AEChip: ch.unizh.ini.jaer.chip.retina.DVS128"
            ])
            .contains("DVS128")
        );
        assert!(
            err(&["!AER-DAT3.1", "Format: SerializedTS", "!END-HEADER"]).contains("SerializedTS")
        );
        assert!(err(&["!AER-DAT3.1", "Source 1: DAVIS240C"]).contains("cut off at byte 5"));
        // A line break damaged into another byte joins two lines: the version line says more.
        assert!(err(&["!AER-DAT3.1\r\u{f5}Format: RAW", "!END-HEADER"]).contains("line 1"));
        assert!(err(&["!AER-DAT3.1", "Format: LZ4", "!END-HEADER"]).contains("line 2"));
    }
}
