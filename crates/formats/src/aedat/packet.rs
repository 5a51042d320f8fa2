//! Decoding one packet's flatbuffer (`EventPacket`, `IMUPacket`, `TriggerPacket`) into evtac's
//! types, checking coordinates against the stream's resolution and that time never goes back.

use super::error::{AedatError, Result};
use super::header::StreamKind;
use super::schema;
use crate::{Event, ImuSample, Resolution, Trigger};

/// What the reader remembers about a stream between packets.
#[derive(Debug, Clone)]
pub(crate) struct StreamState {
    /// The stream id.
    pub id: i32,
    /// What the stream carries.
    pub kind: StreamKind,
    /// Declared resolution (event streams).
    pub resolution: Option<Resolution>,
    /// Elements decoded so far (for error indices).
    pub count: u64,
    /// Last timestamp decoded (`i64::MIN` before the first).
    pub last_t: i64,
    /// Whether its packets are decoded: a kind evtac decodes (events, IMU, triggers), and
    /// selected ([`AedatReader::select_streams`](super::AedatReader::select_streams)).
    pub decoded: bool,
}

impl StreamState {
    fn backwards(&self, offset: u64, index: u64, previous: i64, current: i64) -> AedatError {
        AedatError::TimestampBackwards {
            stream_id: self.id,
            index,
            offset,
            previous,
            current,
        }
    }
}

/// Checks the identifier and the size prefix, then verifies and returns the root.
fn checked<'a, T>(
    payload: &'a [u8],
    what: &'static str,
    identifier: &str,
    offset: u64,
    root: impl FnOnce(&'a [u8]) -> std::result::Result<T, flatbuffers::InvalidFlatbuffer>,
) -> Result<T> {
    let bad = |reason: String| AedatError::BadFlatbuffer {
        what,
        offset,
        reason,
    };
    let Some(prefix) = payload.first_chunk::<4>() else {
        return Err(bad(format!(
            "{} bytes, too short for a size prefix",
            payload.len()
        )));
    };
    let declared = u32::from_le_bytes(*prefix) as usize;
    // A short payload means a cut-off (e.g. truncated LZ4 frame); extra bytes are tolerated.
    let Some(body) = payload.get(..declared.saturating_add(4)) else {
        return Err(bad(format!(
            "size prefix says {declared} bytes but only {} follow",
            payload.len() - 4
        )));
    };
    if !super::has_identifier(body, identifier) {
        return Err(bad(format!("missing file identifier {identifier:?}")));
    }
    root(body).map_err(|e| bad(e.to_string()))
}

/// Decodes an `EventPacket` into `out` (cleared first).
pub(crate) fn decode_events(
    payload: &[u8],
    state: &mut StreamState,
    offset: u64,
    out: &mut Vec<Event>,
) -> Result<()> {
    let packet = checked(
        payload,
        "EventPacket",
        schema::EVENT_PACKET_IDENTIFIER,
        offset,
        schema::size_prefixed_root_as_event_packet,
    )?;
    let bytes = packet.elements_bytes().unwrap_or_default();
    let (records, _) = bytes.as_chunks::<16>();
    // Convert first, then validate in a separate branch-free pass: both loops vectorise, which
    // a single loop with early error returns does not. Errors are rare and located afterwards.
    out.clear();
    out.extend(records.iter().map(|r| {
        let [t0, t1, t2, t3, t4, t5, t6, t7, x0, x1, y0, y1, p, ..] = *r;
        Event {
            t: i64::from_le_bytes([t0, t1, t2, t3, t4, t5, t6, t7]),
            // Negative int16 values become >= 32768 and fail the bound check below.
            x: u16::from_le_bytes([x0, x1]),
            y: u16::from_le_bytes([y0, y1]),
            polarity: p != 0,
        }
    }));
    // Bounds: the declared resolution, and in any case the non-negative int16 range.
    let (width, height) = state.resolution.map_or((1 << 15, 1 << 15), |r| {
        (r.width.min(1 << 15), r.height.min(1 << 15))
    });
    let mut bad = false;
    let mut last = state.last_t;
    for e in out.iter() {
        bad |= (e.x >= width) | (e.y >= height) | (e.t < last);
        last = e.t;
    }
    if bad {
        let mut last = state.last_t;
        for (i, e) in out.iter().enumerate() {
            let index = state.count + i as u64;
            if e.x >= width || e.y >= height {
                return Err(AedatError::OutOfBounds {
                    index,
                    stream_id: state.id,
                    offset,
                    x: (e.x as i16).into(),
                    y: (e.y as i16).into(),
                    width: width.into(),
                    height: height.into(),
                });
            }
            if e.t < last {
                return Err(state.backwards(offset, index, last, e.t));
            }
            last = e.t;
        }
    }
    state.last_t = last;
    state.count += records.len() as u64;
    Ok(())
}

/// Decodes an `IMUPacket` into `out` (cleared first).
pub(crate) fn decode_imu(
    payload: &[u8],
    state: &mut StreamState,
    offset: u64,
    out: &mut Vec<ImuSample>,
) -> Result<()> {
    use schema::Imu;
    let packet = checked(
        payload,
        "IMUPacket",
        schema::IMU_PACKET_IDENTIFIER,
        offset,
        schema::size_prefixed_root_as_imu_packet,
    )?;
    out.clear();
    let Some(elements) = packet.elements() else {
        return Ok(());
    };
    out.reserve(elements.len());
    for (i, s) in elements.iter().enumerate() {
        let t = s.timestamp();
        if t < state.last_t {
            return Err(state.backwards(offset, state.count + i as u64, state.last_t, t));
        }
        state.last_t = t;
        let v = |slot| s.float(slot);
        out.push(ImuSample {
            t,
            accelerometer: [
                v(Imu::VT_ACCELEROMETERX),
                v(Imu::VT_ACCELEROMETERX + 2),
                v(Imu::VT_ACCELEROMETERX + 4),
            ],
            gyroscope: [
                v(Imu::VT_GYROSCOPEX),
                v(Imu::VT_GYROSCOPEX + 2),
                v(Imu::VT_GYROSCOPEX + 4),
            ],
            temperature: v(Imu::VT_TEMPERATURE),
        });
    }
    state.count += out.len() as u64;
    Ok(())
}

/// Decodes a `TriggerPacket` into `out` (cleared first).
pub(crate) fn decode_triggers(
    payload: &[u8],
    state: &mut StreamState,
    offset: u64,
    out: &mut Vec<Trigger>,
) -> Result<()> {
    let packet = checked(
        payload,
        "TriggerPacket",
        schema::TRIGGER_PACKET_IDENTIFIER,
        offset,
        schema::size_prefixed_root_as_trigger_packet,
    )?;
    out.clear();
    let Some(elements) = packet.elements() else {
        return Ok(());
    };
    out.reserve(elements.len());
    for (i, tr) in elements.iter().enumerate() {
        let t = tr.timestamp();
        if t < state.last_t {
            return Err(state.backwards(offset, state.count + i as u64, state.last_t, t));
        }
        state.last_t = t;
        out.push(Trigger {
            t,
            kind: tr.type_(),
        });
    }
    state.count += out.len() as u64;
    Ok(())
}

/// Verifies a data table (`FileDataTable`), whose entries the reader does not need.
pub(crate) fn check_data_table(payload: &[u8], offset: u64) -> Result<()> {
    checked(
        payload,
        "FileDataTable",
        schema::FILE_DATA_TABLE_IDENTIFIER,
        offset,
        schema::size_prefixed_root_as_file_data_table,
    )
    .map(drop)
}
