//! What the AEDAT4 test binaries share: a seeded generator and an input wrapper.

use std::io::{self, Cursor, Read, Seek, SeekFrom};

/// `Read + Seek` over a slice that hands out at most `step` bytes per `read` call and counts the
/// bytes it hands out (to check chunk invariance, and how much of a file a read touches).
pub struct Dribble<'a> {
    inner: Cursor<&'a [u8]>,
    step: usize,
    /// Bytes handed out so far.
    pub read: u64,
}

impl<'a> Dribble<'a> {
    /// Reads `bytes`, at most `step` at a time.
    pub fn new(bytes: &'a [u8], step: usize) -> Self {
        Self {
            inner: Cursor::new(bytes),
            step,
            read: 0,
        }
    }
}

impl Read for Dribble<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = buf.len().min(self.step);
        let n = self.inner.read(&mut buf[..n])?;
        self.read += n as u64;
        Ok(n)
    }
}

impl Seek for Dribble<'_> {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        self.inner.seek(pos)
    }
}

/// A seeded xorshift64 generator: the same seed gives the same numbers everywhere.
pub fn xorshift(seed: u64) -> impl FnMut() -> u64 {
    let mut s = seed.max(1);
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    }
}
