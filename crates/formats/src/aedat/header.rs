//! The AEDAT 4.0 header: the file magic, the size-prefixed `IOHeader` flatbuffer and the XML
//! stream description (`infoNode`) it carries.
//!
//! The XML is DV's configuration-tree dump: `<dv version="2.0">` holds a node `outInfo` with one
//! child node per stream, named by the stream id, whose `<attr>` children give `typeIdentifier`,
//! `compression`, `originalOutputName`, ... and whose child node `info` gives `source`, `sizeX`,
//! `sizeY`.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use quick_xml::events::Event as XmlEvent;

use super::error::{AedatError, Result};
use super::schema;
use crate::Resolution;

/// The 14 bytes every AEDAT 4.0 file starts with.
pub const MAGIC: &[u8; 14] = b"#!AER-DAT4.0\r\n";

/// Packet compression, as the `IOHeader` declares it for the whole file or stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[non_exhaustive]
pub enum Compression {
    /// Uncompressed packets.
    #[default]
    None,
    /// LZ4 frame format, fast setting.
    Lz4,
    /// LZ4 frame format, high-compression setting. The bytes are plain LZ4 frames; our writer
    /// produces them with the fast compressor (lz4_flex has no high-compression mode).
    Lz4High,
    /// Zstandard, fast setting.
    Zstd,
    /// Zstandard, high-compression setting.
    ZstdHigh,
}

impl Compression {
    /// The `CompressionType` value stored in the `IOHeader`.
    pub const fn to_raw(self) -> i32 {
        match self {
            Self::None => 0,
            Self::Lz4 => 1,
            Self::Lz4High => 2,
            Self::Zstd => 3,
            Self::ZstdHigh => 4,
        }
    }

    /// The compression for a raw `CompressionType` value.
    pub fn from_raw(value: i32) -> Result<Self> {
        Ok(match value {
            0 => Self::None,
            1 => Self::Lz4,
            2 => Self::Lz4High,
            3 => Self::Zstd,
            4 => Self::ZstdHigh,
            _ => return Err(AedatError::UnknownCompression { value }),
        })
    }

    /// The name DV writes in the XML description (`NONE`, `LZ4`, ...).
    pub const fn name(self) -> &'static str {
        match self {
            Self::None => "NONE",
            Self::Lz4 => "LZ4",
            Self::Lz4High => "LZ4_HIGH",
            Self::Zstd => "ZSTD",
            Self::ZstdHigh => "ZSTD_HIGH",
        }
    }
}

impl std::fmt::Display for Compression {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What a stream carries, from its `typeIdentifier`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum StreamKind {
    /// `EVTS`: polarity events.
    Events,
    /// `IMUS`: inertial measurements.
    Imu,
    /// `TRIG`: triggers.
    Triggers,
    /// `FRME`: frames (recognised; their packets are skipped).
    Frames,
    /// Any other type (its packets are skipped).
    Other(String),
}

impl StreamKind {
    fn from_identifier(id: &str) -> Self {
        match id {
            "EVTS" => Self::Events,
            "IMUS" => Self::Imu,
            "TRIG" => Self::Triggers,
            "FRME" => Self::Frames,
            other => Self::Other(other.to_owned()),
        }
    }
}

/// One stream declared in the header's XML description.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StreamInfo {
    /// The stream id that packets carry.
    pub id: i32,
    /// What the stream carries.
    pub kind: StreamKind,
    /// The raw `typeIdentifier` (`EVTS`, `IMUS`, `TRIG`, `FRME`, ...).
    pub type_identifier: String,
    /// `originalOutputName` (`events`, `imu`, ...), when given.
    pub name: Option<String>,
    /// `info/source`: the camera, e.g. `DVXplorer_DXB00010`, when given.
    pub source: Option<String>,
    /// `info/sizeX` x `info/sizeY`, when both are given.
    pub resolution: Option<Resolution>,
}

/// Everything the header says: compression, where the data table is, and the streams.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AedatHeader {
    /// Compression of every packet.
    pub compression: Compression,
    /// Byte offset of the data table (files written to completion), `None` when absent.
    pub data_table_position: Option<u64>,
    /// The declared streams, by ascending id.
    pub streams: Vec<StreamInfo>,
    /// The XML description as stored.
    pub description: String,
}

impl AedatHeader {
    /// The first event stream (`EVTS`), if any.
    pub fn event_stream(&self) -> Option<&StreamInfo> {
        self.streams.iter().find(|s| s.kind == StreamKind::Events)
    }

    /// The first stream of `kind`, if any.
    pub fn stream_of(&self, kind: &StreamKind) -> Option<&StreamInfo> {
        self.streams.iter().find(|s| &s.kind == kind)
    }

    /// The stream with id `id`, if declared.
    pub fn stream(&self, id: i32) -> Option<&StreamInfo> {
        self.streams.iter().find(|s| s.id == id)
    }

    /// The event stream's resolution.
    pub fn resolution(&self) -> Option<Resolution> {
        self.event_stream().and_then(|s| s.resolution)
    }

    /// The camera name: the event stream's source, else any stream's.
    pub fn source(&self) -> Option<&str> {
        self.event_stream()
            .and_then(|s| s.source.as_deref())
            .or_else(|| self.streams.iter().find_map(|s| s.source.as_deref()))
    }

    /// Parses a verified `IOHeader` buffer (size prefix included). `offset` is where the buffer
    /// starts in the input, for error messages.
    pub(crate) fn parse(buf: &[u8], offset: u64) -> Result<Self> {
        let bad = |reason: String| AedatError::BadFlatbuffer {
            what: "IOHeader",
            offset,
            reason,
        };
        if !super::has_identifier(buf, schema::IO_HEADER_IDENTIFIER) {
            return Err(bad("missing file identifier \"IOHE\"".into()));
        }
        let root = schema::size_prefixed_root_as_io_header(buf).map_err(|e| bad(e.to_string()))?;
        let compression = Compression::from_raw(root.compression())?;
        let position = root.data_table_position();
        let description = root.info_node().unwrap_or_default().to_owned();
        let streams = parse_description(&description)?;
        Ok(Self {
            compression,
            data_table_position: u64::try_from(position).ok(),
            streams,
            description,
        })
    }
}

/// Attributes collected for one stream while walking the XML.
#[derive(Default)]
struct StreamAttrs {
    type_identifier: Option<String>,
    name: Option<String>,
    source: Option<String>,
    size_x: Option<String>,
    size_y: Option<String>,
}

/// Parses DV's XML description into its streams (sorted by id).
pub fn parse_description(xml: &str) -> Result<Vec<StreamInfo>> {
    let bad = |reason: String| AedatError::BadDescription { reason };
    let mut reader = quick_xml::Reader::from_str(xml);
    // Node names from the root down; `attr` is the key of the <attr> being read.
    let mut path: Vec<String> = Vec::new();
    let mut attr: Option<(String, String)> = None;
    let mut streams: BTreeMap<i32, StreamAttrs> = BTreeMap::new();
    loop {
        let event = reader
            .read_event()
            .map_err(|e| bad(format!("at byte {}: {e}", reader.buffer_position())))?;
        match event {
            XmlEvent::Start(start) => {
                let tag = start.name();
                let mut name = None;
                let mut key = None;
                for a in start.attributes() {
                    let a = a.map_err(|e| bad(format!("bad attribute: {e}")))?;
                    let value = a
                        .normalized_value(quick_xml::XmlVersion::Implicit1_0)
                        .map_err(|e| bad(format!("bad attribute value: {e}")))?
                        .into_owned();
                    match a.key.as_ref() {
                        "name" => name = Some(value),
                        "key" => key = Some(value),
                        _ => {}
                    }
                }
                match tag.as_ref() {
                    "node" => path.push(name.unwrap_or_default()),
                    "attr" => attr = key.map(|k| (k, String::new())),
                    _ => path.push(String::new()),
                }
            }
            XmlEvent::Text(text) => {
                if let Some((_, value)) = attr.as_mut() {
                    value.push_str(&text.xml10_content());
                }
            }
            XmlEvent::GeneralRef(r) => {
                if let Some((_, value)) = attr.as_mut() {
                    if let Some(c) = r
                        .resolve_char_ref()
                        .map_err(|e| bad(format!("bad character reference: {e}")))?
                    {
                        value.push(c);
                    } else if let Some(s) = quick_xml::escape::resolve_xml_entity(&r) {
                        value.push_str(s);
                    } else {
                        return Err(bad(format!("unknown entity &{};", &*r)));
                    }
                }
            }
            XmlEvent::End(end) => {
                if end.name().as_ref() == "attr" {
                    if let Some((key, value)) = attr.take() {
                        store_attr(&path, key, value, &mut streams);
                    }
                } else {
                    path.pop();
                }
            }
            XmlEvent::Eof => break,
            _ => {}
        }
    }
    streams
        .into_iter()
        .map(|(id, a)| {
            let type_identifier = a
                .type_identifier
                .ok_or_else(|| bad(format!("stream {id} has no typeIdentifier")))?;
            let dim = |v: Option<String>, what: &str| -> Result<Option<u16>> {
                v.map(|s| {
                    s.trim()
                        .parse::<u16>()
                        .ok()
                        .filter(|&n| n > 0)
                        .ok_or_else(|| bad(format!("stream {id}: {what} `{s}` is not 1..=65535")))
                })
                .transpose()
            };
            let resolution = match (dim(a.size_x, "sizeX")?, dim(a.size_y, "sizeY")?) {
                (Some(w), Some(h)) => Some(Resolution::new(w, h)),
                _ => None,
            };
            Ok(StreamInfo {
                id,
                kind: StreamKind::from_identifier(&type_identifier),
                type_identifier,
                name: a.name,
                source: a.source,
                resolution,
            })
        })
        .collect()
}

/// Files an `<attr>` under its stream when `path` is `.../outInfo/<id>` or `.../<id>/info`.
fn store_attr(
    path: &[String],
    key: String,
    value: String,
    streams: &mut BTreeMap<i32, StreamAttrs>,
) {
    let (stream, in_info) = match path {
        [.., out, id] if out == "outInfo" => (id, false),
        [.., out, id, info] if out == "outInfo" && info == "info" => (id, true),
        _ => return,
    };
    let Ok(id) = stream.parse::<i32>() else {
        return;
    };
    let s = streams.entry(id).or_default();
    match (in_info, key.as_str()) {
        (false, "typeIdentifier") => s.type_identifier = Some(value),
        (false, "originalOutputName") => s.name = Some(value),
        (true, "source") => s.source = Some(value),
        (true, "sizeX") => s.size_x = Some(value),
        (true, "sizeY") => s.size_y = Some(value),
        _ => {}
    }
}

/// A stream to declare when writing.
pub(crate) struct DeclaredStream<'a> {
    pub id: i32,
    pub output_name: &'a str,
    pub type_identifier: &'a str,
    pub type_description: &'a str,
    pub resolution: Option<Resolution>,
}

/// Writes the XML description the way dv-processing's `MonoCameraWriter` does (same nodes,
/// attribute order and indentation), so DV tools list our streams with their resolution and
/// camera name.
pub(crate) fn write_description(
    streams: &[DeclaredStream<'_>],
    source: &str,
    compression: Compression,
) -> String {
    let esc = |s: &str| quick_xml::escape::escape(s).into_owned();
    let mut x =
        String::from("<dv version=\"2.0\">\n    <node name=\"outInfo\" path=\"/outInfo/\">\n");
    for s in streams {
        let id = s.id;
        // `write!` into a String cannot fail.
        let _ = write!(
            x,
            "        <node name=\"{id}\" path=\"/outInfo/{id}/\">\n\
             \x20           <attr key=\"compression\" type=\"string\">{}</attr>\n\
             \x20           <attr key=\"originalModuleName\" type=\"string\">evtac</attr>\n\
             \x20           <attr key=\"originalOutputName\" type=\"string\">{}</attr>\n\
             \x20           <attr key=\"typeDescription\" type=\"string\">{}</attr>\n\
             \x20           <attr key=\"typeIdentifier\" type=\"string\">{}</attr>\n\
             \x20           <node name=\"info\" path=\"/outInfo/{id}/info/\">\n",
            compression.name(),
            esc(s.output_name),
            esc(s.type_description),
            esc(s.type_identifier),
        );
        if let Some(r) = s.resolution {
            let _ = write!(
                x,
                "                <attr key=\"sizeX\" type=\"int\">{}</attr>\n\
                 \x20               <attr key=\"sizeY\" type=\"int\">{}</attr>\n",
                r.width, r.height
            );
        }
        let _ = write!(
            x,
            "                <attr key=\"source\" type=\"string\">{}</attr>\n\
             \x20           </node>\n\
             \x20       </node>\n",
            esc(source)
        );
    }
    x.push_str("    </node>\n</dv>\n");
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_description_parses_back() {
        let xml = write_description(
            &[
                DeclaredStream {
                    id: 0,
                    output_name: "events",
                    type_identifier: "EVTS",
                    type_description: "Array of events (polarity ON/OFF).",
                    resolution: Some(Resolution::new(640, 480)),
                },
                DeclaredStream {
                    id: 1,
                    output_name: "imu",
                    type_identifier: "IMUS",
                    type_description: "Inertial Measurement Unit data samples.",
                    resolution: None,
                },
            ],
            "Cam <&> \"1\"",
            Compression::Zstd,
        );
        let streams = parse_description(&xml).unwrap();
        assert_eq!(streams.len(), 2);
        assert_eq!(streams[0].kind, StreamKind::Events);
        assert_eq!(streams[0].resolution, Some(Resolution::new(640, 480)));
        assert_eq!(streams[0].source.as_deref(), Some("Cam <&> \"1\""));
        assert_eq!(streams[0].name.as_deref(), Some("events"));
        assert_eq!(streams[1].kind, StreamKind::Imu);
        assert_eq!(streams[1].resolution, None);
    }

    #[test]
    fn description_without_type_is_an_error() {
        let xml = r#"<dv version="2.0"><node name="outInfo" path="/outInfo/">
            <node name="0" path="/outInfo/0/"><attr key="compression" type="string">NONE</attr>
            </node></node></dv>"#;
        assert!(matches!(
            parse_description(xml),
            Err(AedatError::BadDescription { .. })
        ));
    }

    #[test]
    fn compression_round_trips() {
        for raw in 0..5 {
            assert_eq!(Compression::from_raw(raw).unwrap().to_raw(), raw);
        }
        assert!(matches!(
            Compression::from_raw(5),
            Err(AedatError::UnknownCompression { value: 5 })
        ));
    }
}
