//! CSV event files (`t,x,y,p`, `p` 1 = ON) and IMU CSV files (`t,ax,ay,az,gx,gy,gz,temperature`).
//!
//! The event reader streams any [`BufRead`] line by line into a reused buffer; a CSV file
//! declares no sensor size, so callers that know it pass it to
//! [`CsvReader::set_resolution`] and events are then checked against it.
//!
//! Other tools' CSV files read too: a header line names the four columns in any order and under
//! any name [`Field`] accepts (`timestamp,x,y,polarity`, as DV's exporter writes), and a file
//! without a header line (its first line four integers) is read as `t,x,y,p`, which
//! [`CsvReader::headerless`] reports so that `evtac info` can say so. Polarity may be written as
//! -1 for OFF.
//!
//! ```
//! use evtac_formats::csv::{CsvReader, CsvWriter};
//! use evtac_events::Event;
//!
//! let mut writer = CsvWriter::new(Vec::new())?;
//! writer.write_events(&[Event { t: 5, x: 1, y: 2, polarity: true }])?;
//! let bytes = writer.finish()?;
//! assert_eq!(bytes, b"t,x,y,p\n5,1,2,1\n");
//! let mut reader = CsvReader::from_slice(&bytes)?;
//! assert_eq!(reader.next_chunk()?.unwrap()[0].x, 1);
//! # Ok::<(), evtac_formats::csv::CsvError>(())
//! ```

pub(crate) mod family;

use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::Path;

use crate::check::{CheckError, EventCheck};
use crate::columns::{Field, Slots};
use crate::{Event, ImuSample, Resolution};

/// The event CSV header line.
pub const EVENT_HEADER: &str = "t,x,y,p";
/// The IMU CSV header line.
pub const IMU_HEADER: &str = "t,ax,ay,az,gx,gy,gz,temperature";
/// Events handed out per chunk.
const CHUNK: usize = 1 << 14;

/// What can go wrong reading or writing CSV files.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CsvError {
    /// Reading or writing failed.
    #[error("I/O failed: {0}")]
    Io(std::io::Error),
    /// The file has no header line.
    #[error("the file is empty (expected the header `{EVENT_HEADER}`)")]
    Empty,
    /// The first line is neither a header naming the four event columns nor four integers.
    #[error(
        "the header (line 1) is `{found}`: {reason} (expected `{EVENT_HEADER}`, the columns in \
         any order named {accepted}, or no header line)",
        accepted = Field::accepted()
    )]
    BadHeader {
        /// The first line as found.
        found: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A data line could not be parsed.
    #[error("line {line} (byte offset {offset}): {reason}")]
    BadLine {
        /// One-based line number.
        line: u64,
        /// Offset of the line's first byte.
        offset: u64,
        /// What is wrong with it.
        reason: String,
    },
    /// A parsed event is invalid (outside the sensor, or earlier than its predecessor).
    #[error("{error} (line {line}, byte offset {offset})")]
    Event {
        /// What is wrong with it.
        error: CheckError,
        /// One-based number of the line holding the event.
        line: u64,
        /// Offset of that line's first byte.
        offset: u64,
    },
}

// Not `#[from]`: that would also make the I/O error the `source()`, and `{:#}` chains would
// print its message twice (it is already part of ours).
impl From<std::io::Error> for CsvError {
    fn from(error: std::io::Error) -> Self {
        Self::Io(error)
    }
}

/// A streaming reader of `t,x,y,p` event CSV files.
#[derive(Debug)]
pub struct CsvReader<R> {
    source: R,
    line_buf: Vec<u8>,
    /// Number of lines read so far.
    line: u64,
    /// Bytes read so far.
    offset: u64,
    events: Vec<Event>,
    /// Line number and offset of each event of `events`, so that a check failure can name the
    /// line (blank lines make it differ from the event index).
    places: Vec<(u64, u64)>,
    check: EventCheck,
    /// The column holding `t`, `x`, `y` and `p`.
    columns: [usize; 4],
    /// Whether the file has no header line: its first line, still in `line_buf`, is data.
    headerless: bool,
    /// Whether the first line of a headerless file is yet to be handed out.
    first_pending: bool,
}

impl CsvReader<BufReader<File>> {
    /// Opens the file at `path`.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self, CsvError> {
        Self::new(BufReader::with_capacity(1 << 16, File::open(path)?))
    }
}

impl<'a> CsvReader<&'a [u8]> {
    /// Reads from bytes in memory.
    pub fn from_slice(bytes: &'a [u8]) -> Result<Self, CsvError> {
        Self::new(bytes)
    }
}

/// Parses an integer field (ASCII digits, optional leading `-`) without going through `str`.
fn parse_int(field: &[u8]) -> Option<i64> {
    let (negative, digits) = match field {
        [b'-', rest @ ..] => (true, rest),
        _ => (false, field),
    };
    if digits.is_empty() || digits.len() > 19 {
        return None;
    }
    let mut value: i64 = 0;
    for &b in digits {
        let d = b.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        value = value.checked_mul(10)?.checked_add(i64::from(d))?;
    }
    Some(if negative { -value } else { value })
}

/// Parses one data line (without its line break) into an event, its fields in `columns`.
fn parse_event(line: &[u8], columns: [usize; 4]) -> Result<Event, String> {
    let mut fields: [&[u8]; 4] = [&[]; 4];
    let mut n = 0;
    for field in line.split(|&b| b == b',') {
        if n == 4 {
            return Err(format!("more than 4 fields (expected `{EVENT_HEADER}`)"));
        }
        fields[n] = field.trim_ascii();
        n += 1;
    }
    if n < 4 {
        let missing = Field::ALL[columns.iter().position(|&c| c >= n).unwrap_or(3)];
        return Err(format!(
            "missing field `{missing}` (expected `{EVENT_HEADER}`)"
        ));
    }
    let [t, x, y, p] = columns.map(|c| fields[c]);
    let text = |f: &[u8]| String::from_utf8_lossy(f).into_owned();
    let t = parse_int(t).ok_or_else(|| format!("t = `{}` is not an integer", text(t)))?;
    let coordinate = |f: &[u8], name: &str| {
        parse_int(f)
            .and_then(|v| u16::try_from(v).ok())
            .ok_or_else(|| format!("{name} = `{}` is not an integer from 0 to 65535", text(f)))
    };
    let (x, y) = (coordinate(x, "x")?, coordinate(y, "y")?);
    let polarity = match p {
        b"1" => true,
        b"0" | b"-1" => false,
        _ => {
            return Err(format!("p = `{}` is not 1 (ON), 0 or -1 (OFF)", text(p)));
        }
    };
    Ok(Event { t, x, y, polarity })
}

/// The columns a first line names, or `None` when it is data (four integers: no header line).
fn header_columns(line: &str) -> Result<Option<[usize; 4]>, String> {
    let names: Vec<&str> = line.split(',').map(str::trim).collect();
    if names.len() == 4 && names.iter().all(|n| parse_int(n.as_bytes()).is_some()) {
        return Ok(None);
    }
    let mut slots = Slots::default();
    for (i, name) in names.iter().enumerate() {
        let field =
            Field::of(name).ok_or_else(|| format!("column `{name}` is not an event field"))?;
        slots.set(field, i, name)?;
    }
    slots.complete().map(Some)
}

impl<R: BufRead> CsvReader<R> {
    /// Reads the first line from `source`: the header, or the first event of a file without one.
    pub fn new(mut source: R) -> Result<Self, CsvError> {
        let mut line_buf = Vec::with_capacity(64);
        let n = source.read_until(b'\n', &mut line_buf)?;
        if n == 0 {
            return Err(CsvError::Empty);
        }
        let first = String::from_utf8_lossy(&line_buf);
        let cleaned = first.trim_start_matches('\u{feff}').trim();
        let bad = |reason: String| CsvError::BadHeader {
            found: first.trim_end().to_string(),
            reason,
        };
        let columns = header_columns(cleaned).map_err(bad)?;
        let headerless = columns.is_none();
        // A headerless file's first line is data, parsed by `next_chunk` after its byte-order
        // mark (if any) is skipped.
        let bom = if line_buf.starts_with("\u{feff}".as_bytes()) {
            3
        } else {
            0
        };
        if headerless {
            line_buf.drain(..bom);
        }
        Ok(Self {
            source,
            line_buf,
            line: u64::from(!headerless),
            offset: if headerless { bom as u64 } else { n as u64 },
            events: Vec::with_capacity(CHUNK),
            places: Vec::with_capacity(CHUNK),
            check: EventCheck::new(None),
            columns: columns.unwrap_or([0, 1, 2, 3]),
            headerless,
            first_pending: headerless,
        })
    }

    /// Whether the file has no header line (its columns were read as `t,x,y,p`).
    pub fn headerless(&self) -> bool {
        self.headerless
    }

    /// The sensor size events are checked against, if one was set.
    pub fn resolution(&self) -> Option<Resolution> {
        self.check.resolution()
    }

    /// Declares the sensor size: events from now on must lie inside it.
    pub fn set_resolution(&mut self, resolution: Resolution) {
        self.check.set_resolution(Some(resolution));
    }

    /// Bytes of the source consumed so far.
    pub fn position(&self) -> u64 {
        self.offset
    }

    /// Every remaining event, read chunk by chunk (the whole file for a fresh reader).
    pub fn read_to_end(mut self) -> Result<Vec<Event>, CsvError> {
        let mut out = Vec::new();
        while let Some(chunk) = self.next_chunk()? {
            out.extend_from_slice(chunk);
        }
        Ok(out)
    }

    /// The next chunk of events; `Ok(None)` at the end of the file. Blank lines are skipped.
    pub fn next_chunk(&mut self) -> Result<Option<&[Event]>, CsvError> {
        self.events.clear();
        self.places.clear();
        while self.events.len() < CHUNK {
            let n = if std::mem::take(&mut self.first_pending) {
                self.line_buf.len()
            } else {
                self.line_buf.clear();
                self.source.read_until(b'\n', &mut self.line_buf)?
            };
            if n == 0 {
                break;
            }
            let start = self.offset;
            self.offset += n as u64;
            self.line += 1;
            let line = self.line_buf.trim_ascii();
            if line.is_empty() {
                continue;
            }
            let event = parse_event(line, self.columns).map_err(|reason| CsvError::BadLine {
                line: self.line,
                offset: start,
                reason,
            })?;
            self.events.push(event);
            self.places.push((self.line, start));
        }
        let (count, places, last) = (self.check.count(), &self.places, (self.line, self.offset));
        self.check.check(&self.events).map_err(|error| {
            // The failing event is in this chunk, so its index is at least `count`.
            let (line, offset) = usize::try_from(error.index().saturating_sub(count))
                .ok()
                .and_then(|i| places.get(i).copied())
                .unwrap_or(last);
            CsvError::Event {
                error,
                line,
                offset,
            }
        })?;
        Ok((!self.events.is_empty()).then_some(self.events.as_slice()))
    }
}

/// Writes `t,x,y,p` event CSV files.
#[derive(Debug)]
pub struct CsvWriter<W: Write> {
    sink: W,
    line: Vec<u8>,
}

impl CsvWriter<BufWriter<File>> {
    /// Creates (or truncates) the file at `path` and writes the header.
    pub fn create(path: impl AsRef<Path>) -> Result<Self, CsvError> {
        Self::new(BufWriter::with_capacity(1 << 16, File::create(path)?))
    }
}

impl<W: Write> CsvWriter<W> {
    /// Writes the header to `sink`.
    pub fn new(mut sink: W) -> Result<Self, CsvError> {
        writeln!(sink, "{EVENT_HEADER}")?;
        Ok(Self {
            sink,
            line: Vec::with_capacity(64),
        })
    }

    /// Appends events, one line each.
    pub fn write_events(&mut self, events: &[Event]) -> Result<(), CsvError> {
        for e in events {
            self.line.clear();
            // Writing to a Vec cannot fail.
            let _ = writeln!(
                self.line,
                "{},{},{},{}",
                e.t,
                e.x,
                e.y,
                u8::from(e.polarity)
            );
            self.sink.write_all(&self.line)?;
        }
        Ok(())
    }

    /// Flushes and returns the sink.
    pub fn finish(mut self) -> Result<W, CsvError> {
        self.sink.flush()?;
        Ok(self.sink)
    }
}

/// Writes IMU CSV files: `t,ax,ay,az,gx,gy,gz,temperature` (us, g, deg/s, degrees Celsius).
///
/// Floats are written in their shortest exact form, so reading them back gives the same `f32`.
#[derive(Debug)]
pub struct ImuCsvWriter<W: Write> {
    sink: W,
}

impl ImuCsvWriter<BufWriter<File>> {
    /// Creates (or truncates) the file at `path` and writes the header.
    pub fn create(path: impl AsRef<Path>) -> Result<Self, CsvError> {
        Self::new(BufWriter::new(File::create(path)?))
    }
}

impl<W: Write> ImuCsvWriter<W> {
    /// Writes the header to `sink`.
    pub fn new(mut sink: W) -> Result<Self, CsvError> {
        writeln!(sink, "{IMU_HEADER}")?;
        Ok(Self { sink })
    }

    /// Appends samples, one line each.
    pub fn write_imu(&mut self, samples: &[ImuSample]) -> Result<(), CsvError> {
        for s in samples {
            let [ax, ay, az] = s.accelerometer;
            let [gx, gy, gz] = s.gyroscope;
            writeln!(
                self.sink,
                "{},{ax},{ay},{az},{gx},{gy},{gz},{}",
                s.t, s.temperature
            )?;
        }
        Ok(())
    }

    /// Flushes and returns the sink.
    pub fn finish(mut self) -> Result<W, CsvError> {
        self.sink.flush()?;
        Ok(self.sink)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_all(bytes: &[u8]) -> Result<Vec<Event>, CsvError> {
        CsvReader::from_slice(bytes)?.read_to_end()
    }

    #[test]
    fn parses_lines_with_crlf_spaces_and_blank_lines() {
        let events = read_all(b"t, x, y, p\r\n-3,0,1,0\r\n\n7, 65535 ,2,1").unwrap();
        assert_eq!(
            events,
            vec![
                Event {
                    t: -3,
                    x: 0,
                    y: 1,
                    polarity: false
                },
                Event {
                    t: 7,
                    x: 65535,
                    y: 2,
                    polarity: true
                },
            ]
        );
    }

    #[test]
    fn bad_lines_name_line_and_offset() {
        let err = read_all(b"t,x,y,p\n1,2,3,1\n2,2,3,5\n").unwrap_err();
        assert!(
            matches!(&err, CsvError::BadLine { line: 3, offset: 16, reason } if reason.contains("p = `5`")),
            "{err}"
        );
        let err = read_all(b"t,x,y,p\n1,70000,3,1\n").unwrap_err();
        assert!(err.to_string().contains("x = `70000`"), "{err}");
        let err = read_all(b"t,x,y,p\n1,2,3\n").unwrap_err();
        assert!(err.to_string().contains("missing field `p`"), "{err}");
        assert!(matches!(read_all(b""), Err(CsvError::Empty)));
        let err = read_all(b"t,x,y,z\n").unwrap_err();
        assert!(
            matches!(&err, CsvError::BadHeader { reason, .. } if reason.contains("`z`")),
            "{err}"
        );
        let err = read_all(b"t,x,y,t\n").unwrap_err();
        assert!(err.to_string().contains("two columns"), "{err}");
        let err = read_all(b"t,x,y,p\n5,0,0,1\n4,0,0,1\n").unwrap_err();
        assert!(err.to_string().contains("backwards at event 1"), "{err}");
        // Headerless: the first line is line 1.
        let err = read_all(b"1,2,3,1\n2,2,3,5\n").unwrap_err();
        assert!(
            matches!(
                &err,
                CsvError::BadLine {
                    line: 2,
                    offset: 8,
                    ..
                }
            ),
            "{err}"
        );
    }

    #[test]
    fn other_tools_headers_and_no_header() {
        let expected = vec![
            Event {
                t: 5,
                x: 1,
                y: 2,
                polarity: true,
            },
            Event {
                t: 6,
                x: 3,
                y: 4,
                polarity: false,
            },
        ];
        for text in [
            &b"timestamp,x,y,polarity\n5,1,2,1\n6,3,4,0\n"[..],
            b"x, y, polarity, t\r\n1,2,1,5\r\n3,4,-1,6\r\n",
            b"\xef\xbb\xbf5,1,2,1\n6,3,4,0\n",
            b"5,1,2,1\n6,3,4,-1",
        ] {
            let reader = CsvReader::from_slice(text).unwrap();
            let headerless = reader.headerless();
            assert_eq!(headerless, !text.contains(&b't'), "{text:?}");
            assert_eq!(reader.read_to_end().unwrap(), expected, "{text:?}");
        }
    }

    #[test]
    fn resolution_is_enforced_once_set() {
        let mut reader = CsvReader::from_slice(b"t,x,y,p\n1,10,3,1\n").unwrap();
        reader.set_resolution(Resolution::new(10, 10));
        let err = reader.next_chunk().unwrap_err();
        assert!(err.to_string().contains("x must be < 10"), "{err}");
    }

    #[test]
    fn imu_lines_round_trip_floats() {
        let sample = ImuSample {
            t: 9,
            accelerometer: [0.126_342_77, -0.995_117_2, -0.393_066_4],
            gyroscope: [0.411_987_27, 0.076_293_945, -0.411_987_27],
            temperature: 38.152_344,
        };
        let mut w = ImuCsvWriter::new(Vec::new()).unwrap();
        w.write_imu(&[sample]).unwrap();
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        let line = text.lines().nth(1).unwrap();
        let values: Vec<f32> = line
            .split(',')
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(values[..3], sample.accelerometer);
        assert_eq!(values[3..6], sample.gyroscope);
        assert_eq!(values[6], sample.temperature);
    }
}
