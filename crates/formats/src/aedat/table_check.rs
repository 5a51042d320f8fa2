//! The end-of-read check of a data table, streamed: the same verdict as verifying the whole
//! decompressed table with the flatbuffers verifier ([`super::packet::check_data_table`]),
//! holding constant buffers whatever the table's size (the whole table is about 90 bytes a
//! packet, compressed and decompressed: 100 MB for a 1.6-hour session).
//!
//! A `FileDataTable` is a vector of `FileDataDefinition` tables, and what the verifier checks
//! of each is local: the offset to it, its signed offset to its vtable, the vtable's length and
//! field offsets, the fields' alignment and bounds, plus the totals of tables and of the
//! "apparent size" over the whole buffer. The table is read in passes over the decompressed
//! stream (seeking back to its start each time), each pass following the offsets of
//! [`ENTRIES_PER_PASS`] entries as the stream reaches them, and a vtable the stream had passed
//! before an entry named it is read in one more pass; DV and evtac write one vtable for all
//! entries, so that pass is rarely needed.
//!
//! A range read plans its packets in the same passes ([`plan`]): each followed entry's table's
//! first bytes are kept with it, and once the pass has its vtables the entries go to the range
//! read's [`Planner`] in the table's order, so that planning holds a pass's entries and the
//! selected ones rather than the table.
//!
//! The streamed check is sound, not complete: it says [`Verdict::Valid`] only when every check
//! the verifier makes passes, and anything it cannot vouch for (a damaged table, an unusual
//! layout, an input it cannot stream) is [`Verdict::Unsure`]. The caller then verifies the whole
//! table as before, so a damaged file gets exactly the error it always got; only a good table
//! is checked in constant memory.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::io::Read;
use std::ops::ControlFlow;

use super::compression::MAX_PACKET_BYTES;
use super::header::Compression;
use super::index::{Plan, Planner};
use super::schema::{
    DataTableEntry, FILE_DATA_TABLE_IDENTIFIER, FbPacketHeader, FileDataDefinition, FileDataTable,
};
use super::table_stream::{Streamed, stream};

/// Entries followed per pass: their pending reads and positions take about 60 bytes each
/// (4 MB), and a table of a million packets (1.5 hours) takes 16 passes of a fraction of a
/// second each.
pub(crate) const ENTRIES_PER_PASS: usize = 1 << 16;

/// Bytes of the decompressed table's start read for its root (the size prefix, the root table
/// and its vtable, the vector's length): a builder writes them first, in the first hundred bytes.
const HEAD: usize = 4096;

/// Distinct vtables remembered (a builder writes one per distinct set of present fields).
const MAX_VTABLES: usize = 1024;

/// The flatbuffers verifier's limit on the apparent size (its default, as the reader uses it).
const MAX_APPARENT_SIZE: u64 = 1 << 31;

/// Bytes read of a vtable: its length, the table's size and the five fields' offsets.
const VTABLE_READ: u64 = 14;

/// Bytes read of an entry's table when planning a range read: its fields lie within the first
/// 48 bytes as builders lay them out (a soffset, four 8-byte scalars and an 8-byte struct, with
/// padding); an entry whose fields lie further is planned from the whole table.
const TABLE_READ: u64 = 64;

/// What the streamed check found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Verdict {
    /// The verifier would accept the table; the compressed table's length, bytes.
    Valid(u64),
    /// Not known: verify the whole table.
    Unsure,
}

/// Checks the data table at `position` of `reader` (running to the end of the input, at most
/// [`MAX_PACKET_BYTES`]) in passes of `per_pass` entries; the reader's position afterwards is
/// unspecified.
pub(crate) fn check<R: Read>(
    reader: &mut R,
    seek: fn(&mut R, u64) -> std::io::Result<()>,
    position: u64,
    compression: Compression,
    per_pass: usize,
) -> Verdict {
    let mut pass = |sink: &mut dyn FnMut(&[u8]) -> ControlFlow<()>| -> Option<Streamed> {
        seek(reader, position).ok()?;
        let mut input = (&mut *reader).take(MAX_PACKET_BYTES);
        let streamed = stream(&mut input, compression, sink)?;
        match streamed {
            Streamed::Whole(_) => Some(Streamed::Whole(MAX_PACKET_BYTES - input.limit())),
            Streamed::Stopped => Some(streamed),
        }
    };
    check_passes(&mut pass, per_pass, None).map_or(Verdict::Unsure, Verdict::Valid)
}

/// Plans a range read from the data table at `position` of `reader` as [`check`] checks it, in
/// passes of `per_pass` entries, handing each entry to `planner` in the table's order: the
/// plan, or the planner's first error, when the whole verifier would accept the table (so that
/// planning it whole would give the same); `None` when that is not known, and the caller plans
/// from the whole table. Holds `per_pass` entries' positions and first bytes, and the entries
/// the planner selects.
pub(crate) fn plan<R: Read>(
    reader: &mut R,
    seek: fn(&mut R, u64) -> std::io::Result<()>,
    position: u64,
    compression: Compression,
    per_pass: usize,
    planner: Planner,
) -> Option<Result<Plan, String>> {
    let mut pass = |sink: &mut dyn FnMut(&[u8]) -> ControlFlow<()>| -> Option<Streamed> {
        seek(reader, position).ok()?;
        let mut input = (&mut *reader).take(MAX_PACKET_BYTES);
        stream(&mut input, compression, sink)
    };
    plan_passes(&mut pass, per_pass, planner)
}

/// [`plan`], over passes made by `pass`.
fn plan_passes(
    pass: &mut Pass,
    per_pass: usize,
    mut planner: Planner,
) -> Option<Result<Plan, String>> {
    let mut error = None;
    let mut visit = |entry: &DataTableEntry| {
        if error.is_none() {
            error = planner.entry(entry).err();
        }
    };
    check_passes(pass, per_pass, Some(&mut visit))?;
    Some(match error {
        Some(e) => Err(e),
        None => planner.finish(),
    })
}

/// A pass over the decompressed table: the stream's pieces go to the sink; `Whole` carries the
/// compressed length.
type Pass<'a> = dyn FnMut(&mut dyn FnMut(&[u8]) -> ControlFlow<()>) -> Option<Streamed> + 'a;

/// The check, over passes made by `pass`; the compressed length when the table is valid. With
/// `visit`, each entry's values go to it in the table's order (`None` for an entry whose fields
/// lie past the bytes read of its table).
fn check_passes(
    pass: &mut Pass,
    per_pass: usize,
    mut visit: Option<&mut dyn FnMut(&DataTableEntry)>,
) -> Option<u64> {
    let mut head = Vec::with_capacity(HEAD);
    pass(&mut |piece| {
        let take = piece.len().min(HEAD - head.len());
        head.extend_from_slice(&piece[..take]);
        if head.len() == HEAD {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })?;
    let root = Root::read(&head)?;
    let mut totals = Totals {
        apparent: root.apparent,
        tables: 1,
    };
    let mut vtables: HashMap<u64, Vtable> = HashMap::new();
    let mut first = 0u64;
    // At least one pass, which also checks that the stream decompresses and holds the body.
    let compressed = loop {
        let last = root.entries.min(first + per_pass as u64);
        let mut walk = Walk::new(&root, first, last, &vtables, visit.is_some());
        let Streamed::Whole(length) = pass(&mut |piece| walk.piece(piece))? else {
            return None;
        };
        if walk.failed || walk.total < root.body || !walk.pending.is_empty() {
            return None;
        }
        let Walk {
            tables,
            captured,
            found,
            behind,
            ..
        } = walk;
        vtables.extend(found);
        if !behind.is_empty() {
            // Vtables the stream passed before an entry named them.
            let mut walk = Walk::vtables(&root, behind);
            pass(&mut |piece| walk.piece(piece))?;
            if walk.failed || !walk.pending.is_empty() {
                return None;
            }
            vtables.extend(walk.found);
        }
        if vtables.len() > MAX_VTABLES {
            return None;
        }
        for (table, vt) in tables {
            totals.entry(&root, table, (vt, vtables.get(&vt)?))?;
        }
        if let Some(visit) = visit.as_mut() {
            // In the table's order: a builder writes the entries' tables backwards.
            let mut captured = captured;
            captured.sort_unstable_by_key(|c| c.0);
            for (_, vt, bytes, read) in &captured {
                visit(&entry_of(vtables.get(vt)?, &bytes[..usize::from(*read)])?);
            }
        }
        first = last;
        if first >= root.entries {
            break length;
        }
    };
    let max_tables = (root.body / 4).max(1_000_000);
    (totals.tables <= max_tables && totals.apparent <= MAX_APPARENT_SIZE).then_some(compressed)
}

/// The root of the table, read from its head: where the entries' offsets are.
struct Root {
    /// Length of the verified body (size prefix included), bytes.
    body: u64,
    /// Position of the first entry's offset.
    start: u64,
    /// Entries in the vector.
    entries: u64,
    /// The verifier's apparent size of everything read before the entries.
    apparent: u64,
}

impl Root {
    /// Follows the verifier from the size prefix to the vector's length, within `head`.
    fn read(head: &[u8]) -> Option<Self> {
        let u32_at = |pos: u64| -> Option<u32> {
            let p = usize::try_from(pos).ok()?;
            Some(u32::from_le_bytes(*head.get(p..)?.first_chunk::<4>()?))
        };
        let u16_at = |pos: u64| -> Option<u16> {
            let p = usize::try_from(pos).ok()?;
            Some(u16::from_le_bytes(*head.get(p..)?.first_chunk::<2>()?))
        };
        let body = u64::from(u32_at(0)?) + 4;
        let ident = head.get(8..12)?;
        if body < 12 || ident != FILE_DATA_TABLE_IDENTIFIER.as_bytes() {
            return None;
        }
        let fits = |pos: u64, size: u64| pos.checked_add(size).is_some_and(|end| end <= body);
        // The root offset (the verifier's positions count from the size prefix).
        let mut apparent = 4;
        let root = 4 + u64::from(u32_at(4)?);
        // The root table: its vtable, and the `Table` field.
        let vtable = vtable_of(root, u32_at(root)? as i32, body)?;
        let vtable_len = u64::from(u16_at(vtable)?);
        if !vtable.is_multiple_of(2)
            || !(vtable + vtable_len).is_multiple_of(2)
            || !fits(vtable, vtable_len.max(2))
        {
            return None;
        }
        apparent += 4 + 2 + vtable_len;
        let field = u64::from(FileDataTable::VT_TABLE);
        let offset = if field < vtable_len {
            apparent += 2;
            u16_at(vtable + field)?
        } else {
            0
        };
        if offset == 0 {
            // No entries.
            return Some(Self {
                body,
                start: 0,
                entries: 0,
                apparent,
            });
        }
        // The field's offset to the vector, and the vector's length and offsets.
        let field_pos = root + u64::from(offset);
        if !field_pos.is_multiple_of(4) || !fits(field_pos, 4) {
            return None;
        }
        let vector = field_pos + u64::from(u32_at(field_pos)?);
        if !vector.is_multiple_of(4) || !fits(vector, 4) {
            return None;
        }
        let entries = u64::from(u32_at(vector)?);
        let start = vector + 4;
        if !fits(start, entries * 4) {
            return None;
        }
        apparent += 4 + 4 + 4 * entries;
        Some(Self {
            body,
            start,
            entries,
            apparent,
        })
    }
}

/// Where the table at `table` with signed offset `soffset` has its vtable (`None` outside
/// the body, and for a table that does not fit: the verifier's `deref_soffset`).
fn vtable_of(table: u64, soffset: i32, body: u64) -> Option<u64> {
    if !table.is_multiple_of(4) || table + 4 > body {
        return None;
    }
    let vtable = if soffset > 0 {
        table.checked_sub(u64::from(soffset.unsigned_abs()))?
    } else {
        table + u64::from(soffset.unsigned_abs())
    };
    (vtable < body).then_some(vtable)
}

/// The start of a vtable: its length and up to five field offsets (bytes past its end are 0).
#[derive(Debug, Clone, Copy)]
struct Vtable {
    bytes: [u8; VTABLE_READ as usize],
    /// Bytes read (a vtable near the body's end has fewer).
    read: usize,
}

impl Vtable {
    fn u16_at(&self, at: usize) -> Option<u16> {
        (at + 2 <= self.read).then(|| u16::from_le_bytes([self.bytes[at], self.bytes[at + 1]]))
    }
}

/// An entry's values from its vtable and the first bytes of its table, as
/// `FileDataDefinition::entry` reads them (a field left out is 0); `None` when a field lies
/// past `table`.
fn entry_of(vtable: &Vtable, table: &[u8]) -> Option<DataTableEntry> {
    let len = vtable.u16_at(0)?;
    let field = |slot: u16, size: usize| -> Option<Option<&[u8]>> {
        if slot >= len {
            return Some(None);
        }
        match usize::from(vtable.u16_at(usize::from(slot))?) {
            0 => Some(None),
            at => table.get(at..at + size).map(Some),
        }
    };
    let eight = |b: Option<&[u8]>| b.and_then(|b| b.first_chunk::<8>()).copied();
    let int = |slot| Some(eight(field(slot, 8)?).map_or(0, i64::from_le_bytes));
    let header =
        FbPacketHeader(eight(field(FileDataDefinition::VT_PACKETINFO, 8)?).unwrap_or_default());
    Some(DataTableEntry {
        byte_offset: int(FileDataDefinition::VT_BYTEOFFSET)?,
        stream_id: header.stream_id(),
        size: header.size(),
        num_elements: int(FileDataDefinition::VT_NUMELEMENTS)?,
        timestamp_start: int(FileDataDefinition::VT_TIMESTAMPSTART)?,
        timestamp_end: int(FileDataDefinition::VT_TIMESTAMPEND)?,
    })
}

/// The verifier's running totals.
struct Totals {
    apparent: u64,
    tables: u64,
}

impl Totals {
    /// Checks the entry table at `table` with `vtable` (at `vt`) as the verifier would, adding
    /// to the totals; `None` when it would fail.
    fn entry(&mut self, root: &Root, table: u64, (vt, vtable): (u64, &Vtable)) -> Option<()> {
        let body = root.body;
        let len = u64::from(vtable.u16_at(0)?);
        if !vt.is_multiple_of(2) || !(vt + len).is_multiple_of(2) || vt + len > body {
            return None;
        }
        // The entry's offset, its soffset, the vtable's length and the vtable.
        self.apparent += 4 + 4 + 2 + len;
        self.tables += 1;
        let fields = [
            (FileDataDefinition::VT_BYTEOFFSET, 8),
            (FileDataDefinition::VT_PACKETINFO, 1),
            (FileDataDefinition::VT_NUMELEMENTS, 8),
            (FileDataDefinition::VT_TIMESTAMPSTART, 8),
            (FileDataDefinition::VT_TIMESTAMPEND, 8),
        ];
        for (field, align) in fields {
            let field = u64::from(field);
            if field >= len {
                continue;
            }
            self.apparent += 2;
            let offset = u64::from(vtable.u16_at(field as usize)?);
            if offset > 0 {
                let pos = table + offset;
                if !pos.is_multiple_of(align) || pos + 8 > body {
                    return None;
                }
                self.apparent += 8;
            }
        }
        Some(())
    }
}

/// A read waiting for the stream to reach it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Want {
    /// Entry `i`'s offset (4 bytes).
    Entry(u64),
    /// Entry `i`'s table's soffset (4 bytes, or its first bytes when capturing).
    Table(u64),
    /// A vtable's first bytes.
    Vtable,
}

/// One pass over the stream, following entries `[first, last)` to their tables and vtables.
struct Walk<'a> {
    root: &'a Root,
    last: u64,
    /// Vtables known from earlier passes.
    known: Option<&'a HashMap<u64, Vtable>>,
    /// Reads by position (and a sequence number, as a position may be wanted twice).
    pending: BTreeMap<(u64, u64), Want>,
    seq: u64,
    /// The last bytes of the previous piece, so that a read may straddle two pieces.
    window: Vec<u8>,
    /// Stream position of `window[0]`.
    window_at: u64,
    /// Bytes streamed so far.
    total: u64,
    /// Each followed entry's table and vtable positions.
    tables: Vec<(u64, u64)>,
    /// With `capture`, each followed entry's table's first bytes (and how many were read).
    capture: bool,
    /// Entry, vtable position, bytes, bytes read; in the stream's order (a builder writes tables backwards).
    captured: Vec<(u64, u64, [u8; TABLE_READ as usize], u8)>,
    /// Vtables read in this pass.
    found: HashMap<u64, Vtable>,
    /// Vtables asked for in this pass (read, pending or behind), so each is asked for once.
    wanted: HashSet<u64>,
    /// Vtables named after the stream had passed them.
    behind: Vec<u64>,
    failed: bool,
}

/// Longest read, bytes: what a window keeps of the previous piece.
const LONGEST_READ: usize = TABLE_READ as usize;

impl<'a> Walk<'a> {
    fn new(
        root: &'a Root,
        first: u64,
        last: u64,
        known: &'a HashMap<u64, Vtable>,
        capture: bool,
    ) -> Self {
        let mut walk = Self::empty(root, last, Some(known));
        walk.capture = capture;
        if first < last {
            walk.want(root.start + 4 * first, Want::Entry(first));
        }
        walk
    }

    /// A pass reading the vtables at `positions` only.
    fn vtables(root: &'a Root, positions: Vec<u64>) -> Self {
        let mut walk = Self::empty(root, 0, None);
        for p in positions {
            walk.want(p, Want::Vtable);
        }
        walk
    }

    fn empty(root: &'a Root, last: u64, known: Option<&'a HashMap<u64, Vtable>>) -> Self {
        Self {
            root,
            last,
            known,
            pending: BTreeMap::new(),
            seq: 0,
            window: Vec::with_capacity(super::table_stream::PIECE + LONGEST_READ),
            window_at: 0,
            total: 0,
            tables: Vec::new(),
            capture: false,
            captured: Vec::new(),
            found: HashMap::new(),
            wanted: HashSet::new(),
            behind: Vec::new(),
            failed: false,
        }
    }

    fn want(&mut self, pos: u64, want: Want) {
        self.pending.insert((pos, self.seq), want);
        self.seq += 1;
    }

    /// Bytes a read takes at `pos`.
    fn size(&self, pos: u64, want: Want) -> u64 {
        match want {
            Want::Vtable => VTABLE_READ.min(self.root.body.saturating_sub(pos)),
            // At least the soffset, as without capturing (the check of its bounds follows).
            Want::Table(_) if self.capture => {
                TABLE_READ.min(self.root.body.saturating_sub(pos)).max(4)
            }
            _ => 4,
        }
    }

    /// Takes the next piece of the stream.
    fn piece(&mut self, piece: &[u8]) -> ControlFlow<()> {
        let keep = self.window.len().min(LONGEST_READ);
        self.window.drain(..self.window.len() - keep);
        self.window_at = self.total - keep as u64;
        self.window.extend_from_slice(piece);
        self.total += piece.len() as u64;
        while let Some((&(pos, seq), &want)) = self.pending.first_key_value() {
            let size = self.size(pos, want);
            if pos < self.window_at {
                // Only a vtable can lie behind (entries and tables lie after what names them).
                self.pending.remove(&(pos, seq));
                match want {
                    Want::Vtable => self.behind.push(pos),
                    _ => self.failed = true,
                }
                continue;
            }
            if pos + size > self.total {
                break;
            }
            self.pending.remove(&(pos, seq));
            let (at, size) = ((pos - self.window_at) as usize, size as usize);
            let mut bytes = [0u8; LONGEST_READ];
            bytes[..size].copy_from_slice(&self.window[at..at + size]);
            self.got(pos, want, &bytes[..size]);
        }
        if self.failed {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }

    /// A read is complete.
    fn got(&mut self, pos: u64, want: Want, bytes: &[u8]) {
        let word = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        match want {
            Want::Entry(i) => {
                let table = pos + u64::from(word(bytes));
                // A table at its own offset would be read from bytes already passed.
                if table < pos + 4 {
                    self.failed = true;
                    return;
                }
                self.want(table, Want::Table(i));
                if i + 1 < self.last {
                    self.want(pos + 4, Want::Entry(i + 1));
                }
            }
            Want::Table(i) => {
                let Some(vtable) = vtable_of(pos, word(bytes) as i32, self.root.body) else {
                    self.failed = true;
                    return;
                };
                self.tables.push((pos, vtable));
                if self.capture {
                    let mut table = [0u8; TABLE_READ as usize];
                    table[..bytes.len()].copy_from_slice(bytes);
                    self.captured.push((i, vtable, table, bytes.len() as u8));
                }
                let known = self.known.is_some_and(|k| k.contains_key(&vtable));
                if !known && !self.wanted.contains(&vtable) {
                    if self.wanted.len() + self.behind.len() > MAX_VTABLES {
                        self.failed = true;
                        return;
                    }
                    self.wanted.insert(vtable);
                    self.want(vtable, Want::Vtable);
                }
            }
            Want::Vtable => {
                let mut v = Vtable {
                    bytes: [0; VTABLE_READ as usize],
                    read: bytes.len(),
                };
                v.bytes[..bytes.len()].copy_from_slice(bytes);
                self.found.insert(pos, v);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::compression::{Compressor, Decompressor};
    use super::super::header::StreamKind;
    use super::super::packet::StreamState;
    use super::super::packet::check_data_table;
    use super::super::schema::{DataTableEntry, build_file_data_table};
    use super::*;
    use std::io::Cursor;

    const ALL: [Compression; 3] = [Compression::None, Compression::Lz4, Compression::Zstd];

    /// A decompressed table of `n` entries as the writer builds it; every third entry has no
    /// elements (its `NumElements` is left out, so two vtables).
    fn table(n: usize) -> Vec<u8> {
        let entries: Vec<DataTableEntry> = (0..n as i64)
            .map(|i| DataTableEntry {
                byte_offset: 100 + 64 * i,
                stream_id: (i % 2) as i32,
                size: 56,
                num_elements: if i % 3 == 0 { 0 } else { 7 },
                timestamp_start: 1000 * i,
                timestamp_end: 1000 * i + 999,
            })
            .collect();
        let mut fbb = flatbuffers::FlatBufferBuilder::new();
        build_file_data_table(&mut fbb, &entries);
        fbb.finished_data().to_vec()
    }

    fn compress(table: &[u8], c: Compression) -> Vec<u8> {
        Compressor::new(c)
            .unwrap()
            .compress(table)
            .unwrap()
            .to_vec()
    }

    /// What verifying the whole table says: whether it decompresses and verifies.
    fn whole(compressed: &[u8], c: Compression) -> bool {
        let mut d = Decompressor::new(c);
        d.input().extend_from_slice(compressed);
        d.decompress()
            .is_ok_and(|payload| check_data_table(payload, 0).is_ok())
    }

    /// The streamed check of `compressed`, its stream cut into pieces of `piece` bytes (a
    /// vtable the pieces have passed is then read in a pass of its own).
    fn streamed(compressed: &[u8], c: Compression, per_pass: usize, piece: usize) -> Verdict {
        let mut pass = |sink: &mut dyn FnMut(&[u8]) -> ControlFlow<()>| {
            let mut input = compressed;
            stream(&mut input, c, &mut |p| {
                p.chunks(piece).try_for_each(&mut *sink)
            })
            .map(|s| match s {
                Streamed::Whole(_) => Streamed::Whole(compressed.len() as u64),
                stopped => stopped,
            })
        };
        check_passes(&mut pass, per_pass, None).map_or(Verdict::Unsure, Verdict::Valid)
    }

    #[test]
    fn good_tables_are_valid_in_any_number_of_passes() {
        for c in ALL {
            for n in [0, 1, 5, 300] {
                let compressed = compress(&table(n), c);
                let valid = Verdict::Valid(compressed.len() as u64);
                for per_pass in [1, 7, ENTRIES_PER_PASS] {
                    for piece in [1, 5, 64 << 10] {
                        assert_eq!(
                            streamed(&compressed, c, per_pass, piece),
                            valid,
                            "{c}, {n} entries, {per_pass} a pass, pieces of {piece}"
                        );
                    }
                }
                // Through a reader that seeks, as the AEDAT reader calls it.
                let mut cursor = Cursor::new(compressed.clone());
                let seek: fn(&mut Cursor<Vec<u8>>, u64) -> std::io::Result<()> = |r, at| {
                    r.set_position(at);
                    Ok(())
                };
                assert_eq!(check(&mut cursor, seek, 0, c, 3), valid, "{c}");
            }
        }
    }

    /// DV's own table (written by the C++ flatbuffers builder, a real DVXplorer recording) is
    /// vouched for in passes: a real session's check holds constant memory too.
    #[test]
    fn a_dv_written_table_is_valid_streamed() {
        use std::io::{Seek, SeekFrom};
        let Some(path) = evtac_testkit::real_fixture("dvxplorer_320x240_imu.aedat4") else {
            return;
        };
        let reader = super::super::AedatReader::open(&path).unwrap();
        let (position, c) = (
            reader.header().data_table_position.unwrap(),
            reader.compression(),
        );
        let mut file = reader.into_inner();
        let seek: fn(&mut std::io::BufReader<std::fs::File>, u64) -> std::io::Result<()> =
            |r, at| r.seek(SeekFrom::Start(at)).map(drop);
        let length = std::fs::metadata(&path).unwrap().len() - position;
        for per_pass in [3, ENTRIES_PER_PASS] {
            assert_eq!(
                check(&mut file, seek, position, c, per_pass),
                Verdict::Valid(length)
            );
        }
    }

    /// Every byte of a table damaged (three ways), then compressed: the streamed check calls
    /// valid only what the whole verifier accepts, and still vouches for damage the verifier
    /// cannot see (a changed timestamp).
    #[test]
    fn the_streamed_check_never_passes_a_table_the_verifier_rejects() {
        let good = table(12);
        for c in ALL {
            let (mut valid, mut unsure) = (0, 0);
            for at in 0..good.len() {
                for flip in [0x01u8, 0x80, 0xff] {
                    let mut bad = good.clone();
                    bad[at] ^= flip;
                    let compressed = compress(&bad, c);
                    match streamed(&compressed, c, 5, 3) {
                        Verdict::Valid(_) => {
                            assert!(whole(&compressed, c), "{c}: byte {at} ^ {flip:#x} passed");
                            valid += 1;
                        }
                        Verdict::Unsure => unsure += 1,
                    }
                }
            }
            assert!(
                valid > 0 && unsure > 0,
                "{c}: {valid} valid, {unsure} unsure"
            );
        }
    }

    /// The packets of [`table`]'s entries fill `92 .. 92 + 64 n` (each body 8 bytes after
    /// its header) in streams 0 (events) and 1 (IMU).
    fn streams() -> Vec<StreamState> {
        let state = |id, kind| StreamState {
            decoded: true,
            id,
            kind,
            resolution: None,
            count: 0,
            last_t: i64::MIN,
        };
        vec![state(0, StreamKind::Events), state(1, StreamKind::Imu)]
    }

    /// The streamed plan of `compressed` for `[from, to)`, its stream cut into pieces.
    fn plan_streamed(
        compressed: &[u8],
        c: Compression,
        (per_pass, piece): (usize, usize),
        position: u64,
        (from, to): (i64, i64),
    ) -> Option<Result<Plan, String>> {
        let streams = streams();
        let planner = Planner::new(92, position, &streams, from, to);
        let mut pass = |sink: &mut dyn FnMut(&[u8]) -> ControlFlow<()>| {
            let mut input = compressed;
            stream(&mut input, c, &mut |p| {
                p.chunks(piece).try_for_each(&mut *sink)
            })
        };
        plan_passes(&mut pass, per_pass, planner)
    }

    /// The whole table's plan (what the reader falls back to).
    fn plan_whole(
        compressed: &[u8],
        c: Compression,
        position: u64,
        (from, to): (i64, i64),
    ) -> Result<Plan, String> {
        let mut d = Decompressor::new(c);
        d.input().extend_from_slice(compressed);
        let payload = d.decompress().map_err(|e| e.to_string())?;
        super::super::index::plan(payload, 92, position, &streams(), from, to)
    }

    /// Planned in passes of any size from a stream in pieces of any size, a range read selects
    /// the packets the whole table selects, for ranges before, inside, across and after the
    /// entries (and a table that ends elsewhere gets the same error).
    #[test]
    fn the_streamed_plan_is_the_whole_plan_for_every_range() {
        let n = 300;
        let ranges: Vec<(i64, i64)> = [(-50, 0), (0, 1), (999, 1000), (12_345, 12_346)]
            .into_iter()
            .chain((0..40).map(|k| (k * 7919 % 300_000, k * 7919 % 300_000 + k * 977 + 1)))
            .chain([(290_000, 400_000), (300_000, 301_000), (i64::MIN, i64::MAX)])
            .collect();
        for c in ALL {
            let compressed = compress(&table(n), c);
            for position in [92 + 64 * n as u64, 92 + 64 * n as u64 + 8] {
                for &range in &ranges {
                    let whole = plan_whole(&compressed, c, position, range);
                    for setup in [(1, 3), (7, 5), (ENTRIES_PER_PASS, 64 << 10)] {
                        let streamed = plan_streamed(&compressed, c, setup, position, range);
                        assert_eq!(streamed.as_ref(), Some(&whole), "{c} {range:?} {setup:?}");
                    }
                }
                // The selection is not empty for every range.
                let all = plan_whole(&compressed, c, position, (i64::MIN, i64::MAX));
                assert!(all.is_err() || all.unwrap().packets.len() == 200, "{c}");
            }
        }
    }

    /// Every byte of a table damaged (three ways): the streamed plan, when it gives one, is the
    /// whole table's plan or error; otherwise the reader plans from the whole table.
    #[test]
    fn a_damaged_table_gets_the_whole_plans_result() {
        let good = table(12);
        let position = 92 + 64 * 12;
        let (mut planned, mut errors) = (0, 0);
        for c in ALL {
            for at in 0..good.len() {
                for flip in [0x01u8, 0x80, 0xff] {
                    let mut bad = good.clone();
                    bad[at] ^= flip;
                    let compressed = compress(&bad, c);
                    for range in [(0, 5_000), (3_500, 3_501), (i64::MIN, i64::MAX)] {
                        let whole = plan_whole(&compressed, c, position, range);
                        if let Some(streamed) =
                            plan_streamed(&compressed, c, (5, 3), position, range)
                        {
                            assert_eq!(streamed, whole, "{c}: byte {at} ^ {flip:#x}, {range:?}");
                            planned += 1;
                            errors += usize::from(streamed.is_err());
                        }
                    }
                }
            }
        }
        // Streamed plans of damaged tables, some of them the planner's errors.
        assert!(
            planned > errors && errors > 0,
            "{planned} planned, {errors} errors"
        );
    }

    /// Damage to the compressed bytes, and a table cut short anywhere: never valid unless the
    /// whole decompressor and verifier accept it.
    #[test]
    fn damaged_or_cut_compressed_tables_are_never_passed_wrongly() {
        let good = table(20);
        for c in ALL {
            let compressed = compress(&good, c);
            let mut cases: Vec<Vec<u8>> = (0..compressed.len())
                .map(|n| compressed[..n].to_vec())
                .collect();
            for at in 0..compressed.len() {
                let mut bad = compressed.clone();
                bad[at] ^= 0x5a;
                cases.push(bad);
            }
            let mut longer = compressed.clone();
            longer.extend_from_slice(&compressed);
            cases.push(longer);
            for bad in cases {
                if let Verdict::Valid(_) = streamed(&bad, c, 4, 7) {
                    assert!(whole(&bad, c), "{c}: {} bytes passed", bad.len());
                }
            }
        }
    }
}
