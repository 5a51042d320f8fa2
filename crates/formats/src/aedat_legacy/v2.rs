//! AEDAT 2.0 records from DAVIS cameras (jAER).
//!
//! After the header come 8-byte records: a big-endian 32-bit address and a big-endian 32-bit
//! timestamp in us (iniVation's AEDAT 2.0 format description). A DAVIS address is
//!
//! - bit 31 set: an APS (frame) sample or, with bits 10 and 11 also set, one axis of an IMU
//!   sample. Both are skipped: jAER stores IMU axes as raw 16-bit counts whose scale depends on
//!   the IMU's full-scale setting, which the file does not record, so they cannot be turned into
//!   g and deg/s reliably.
//! - bit 31 clear, bit 10 set: an external input (special) event; skipped, since the file does
//!   not say which edge it was.
//! - bit 31 and bit 10 clear: a polarity event, `y` in bits 22..30, `x` in bits 12..21,
//!   polarity (1 = ON) in bit 11.
//!
//! jAER's DAVIS extractor mirrors `x` (`x = width - 1 - x address`) and keeps `y` with its origin
//! at the bottom, as jAER draws; evtac's `y` grows downwards, so both addresses are mirrored:
//! `x = width - 1 - x address`, `y = height - 1 - y address` (SensorsINI's v2e writes AEDAT 2.0
//! for jAER with exactly these two flips). An address beyond the sensor is an error.
//!
//! The 32-bit timestamp wraps after 2^32 us (71.6 minutes; jAER's signed view turns negative
//! after half of that): a timestamp more than 2^31 us below the previous one counts as a wrap,
//! and 2^32 us is added from then on. Any other step back (a jAER timestamp reset) is an error,
//! like every reader's time going backwards.
//!
//! The header ends at the first line that does not start with `#`, as jAER reads it: a first
//! record whose first byte happens to be `#` (0x23) cannot be told from a header line, here as in
//! jAER (SensorsINI's v2e drops such a first event when it writes).

use super::{LegacyError, Out};
use crate::{Event, Resolution};

/// Size of one record.
const RECORD: usize = 8;

/// Decoder state carried across reads.
#[derive(Debug, Clone)]
pub(crate) struct Decoder {
    size: Resolution,
    /// The last timestamp as written, and the wraps so far.
    last: Option<u32>,
    wraps: i64,
}

impl Decoder {
    /// A decoder for a sensor of `size` (DAVIS240 when the header names none).
    pub(crate) fn new(size: Option<Resolution>) -> Self {
        Self {
            size: size.unwrap_or(Resolution::new(240, 180)),
            last: None,
            wraps: 0,
        }
    }

    /// Decodes the whole records at the start of `bytes` (found at file offset `offset`) into
    /// `out`; returns the bytes used.
    pub(crate) fn decode(
        &mut self,
        bytes: &[u8],
        offset: u64,
        out: &mut Out,
    ) -> Result<usize, LegacyError> {
        let whole = bytes.len() - bytes.len() % RECORD;
        let (width, height) = (u32::from(self.size.width), u32::from(self.size.height));
        for (i, r) in bytes[..whole].chunks_exact(RECORD).enumerate() {
            let address = u32::from_be_bytes([r[0], r[1], r[2], r[3]]);
            let ts = u32::from_be_bytes([r[4], r[5], r[6], r[7]]);
            if address >> 31 != 0 || address & (1 << 10) != 0 {
                continue;
            }
            let (x, y) = ((address >> 12) & 0x3FF, (address >> 22) & 0x1FF);
            if x >= width || y >= height {
                return Err(LegacyError::AddressOutside {
                    offset: offset + (i * RECORD) as u64,
                    address,
                    x,
                    y,
                    width: self.size.width,
                    height: self.size.height,
                });
            }
            if let Some(last) = self.last
                && ts < last
                && last - ts > 1 << 31
            {
                self.wraps += 1;
            }
            self.last = Some(ts);
            out.events.push(Event {
                t: (self.wraps << 32) + i64::from(ts),
                // Both below the sensor size, itself a u16.
                x: (width - 1 - x) as u16,
                y: (height - 1 - y) as u16,
                polarity: address & (1 << 11) != 0,
            });
        }
        Ok(whole)
    }

    /// Checks the end of the file: `left` bytes of a record at `offset` remain.
    pub(crate) fn finish(&self, left: usize, offset: u64, len: u64) -> Result<(), LegacyError> {
        if left == 0 {
            return Ok(());
        }
        Err(LegacyError::Truncated {
            what: "record",
            offset,
            needed: RECORD as u64,
            len,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(address: u32, ts: u32) -> Vec<u8> {
        [address.to_be_bytes(), ts.to_be_bytes()].concat()
    }

    #[test]
    fn polarity_flips_skips_and_wraps() {
        let bytes = [
            record(3 << 22 | 5 << 12 | 1 << 11, 10), // ON at raw (5, 3)
            record(1 << 31 | 0xC00, 11),             // IMU axis: skipped
            record(1 << 31 | 7 << 12, 12),           // APS: skipped
            record(1 << 10, 13),                     // external input: skipped
            record(179 << 22 | 239 << 12, u32::MAX), // OFF at raw (239, 179)
            record(0, 4),                            // after the wrap
        ]
        .concat();
        let mut out = Out::default();
        let used = Decoder::new(None).decode(&bytes, 0, &mut out).unwrap();
        assert_eq!(used, bytes.len());
        let e = |t, x, y, polarity| Event { t, x, y, polarity };
        assert_eq!(
            out.events,
            vec![
                e(10, 234, 176, true),
                e(i64::from(u32::MAX), 0, 0, false),
                e((1 << 32) + 4, 239, 179, false)
            ]
        );
    }

    #[test]
    fn addresses_outside_the_sensor_are_errors() {
        let bytes = [record(0, 1), record(240 << 12, 2)].concat();
        let err = Decoder::new(None)
            .decode(&bytes, 100, &mut Out::default())
            .unwrap_err();
        assert!(
            matches!(
                err,
                LegacyError::AddressOutside {
                    offset: 108,
                    x: 240,
                    ..
                }
            ),
            "{err}"
        );
    }
}
