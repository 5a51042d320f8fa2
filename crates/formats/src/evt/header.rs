//! The `%` text header that Prophesee tools write before EVT 2.0 / 2.1 / 3.0 data.
//!
//! Each line is `% key value`; the header ends at `% end` or at the first line that does not
//! start with `%`. The version comes from `% evt 3.0` (older files) or
//! `% format EVT3;height=720;width=1280` (newer ones; EVT 2.1 is `% format EVT21`, and its
//! `endianness=legacy` variant, with the two 32-bit halves of each word swapped, is refused); the resolution from the `format` options,
//! `% geometry 1280x720`, or, for older files that carry neither (such as our Gen3 and Gen4.1
//! fixtures), from the sensor named by `% sensor_generation` or `% plugin_name`.

use crate::Resolution;

/// The EVT encodings evtac decodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EvtVersion {
    /// EVT 2.0: 32-bit words, one event per word.
    Evt2,
    /// EVT 2.1: 64-bit words, each up to 32 events of one row (a validity mask).
    Evt21,
    /// EVT 3.0: 16-bit words, stateful and vectorised.
    Evt3,
}

impl EvtVersion {
    /// Size of one raw word in bytes.
    pub const fn word_size(self) -> usize {
        match self {
            Self::Evt2 => 4,
            Self::Evt21 => 8,
            Self::Evt3 => 2,
        }
    }
}

impl std::fmt::Display for EvtVersion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Evt2 => "EVT 2.0",
            Self::Evt21 => "EVT 2.1",
            Self::Evt3 => "EVT 3.0",
        })
    }
}

/// A parsed EVT text header.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header {
    /// The encoding of the data that follows.
    pub version: EvtVersion,
    /// The sensor size, when the header states it or names a known sensor.
    pub resolution: Option<Resolution>,
    /// Every `% key value` line, in file order (`value` may be empty).
    pub fields: Vec<(String, String)>,
    /// Length of the header in bytes: the offset of the first data byte.
    pub len: u64,
}

impl Header {
    /// The value of the first field named `key`.
    pub fn field(&self, key: &str) -> Option<&str> {
        self.fields
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// A short name of the camera that recorded the file (plugin or integrator, and serial
    /// number), when the header says.
    pub fn source(&self) -> Option<String> {
        let camera = self
            .field("plugin_name")
            .or_else(|| self.field("camera_integrator_name"))
            .or_else(|| self.field("integrator_name"))
            .filter(|v| !v.is_empty());
        let serial = self.field("serial_number").filter(|v| !v.is_empty());
        match (camera, serial) {
            (Some(c), Some(s)) => Some(format!("{c} {s}")),
            (Some(c), None) => Some(c.to_string()),
            (None, Some(s)) => Some(s.to_string()),
            (None, None) => None,
        }
    }
}

/// Why a header could not be understood.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum HeaderError {
    /// Neither `% evt` nor `% format` names the encoding.
    #[error("the header has no `% evt` or `% format` field, so the EVT version is unknown")]
    MissingVersion,
    /// The version field names an encoding evtac does not decode.
    #[error(
        "header field `{field}` names `{value}`; evtac reads EVT 2.0, EVT 2.1 (little-endian) \
         and EVT 3.0 only"
    )]
    UnsupportedVersion {
        /// The field (`evt` or `format`).
        field: &'static str,
        /// Its value.
        value: String,
    },
    /// A size field is not a valid resolution.
    #[error("header field `{field}` = `{value}` is not a valid sensor size")]
    BadResolution {
        /// The field (`geometry`, `format`).
        field: &'static str,
        /// Its value.
        value: String,
    },
}

/// Parses the header lines (each without its leading `%` and line break).
pub(crate) fn parse_fields(fields: Vec<(String, String)>, len: u64) -> Result<Header, HeaderError> {
    let mut version = None;
    let mut resolution = None;
    // `format` (newer) takes precedence over `evt` and `geometry` (older), whatever the order.
    if let Some((_, value)) = fields.iter().find(|(k, _)| k == "format") {
        let mut parts = value.split(';');
        let name = parts.next().unwrap_or("").trim();
        version = Some(match name.to_ascii_uppercase().as_str() {
            "EVT2" | "EVT20" | "EVT2.0" => EvtVersion::Evt2,
            "EVT21" | "EVT2.1" => EvtVersion::Evt21,
            "EVT3" | "EVT30" | "EVT3.0" => EvtVersion::Evt3,
            _ => {
                return Err(HeaderError::UnsupportedVersion {
                    field: "format",
                    value: value.clone(),
                });
            }
        });
        let (mut width, mut height) = (None, None);
        for option in parts {
            let bad = || HeaderError::BadResolution {
                field: "format",
                value: value.clone(),
            };
            match option.split_once('=').map(|(k, v)| (k.trim(), v.trim())) {
                Some(("width", v)) => width = Some(v.parse::<u16>().map_err(|_| bad())?),
                Some(("height", v)) => height = Some(v.parse::<u16>().map_err(|_| bad())?),
                // Legacy EVT 2.1 swaps the two 32-bit halves of each word: not decoded.
                Some(("endianness", v)) if !v.eq_ignore_ascii_case("little") => {
                    return Err(HeaderError::UnsupportedVersion {
                        field: "format",
                        value: value.clone(),
                    });
                }
                _ => {}
            }
        }
        match (width, height) {
            (Some(w), Some(h)) if w > 0 && h > 0 => resolution = Some(Resolution::new(w, h)),
            (None, None) => {}
            _ => {
                return Err(HeaderError::BadResolution {
                    field: "format",
                    value: value.clone(),
                });
            }
        }
    }
    if version.is_none()
        && let Some((_, value)) = fields.iter().find(|(k, _)| k == "evt")
    {
        version = Some(match value.trim() {
            "2" | "2.0" => EvtVersion::Evt2,
            "2.1" => EvtVersion::Evt21,
            "3" | "3.0" => EvtVersion::Evt3,
            _ => {
                return Err(HeaderError::UnsupportedVersion {
                    field: "evt",
                    value: value.clone(),
                });
            }
        });
    }
    if resolution.is_none()
        && let Some((_, value)) = fields.iter().find(|(k, _)| k == "geometry")
    {
        resolution =
            Some(
                value
                    .trim()
                    .parse::<Resolution>()
                    .map_err(|_| HeaderError::BadResolution {
                        field: "geometry",
                        value: value.clone(),
                    })?,
            );
    }
    if resolution.is_none() {
        resolution = known_sensor(&fields);
    }
    Ok(Header {
        version: version.ok_or(HeaderError::MissingVersion)?,
        resolution,
        fields,
        len,
    })
}

/// The size of a sensor named by an older header that states no geometry. Metavision itself
/// derives the geometry from the camera plugin in that case; this table covers the sensors whose
/// plugins write such headers.
fn known_sensor(fields: &[(String, String)]) -> Option<Resolution> {
    let get = |key: &str| {
        fields
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.trim().to_ascii_lowercase())
    };
    if let Some(generation) = get("sensor_generation") {
        match generation.as_str() {
            "3" | "3.0" | "3.1" => return Some(Resolution::new(640, 480)),
            "4" | "4.0" | "4.1" => return Some(Resolution::new(1280, 720)),
            _ => {}
        }
    }
    let plugin = get("plugin_name")?;
    if plugin.contains("genx320") {
        Some(Resolution::new(320, 320))
    } else if plugin.contains("gen3") {
        Some(Resolution::new(640, 480))
    } else if plugin.contains("gen4") || plugin.contains("imx636") {
        Some(Resolution::new(1280, 720))
    } else {
        None
    }
}

/// Splits one header line (after its `%`) into key and value.
pub(crate) fn split_line(line: &[u8]) -> (String, String) {
    let text = String::from_utf8_lossy(line);
    let text = text.trim();
    match text.split_once(char::is_whitespace) {
        Some((k, v)) => (k.to_string(), v.trim().to_string()),
        None => (text.to_string(), String::new()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fields(lines: &[&str]) -> Vec<(String, String)> {
        lines.iter().map(|l| split_line(l.as_bytes())).collect()
    }

    #[test]
    fn newer_format_line_gives_version_and_size() {
        let h = parse_fields(fields(&[" format EVT3;height=720;width=1280", " end"]), 10).unwrap();
        assert_eq!(h.version, EvtVersion::Evt3);
        assert_eq!(h.resolution, Some(Resolution::new(1280, 720)));
    }

    #[test]
    fn older_evt_and_geometry_lines() {
        let h = parse_fields(fields(&[" evt 2.0", " geometry 640x480"]), 0).unwrap();
        assert_eq!(h.version, EvtVersion::Evt2);
        assert_eq!(h.resolution, Some(Resolution::new(640, 480)));
    }

    #[test]
    fn plugin_name_gives_size_when_nothing_else_does() {
        let h = parse_fields(
            fields(&[
                " evt 3.0",
                " plugin_name hal_plugin_gen41_evk3",
                " serial_number 7",
            ]),
            0,
        )
        .unwrap();
        assert_eq!(h.resolution, Some(Resolution::new(1280, 720)));
        assert_eq!(h.source().as_deref(), Some("hal_plugin_gen41_evk3 7"));
    }

    #[test]
    fn bad_fields_are_named() {
        assert_eq!(
            parse_fields(fields(&[" Date today"]), 0),
            Err(HeaderError::MissingVersion)
        );
        let err = parse_fields(fields(&[" evt 4.0"]), 0).unwrap_err();
        assert!(err.to_string().contains("`evt`"), "{err}");
        let err = parse_fields(fields(&[" evt 3.0", " geometry 12"]), 0).unwrap_err();
        assert!(err.to_string().contains("`geometry`"), "{err}");
        let err = parse_fields(fields(&[" format EVT3;width=12"]), 0).unwrap_err();
        assert!(err.to_string().contains("`format`"), "{err}");
        let header = parse_fields(fields(&[" evt 2.1", " geometry 64x32"]), 0).unwrap();
        assert_eq!(header.version, EvtVersion::Evt21);
    }
}
