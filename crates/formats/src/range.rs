//! Reading a time range `[from, to)` of a recording: what a range read reports about how it
//! found its data, and the filter that cuts decoded elements to exactly the range.
//!
//! A range read must give exactly what "read everything, then keep `from <= t < to`" gives, but
//! an AEDAT4 file with a data table lets the reader seek to the few packets that overlap the
//! range instead of decoding gigabytes ([`crate::aedat::AedatReader::select_range`]). When that
//! shortcut is not available the reader scans the whole file; a silent scan would hide why an
//! import of one trial out of a long session takes minutes, so the reader says so once, through
//! the [`RangeIndex`] it returns.

use std::ops::Range;

/// How a range read finds the packets it needs.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum RangeIndex {
    /// The AEDAT4 data table located the packets: only `packets` of the file's `total` are read.
    DataTable {
        /// Packets overlapping the range (those that will be read and decoded).
        packets: usize,
        /// Packets in the file.
        total: usize,
    },
    /// An HDF5 file's `ms_to_idx` (DSEC's index of each millisecond's first event) located the
    /// events: only `events` of the file's `total` are read.
    EventIndex {
        /// Events read (those of the milliseconds the range touches).
        events: u64,
        /// Events in the file.
        total: u64,
    },
    /// The file is read from its start and every packet outside the range is dropped.
    Scan(ScanReason),
}

impl RangeIndex {
    /// The reason to warn about, when the read falls back to a scan of a file that should have
    /// been indexed (a missing or damaged AEDAT4 data table); `None` when the data table is used
    /// or the format has no index at all.
    pub fn fallback(&self) -> Option<&ScanReason> {
        match self {
            Self::Scan(
                reason @ (ScanReason::NoDataTable | ScanReason::DamagedDataTable { .. }),
            ) => Some(reason),
            _ => None,
        }
    }
}

/// Why a range read scans the whole file.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ScanReason {
    /// The AEDAT4 header announces no data table (a recording cut short, or written by a writer
    /// that could not go back to its header).
    #[error("the file has no data table (packet index)")]
    NoDataTable,
    /// The AEDAT4 data table is unusable.
    #[error("the data table at byte {position} is unusable: {reason}")]
    DamagedDataTable {
        /// The data table's byte offset, as the header gives it.
        position: u64,
        /// What is wrong with it.
        reason: String,
    },
    /// The format has no index (EVT, CSV, NPY): every range read of such a file is a scan.
    #[error("{format} files have no packet index")]
    NotIndexed {
        /// The format's name.
        format: &'static str,
    },
}

/// The indices of the elements of `elements` (sorted by time) with `from <= t < to`.
pub(crate) fn within<T>(elements: &[T], t: impl Fn(&T) -> i64, from: i64, to: i64) -> Range<usize> {
    let start = elements.partition_point(|e| t(e) < from);
    let end = start + elements[start..].partition_point(|e| t(e) < to);
    start..end
}

/// Keeps the elements of `v` (sorted by time) with `from <= t < to`.
pub(crate) fn retain_within<T>(v: &mut Vec<T>, t: impl Fn(&T) -> i64, from: i64, to: i64) {
    let keep = within(v, t, from, to);
    v.truncate(keep.end);
    v.drain(..keep.start);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn within_is_half_open_and_keeps_repeats() {
        let ts = [1i64, 2, 2, 3, 5, 5, 8];
        let id = |t: &i64| *t;
        assert_eq!(within(&ts, id, 2, 5), 1..4);
        assert_eq!(within(&ts, id, 5, 6), 4..6);
        assert_eq!(within(&ts, id, 9, 10), 7..7);
        assert_eq!(within(&ts, id, i64::MIN, 0), 0..0);
        let mut v = ts.to_vec();
        retain_within(&mut v, id, 2, 8);
        assert_eq!(v, [2, 2, 3, 5, 5]);
    }
}
