//! The packed little-endian records that cross between Rust and numpy, one numpy structured
//! dtype each. Rust writes them into a `Vec<u8>` with the interpreter released, and numpy takes
//! that vector without a copy and views it with the dtype; incoming arrays are brought to the
//! same layout by the Python half and read here as bytes.
//!
//! | record   | numpy dtype | bytes |
//! |----------|-------------|-------|
//! | event    | `t <i8, x <i2, y <i2, p u1` (evtac's NPY files) | 13 |
//! | IMU      | `t <i8, ax ay az <f4 (g), gx gy gz <f4 (deg/s), temperature <f4` | 36 |
//! | trigger  | `t <i8, kind i1` | 9 |
//! | estimate | `t_us <i8, pitch_deg <f4, roll_deg <f4, latency_us <f8` | 24 |
//!
//! Events are checked on the way in as evtac's NPY reader checks them (coordinates not
//! negative, polarity 0 or 1); time order and the sensor bounds are checked where they matter.

use evtac_events::{Event, ImuSample, Trigger};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;

use crate::error;

/// A numpy structured dtype as `(name, format)` fields.
pub type Fields = &'static [(&'static str, &'static str)];

/// The record layouts, each with its numpy dtype.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// `t <i8, x <i2, y <i2, p u1`: evtac's NPY event dtype.
    Event,
    /// `t <i8, ax ay az gx gy gz temperature <f4`.
    Imu,
    /// `t <i8, kind i1`.
    Trigger,
    /// `t_us <i8, pitch_deg <f4, roll_deg <f4, latency_us <f8`.
    Estimate,
}

impl Layout {
    const ALL: [Self; 4] = [Self::Event, Self::Imu, Self::Trigger, Self::Estimate];

    /// The dtype's fields.
    pub const fn fields(self) -> Fields {
        match self {
            Self::Event => &[("t", "<i8"), ("x", "<i2"), ("y", "<i2"), ("p", "u1")],
            Self::Imu => &[
                ("t", "<i8"),
                ("ax", "<f4"),
                ("ay", "<f4"),
                ("az", "<f4"),
                ("gx", "<f4"),
                ("gy", "<f4"),
                ("gz", "<f4"),
                ("temperature", "<f4"),
            ],
            Self::Trigger => &[("t", "<i8"), ("kind", "i1")],
            Self::Estimate => &[
                ("t_us", "<i8"),
                ("pitch_deg", "<f4"),
                ("roll_deg", "<f4"),
                ("latency_us", "<f8"),
            ],
        }
    }

    /// The numpy dtype (built once per layout).
    fn dtype(self, py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
        static DTYPES: PyOnceLock<Vec<Py<PyAny>>> = PyOnceLock::new();
        let all = DTYPES.get_or_try_init(py, || -> PyResult<_> {
            let make = py.import("numpy")?.getattr("dtype")?;
            Self::ALL
                .iter()
                .map(|l| Ok(make.call1((l.fields().to_vec(),))?.unbind()))
                .collect()
        })?;
        Ok(all[self as usize].bind(py).clone())
    }

    /// Hands `bytes` (whole records of this layout) to numpy without a copy, as a structured
    /// array.
    pub fn to_numpy(self, py: Python<'_>, bytes: Vec<u8>) -> PyResult<Bound<'_, PyAny>> {
        let raw = PyArray1::from_vec(py, bytes);
        raw.call_method1("view", (self.dtype(py)?,))
    }
}

/// Bytes per event record.
pub const EVENT_SIZE: usize = 13;
/// Bytes per IMU record.
pub const IMU_SIZE: usize = 36;
/// Bytes per trigger record.
pub const TRIGGER_SIZE: usize = 9;

fn le_i64(r: &[u8]) -> i64 {
    let mut b = [0; 8];
    b.copy_from_slice(&r[..8]);
    i64::from_le_bytes(b)
}

fn le_f32(r: &[u8], at: usize) -> f32 {
    f32::from_le_bytes([r[at], r[at + 1], r[at + 2], r[at + 3]])
}

/// Decodes packed event records.
pub fn decode_events(bytes: &[u8]) -> PyResult<Vec<Event>> {
    if !bytes.len().is_multiple_of(EVENT_SIZE) {
        return Err(error::value(format!(
            "{} bytes are not whole {EVENT_SIZE}-byte event records",
            bytes.len()
        )));
    }
    bytes
        .chunks_exact(EVENT_SIZE)
        .enumerate()
        .map(|(i, r)| {
            let t = le_i64(r);
            let x = i16::from_le_bytes([r[8], r[9]]);
            let y = i16::from_le_bytes([r[10], r[11]]);
            let (Ok(x), Ok(y)) = (u16::try_from(x), u16::try_from(y)) else {
                return Err(error::value(format!(
                    "event {i} at t={t} us has a negative coordinate (x={x}, y={y})"
                )));
            };
            let polarity = match r[12] {
                0 => false,
                1 => true,
                p => {
                    return Err(error::value(format!(
                        "event {i} at t={t} us has polarity {p} (must be 0 or 1)"
                    )));
                }
            };
            Ok(Event { t, x, y, polarity })
        })
        .collect()
}

/// Encodes events as packed records (coordinates above 32767 do not fit `<i2`).
pub fn encode_events(events: &[Event]) -> PyResult<Vec<u8>> {
    let mut out = Vec::with_capacity(events.len() * EVENT_SIZE);
    for (i, e) in events.iter().enumerate() {
        let (Ok(x), Ok(y)) = (i16::try_from(e.x), i16::try_from(e.y)) else {
            return Err(error::value(format!(
                "event {i} at (x={}, y={}) does not fit the <i2 coordinates of the event dtype",
                e.x, e.y
            )));
        };
        out.extend_from_slice(&e.t.to_le_bytes());
        out.extend_from_slice(&x.to_le_bytes());
        out.extend_from_slice(&y.to_le_bytes());
        out.push(u8::from(e.polarity));
    }
    Ok(out)
}

/// Encodes IMU samples as packed records.
pub fn encode_imu(imu: &[ImuSample]) -> Vec<u8> {
    let mut out = Vec::with_capacity(imu.len() * IMU_SIZE);
    for s in imu {
        out.extend_from_slice(&s.t.to_le_bytes());
        for v in s.accelerometer.iter().chain(&s.gyroscope) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&s.temperature.to_le_bytes());
    }
    out
}

/// Decodes packed IMU records.
pub fn decode_imu(bytes: &[u8]) -> PyResult<Vec<ImuSample>> {
    if !bytes.len().is_multiple_of(IMU_SIZE) {
        return Err(error::value(format!(
            "{} bytes are not whole {IMU_SIZE}-byte IMU records",
            bytes.len()
        )));
    }
    Ok(bytes
        .chunks_exact(IMU_SIZE)
        .map(|r| ImuSample {
            t: le_i64(r),
            accelerometer: [le_f32(r, 8), le_f32(r, 12), le_f32(r, 16)],
            gyroscope: [le_f32(r, 20), le_f32(r, 24), le_f32(r, 28)],
            temperature: le_f32(r, 32),
        })
        .collect())
}

/// Encodes triggers as packed records.
pub fn encode_triggers(triggers: &[Trigger]) -> Vec<u8> {
    let mut out = Vec::with_capacity(triggers.len() * TRIGGER_SIZE);
    for tr in triggers {
        out.extend_from_slice(&tr.t.to_le_bytes());
        out.extend_from_slice(&tr.kind.to_le_bytes());
    }
    out
}
