//! Helpers shared by the reader tests.

#![allow(dead_code)]

use std::io::Read;

use evtac_events::Event;

/// A reader that hands out at most `step` bytes per `read`, to exercise the carry-over of data
/// that straddles read boundaries.
pub struct Trickle<'a> {
    pub bytes: &'a [u8],
    pub step: usize,
}

impl Read for Trickle<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.step.min(buf.len()).min(self.bytes.len());
        buf[..n].copy_from_slice(&self.bytes[..n]);
        self.bytes = &self.bytes[n..];
        Ok(n)
    }
}

/// The read sizes every streaming reader must be invariant to.
pub const READ_SIZES: [usize; 3] = [1, 7, 65536];

/// A deterministic, ordered event stream on a `width` x `height` sensor.
pub fn synthetic_events(n: usize, width: u16, height: u16) -> Vec<Event> {
    // A fixed linear congruential sequence: reproducible without a seed argument.
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut t = 1_000_000i64;
    (0..n)
        .map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            t += ((state >> 60) % 3) as i64;
            Event {
                t,
                x: ((state >> 16) % u64::from(width)) as u16,
                y: ((state >> 32) % u64::from(height)) as u16,
                polarity: state >> 63 == 1,
            }
        })
        .collect()
}

/// Reads the `.expected.npy` of the EVT3 fixture with the crate's own NPY reader.
pub fn read_npy_events(path: &std::path::Path) -> Vec<Event> {
    let mut reader = evtac_events::npy::NpyReader::from_path(path).expect("open npy");
    let mut out = Vec::new();
    while let Some(chunk) = reader.next_chunk().expect("read npy") {
        out.extend_from_slice(chunk);
    }
    out
}
