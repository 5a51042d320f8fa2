//! The text headers that EVT (`%` lines) and AEDAT 2.0 / 3.1 (`#` lines) files start with: lines
//! that begin with a marker byte, read from any [`Read`] up to the first line that does not (or
//! up to a closing line), with the bytes read past the header kept for the data reader; and the
//! [`DataBuffer`] both kinds of readers then decode from.

use std::io::{ErrorKind, Read};

/// Bytes asked of the source per read.
pub(crate) const READ_SIZE: usize = 1 << 16;
/// A header longer than this is not a header.
const MAX_HEADER: usize = 1 << 20;

/// A header read from the start of a source.
#[derive(Debug)]
pub(crate) struct TextHeader {
    /// Each line after its marker byte, without its line break (LF or CR LF).
    pub(crate) lines: Vec<Vec<u8>>,
    /// The buffer: the header, then `buf[len..end]` already read from the data.
    pub(crate) buf: Vec<u8>,
    /// Length of the header in bytes.
    pub(crate) len: usize,
    /// End of the bytes read into `buf`.
    pub(crate) end: usize,
}

/// Why a header could not be read.
#[derive(Debug)]
pub(crate) enum HeaderReadError {
    /// Reading the source failed.
    Io(std::io::Error),
    /// The source holds no bytes.
    Empty,
    /// A line never ends, or the header is longer than 1 MiB; the offset where it stops.
    Truncated(u64),
}

impl From<std::io::Error> for HeaderReadError {
    fn from(error: std::io::Error) -> Self {
        Self::Io(error)
    }
}

/// Reads into `buf`, retrying when interrupted; `Ok(0)` only at the end of the source.
pub(crate) fn read_some(source: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    loop {
        match source.read(buf) {
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            other => return other,
        }
    }
}

/// Reads the lines starting with `marker` at the start of `source`, stopping after a line for
/// which `last` is true or before the first line that does not start with `marker`.
pub(crate) fn read(
    source: &mut impl Read,
    marker: u8,
    last: impl Fn(&[u8]) -> bool,
) -> Result<TextHeader, HeaderReadError> {
    let mut buf = vec![0u8; READ_SIZE];
    let mut end = 0;
    let mut pos = 0;
    let mut lines = Vec::new();
    loop {
        // At least one byte past `pos` must be buffered to see whether a line follows.
        if pos == end {
            let n = read_more(source, &mut buf, end)?;
            if n == 0 {
                if end == 0 {
                    return Err(HeaderReadError::Empty);
                }
                break;
            }
            end += n;
        }
        if buf[pos] != marker {
            break;
        }
        let Some(newline) = buf[pos..end].iter().position(|&b| b == b'\n') else {
            // The line continues past what is buffered: read more.
            let n = read_more(source, &mut buf, end)?;
            if n == 0 {
                return Err(HeaderReadError::Truncated(end as u64));
            }
            end += n;
            continue;
        };
        let line = &buf[pos + 1..pos + newline];
        let line = line.strip_suffix(b"\r").unwrap_or(line).to_vec();
        pos += newline + 1;
        let done = last(&line);
        lines.push(line);
        if done {
            break;
        }
    }
    Ok(TextHeader {
        lines,
        buf,
        len: pos,
        end,
    })
}

/// Reads more bytes behind `buf[..end]`, growing `buf` up to [`MAX_HEADER`].
fn read_more(
    source: &mut impl Read,
    buf: &mut Vec<u8>,
    end: usize,
) -> Result<usize, HeaderReadError> {
    if end >= MAX_HEADER {
        return Err(HeaderReadError::Truncated(end as u64));
    }
    if end == buf.len() {
        buf.resize(buf.len() * 2, 0);
    }
    Ok(read_some(source, &mut buf[end..])?)
}

/// The data after a text header, read in blocks of [`READ_SIZE`] into one reused buffer: the EVT
/// and AEDAT 2.0 / 3.1 readers decode the whole units (words, records, packets) at its front and
/// [`refill`](Self::refill) carries a unit that straddles two reads over to the next.
#[derive(Debug)]
pub(crate) struct DataBuffer<R> {
    source: R,
    buf: Vec<u8>,
    /// Unconsumed bytes are `buf[start..end]`.
    start: usize,
    end: usize,
    /// File offset of `buf[start]`.
    offset: u64,
}

impl<R: Read> DataBuffer<R> {
    /// The data of `source` after `header` (whose buffer already holds its first bytes).
    pub(crate) fn after(source: R, header: &mut TextHeader) -> Self {
        Self {
            source,
            buf: std::mem::take(&mut header.buf),
            start: header.len,
            end: header.end,
            offset: header.len as u64,
        }
    }

    /// The bytes read and not yet consumed.
    pub(crate) fn bytes(&self) -> &[u8] {
        &self.buf[self.start..self.end]
    }

    /// File offset of the first unconsumed byte.
    pub(crate) fn offset(&self) -> u64 {
        self.offset
    }

    /// Bytes of the source read so far (header included).
    pub(crate) fn position(&self) -> u64 {
        self.offset + (self.end - self.start) as u64
    }

    /// Marks the first `n` unconsumed bytes as decoded.
    pub(crate) fn consume(&mut self, n: usize) {
        debug_assert!(n <= self.end - self.start);
        self.start += n;
        self.offset += n as u64;
    }

    /// Moves the unconsumed bytes (a partial unit) to the front and reads more behind them;
    /// returns the bytes read, 0 at the end of the source.
    pub(crate) fn refill(&mut self) -> std::io::Result<usize> {
        self.buf.copy_within(self.start..self.end, 0);
        self.end -= self.start;
        self.start = 0;
        let n = read_some(&mut self.source, &mut self.buf[self.end..])?;
        self.end += n;
        Ok(n)
    }
}
