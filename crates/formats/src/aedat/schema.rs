//! Flatbuffers accessors for the AEDAT 4.0 schemas in `crates/formats/schema/*.fbs`.
//!
//! Written by hand in the shape `flatc --rust` 25.x emits (see `schema/README.md`): the only
//! `flatc` installable here (Debian's 2.0.8) generates code for the flatbuffers 2.x API, which no
//! longer compiles against the `flatbuffers` 25.12 crate. Only the tables and fields evtac reads or
//! writes are covered. Every reader entry point verifies the buffer first (`size_prefixed_root`);
//! no `_unchecked` root is ever taken on file bytes.

use flatbuffers::{
    FlatBufferBuilder, Follow, ForwardsUOffset, InvalidFlatbuffer, Push, Table, VOffsetT, Vector,
    VectorIter, Verifiable, Verifier, WIPOffset,
};

/// Defines a table type with a `Follow` impl and a `_tab` field, as flatc does.
macro_rules! table_type {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Copy, Clone, PartialEq)]
        pub struct $name<'a> {
            /// The underlying table (verified before it is handed out).
            pub _tab: Table<'a>,
        }

        impl<'a> Follow<'a> for $name<'a> {
            type Inner = $name<'a>;
            #[inline]
            unsafe fn follow(buf: &'a [u8], loc: usize) -> Self::Inner {
                // SAFETY: forwarded from the caller (flatc's generated shape); only reached after
                // the verifier accepted the buffer.
                Self { _tab: unsafe { Table::new(buf, loc) } }
            }
        }
    };
}

// ---------------------------------------------------------------------------------------------
// IOHeader.fbs
// ---------------------------------------------------------------------------------------------

/// `IOHeader.fbs` file identifier.
pub const IO_HEADER_IDENTIFIER: &str = "IOHE";

table_type!(
    /// The AEDAT 4.0 header table: compression, data-table position and the XML description.
    IoHeader
);

impl<'a> IoHeader<'a> {
    /// vtable slot of `compression`.
    pub const VT_COMPRESSION: VOffsetT = 4;
    /// vtable slot of `dataTablePosition`.
    pub const VT_DATATABLEPOSITION: VOffsetT = 6;
    /// vtable slot of `infoNode`.
    pub const VT_INFONODE: VOffsetT = 8;

    /// `compression` (the `CompressionType` enum as its raw `int32`; default `NONE` = 0).
    #[inline]
    pub fn compression(&self) -> i32 {
        // SAFETY: the table was verified with `IoHeader::run_verifier`.
        unsafe { self._tab.get::<i32>(Self::VT_COMPRESSION, Some(0)) }.unwrap_or(0)
    }

    /// `dataTablePosition` (default -1: no data table).
    #[inline]
    pub fn data_table_position(&self) -> i64 {
        // SAFETY: verified table.
        unsafe { self._tab.get::<i64>(Self::VT_DATATABLEPOSITION, Some(-1)) }.unwrap_or(-1)
    }

    /// `infoNode`: the XML stream description.
    #[inline]
    pub fn info_node(&self) -> Option<&'a str> {
        // SAFETY: verified table.
        unsafe {
            self._tab
                .get::<ForwardsUOffset<&str>>(Self::VT_INFONODE, None)
        }
    }
}

impl Verifiable for IoHeader<'_> {
    #[inline]
    fn run_verifier(v: &mut Verifier, pos: usize) -> Result<(), InvalidFlatbuffer> {
        v.visit_table(pos)?
            .visit_field::<i32>("compression", Self::VT_COMPRESSION, false)?
            .visit_field::<i64>("dataTablePosition", Self::VT_DATATABLEPOSITION, false)?
            .visit_field::<ForwardsUOffset<&str>>("infoNode", Self::VT_INFONODE, false)?
            .finish();
        Ok(())
    }
}

/// Verifies a size-prefixed `IOHeader` buffer and returns its root.
pub fn size_prefixed_root_as_io_header(buf: &[u8]) -> Result<IoHeader<'_>, InvalidFlatbuffer> {
    flatbuffers::size_prefixed_root::<IoHeader>(buf)
}

/// Builds a finished, size-prefixed `IOHeader` buffer into `fbb`.
pub fn build_io_header(
    fbb: &mut FlatBufferBuilder,
    compression: i32,
    data_table_position: i64,
    info_node: &str,
) {
    let info = fbb.create_string(info_node);
    let start = fbb.start_table();
    // flatc's builder adds fields largest-first: 8-byte, then 4-byte ones.
    fbb.push_slot::<i64>(IoHeader::VT_DATATABLEPOSITION, data_table_position, -1);
    fbb.push_slot_always::<WIPOffset<_>>(IoHeader::VT_INFONODE, info);
    fbb.push_slot::<i32>(IoHeader::VT_COMPRESSION, compression, 0);
    let root = fbb.end_table(start);
    fbb.finish_size_prefixed(
        WIPOffset::<IoHeader>::new(root.value()),
        Some(IO_HEADER_IDENTIFIER),
    );
}

// ---------------------------------------------------------------------------------------------
// Events.fbs
// ---------------------------------------------------------------------------------------------

/// `Events.fbs` file identifier.
pub const EVENT_PACKET_IDENTIFIER: &str = "EVTS";

/// `struct Event { timestamp: int64; x: int16; y: int16; polarity: bool; }`: 16 bytes, aligned
/// to 8 (three bytes of padding after `polarity`), stored as raw little-endian bytes as flatc does.
#[repr(transparent)]
#[derive(Clone, Copy, PartialEq, Default)]
pub struct FbEvent(pub [u8; 16]);

impl FbEvent {
    /// Packs an event (padding zeroed, so the bytes are deterministic).
    #[inline]
    pub fn new(timestamp: i64, x: i16, y: i16, polarity: bool) -> Self {
        let mut b = [0u8; 16];
        b[0..8].copy_from_slice(&timestamp.to_le_bytes());
        b[8..10].copy_from_slice(&x.to_le_bytes());
        b[10..12].copy_from_slice(&y.to_le_bytes());
        b[12] = u8::from(polarity);
        Self(b)
    }
}

impl flatbuffers::SimpleToVerifyInSlice for FbEvent {}

impl<'a> Follow<'a> for &'a FbEvent {
    type Inner = &'a FbEvent;
    #[inline]
    unsafe fn follow(buf: &'a [u8], loc: usize) -> Self::Inner {
        // SAFETY: forwarded from the caller; `FbEvent` is a `repr(transparent)` byte array with
        // alignment 1, so any in-bounds location is a valid reference.
        unsafe { flatbuffers::follow_cast_ref::<FbEvent>(buf, loc) }
    }
}

impl<'a> Follow<'a> for FbEvent {
    type Inner = &'a FbEvent;
    #[inline]
    unsafe fn follow(buf: &'a [u8], loc: usize) -> Self::Inner {
        // SAFETY: forwarded from the caller.
        unsafe { <&'a FbEvent>::follow(buf, loc) }
    }
}

impl Push for FbEvent {
    type Output = FbEvent;
    #[inline]
    unsafe fn push(&self, dst: &mut [u8], _written_len: usize) {
        // Safe copy: `dst` is at least `size()` = 16 bytes long (Push's contract).
        dst[..16].copy_from_slice(&self.0);
    }
    #[inline]
    fn alignment() -> flatbuffers::PushAlignment {
        // The schema struct holds an int64: flatbuffers aligns it to 8 in the buffer.
        flatbuffers::PushAlignment::new(8)
    }
}

impl Verifiable for FbEvent {
    #[inline]
    fn run_verifier(v: &mut Verifier, pos: usize) -> Result<(), InvalidFlatbuffer> {
        v.in_buffer::<Self>(pos)
    }
}

table_type!(
    /// `table EventPacket { elements: [Event]; }`
    EventPacket
);

impl<'a> EventPacket<'a> {
    /// vtable slot of `elements`.
    pub const VT_ELEMENTS: VOffsetT = 4;

    /// The packed events as raw bytes (16 per event), or `None` when the field is absent.
    #[inline]
    pub fn elements_bytes(&self) -> Option<&'a [u8]> {
        // SAFETY: verified table; the vector range was checked by the verifier.
        unsafe {
            self._tab
                .get::<ForwardsUOffset<Vector<'a, FbEvent>>>(Self::VT_ELEMENTS, None)
        }
        .map(|v| v.bytes())
    }
}

impl Verifiable for EventPacket<'_> {
    #[inline]
    fn run_verifier(v: &mut Verifier, pos: usize) -> Result<(), InvalidFlatbuffer> {
        v.visit_table(pos)?
            .visit_field::<ForwardsUOffset<Vector<'_, FbEvent>>>(
                "elements",
                Self::VT_ELEMENTS,
                false,
            )?
            .finish();
        Ok(())
    }
}

/// Verifies a size-prefixed `EventPacket` buffer and returns its root.
pub fn size_prefixed_root_as_event_packet(
    buf: &[u8],
) -> Result<EventPacket<'_>, InvalidFlatbuffer> {
    flatbuffers::size_prefixed_root::<EventPacket>(buf)
}

/// Builds a finished, size-prefixed `EventPacket` buffer into `fbb`.
pub fn build_event_packet(fbb: &mut FlatBufferBuilder, events: &[FbEvent]) {
    let elements = fbb.create_vector(events);
    let start = fbb.start_table();
    fbb.push_slot_always::<WIPOffset<_>>(EventPacket::VT_ELEMENTS, elements);
    let root = fbb.end_table(start);
    fbb.finish_size_prefixed(
        WIPOffset::<EventPacket>::new(root.value()),
        Some(EVENT_PACKET_IDENTIFIER),
    );
}

// ---------------------------------------------------------------------------------------------
// IMU.fbs
// ---------------------------------------------------------------------------------------------

/// `IMU.fbs` file identifier.
pub const IMU_PACKET_IDENTIFIER: &str = "IMUS";

table_type!(
    /// `table IMU { timestamp: int64; temperature: float; accelerometerX..Z: float;
    /// gyroscopeX..Z: float; magnetometerX..Z: float; }`
    Imu
);

impl<'a> Imu<'a> {
    /// vtable slot of `timestamp`.
    pub const VT_TIMESTAMP: VOffsetT = 4;
    /// vtable slot of `temperature`.
    pub const VT_TEMPERATURE: VOffsetT = 6;
    /// vtable slot of `accelerometerX` (Y and Z follow at +2 and +4).
    pub const VT_ACCELEROMETERX: VOffsetT = 8;
    /// vtable slot of `gyroscopeX` (Y and Z follow at +2 and +4).
    pub const VT_GYROSCOPEX: VOffsetT = 14;
    /// vtable slot of `magnetometerX` (Y and Z follow at +2 and +4).
    pub const VT_MAGNETOMETERX: VOffsetT = 20;
    /// Number of float fields after `timestamp` (temperature + 3 x 3 vectors).
    const FLOATS: VOffsetT = 10;

    /// `timestamp` (microseconds, default 0).
    #[inline]
    pub fn timestamp(&self) -> i64 {
        // SAFETY: verified table.
        unsafe { self._tab.get::<i64>(Self::VT_TIMESTAMP, Some(0)) }.unwrap_or(0)
    }

    /// A float field by vtable slot (default 0.0).
    #[inline]
    pub fn float(&self, slot: VOffsetT) -> f32 {
        // SAFETY: verified table; every float slot is checked by `run_verifier`.
        unsafe { self._tab.get::<f32>(slot, Some(0.0)) }.unwrap_or(0.0)
    }
}

impl Verifiable for Imu<'_> {
    #[inline]
    fn run_verifier(v: &mut Verifier, pos: usize) -> Result<(), InvalidFlatbuffer> {
        let mut t = v.visit_table(pos)?;
        t = t.visit_field::<i64>("timestamp", Self::VT_TIMESTAMP, false)?;
        for i in 0..Self::FLOATS {
            t = t.visit_field::<f32>("float field", Self::VT_TEMPERATURE + 2 * i, false)?;
        }
        t.finish();
        Ok(())
    }
}

table_type!(
    /// `table IMUPacket { elements: [IMU]; }`
    ImuPacket
);

impl<'a> ImuPacket<'a> {
    /// vtable slot of `elements`.
    pub const VT_ELEMENTS: VOffsetT = 4;

    /// The samples, or `None` when the field is absent.
    #[inline]
    pub fn elements(&self) -> Option<Vector<'a, ForwardsUOffset<Imu<'a>>>> {
        // SAFETY: verified table.
        unsafe {
            self._tab
                .get::<ForwardsUOffset<Vector<'a, ForwardsUOffset<Imu>>>>(Self::VT_ELEMENTS, None)
        }
    }
}

impl Verifiable for ImuPacket<'_> {
    #[inline]
    fn run_verifier(v: &mut Verifier, pos: usize) -> Result<(), InvalidFlatbuffer> {
        v.visit_table(pos)?
            .visit_field::<ForwardsUOffset<Vector<'_, ForwardsUOffset<Imu>>>>(
                "elements",
                Self::VT_ELEMENTS,
                false,
            )?
            .finish();
        Ok(())
    }
}

/// Verifies a size-prefixed `IMUPacket` buffer and returns its root.
pub fn size_prefixed_root_as_imu_packet(buf: &[u8]) -> Result<ImuPacket<'_>, InvalidFlatbuffer> {
    flatbuffers::size_prefixed_root::<ImuPacket>(buf)
}

/// One IMU sample's fields in schema order after `timestamp`: temperature, accelerometer x/y/z,
/// gyroscope x/y/z, magnetometer x/y/z.
pub type ImuFields = [f32; 10];

/// Builds a finished, size-prefixed `IMUPacket` buffer into `fbb`.
pub fn build_imu_packet(fbb: &mut FlatBufferBuilder, samples: &[(i64, ImuFields)]) {
    let mut tables = Vec::with_capacity(samples.len());
    for (timestamp, floats) in samples {
        let start = fbb.start_table();
        fbb.push_slot::<i64>(Imu::VT_TIMESTAMP, *timestamp, 0);
        for (i, &f) in (0..).zip(floats.iter()) {
            fbb.push_slot::<f32>(Imu::VT_TEMPERATURE + 2 * i, f, 0.0);
        }
        let t = fbb.end_table(start);
        tables.push(WIPOffset::<Imu>::new(t.value()));
    }
    let elements = fbb.create_vector(&tables);
    let start = fbb.start_table();
    fbb.push_slot_always::<WIPOffset<_>>(ImuPacket::VT_ELEMENTS, elements);
    let root = fbb.end_table(start);
    fbb.finish_size_prefixed(
        WIPOffset::<ImuPacket>::new(root.value()),
        Some(IMU_PACKET_IDENTIFIER),
    );
}

// ---------------------------------------------------------------------------------------------
// Trigger.fbs
// ---------------------------------------------------------------------------------------------

/// `Trigger.fbs` file identifier.
pub const TRIGGER_PACKET_IDENTIFIER: &str = "TRIG";

table_type!(
    /// `table Trigger { timestamp: int64; type: TriggerType (int8); }`
    FbTrigger
);

impl<'a> FbTrigger<'a> {
    /// vtable slot of `timestamp`.
    pub const VT_TIMESTAMP: VOffsetT = 4;
    /// vtable slot of `type`.
    pub const VT_TYPE: VOffsetT = 6;

    /// `timestamp` (microseconds, default 0).
    #[inline]
    pub fn timestamp(&self) -> i64 {
        // SAFETY: verified table.
        unsafe { self._tab.get::<i64>(Self::VT_TIMESTAMP, Some(0)) }.unwrap_or(0)
    }

    /// `type` as its raw `int8` (default `TIMESTAMP_RESET` = 0).
    #[inline]
    pub fn type_(&self) -> i8 {
        // SAFETY: verified table.
        unsafe { self._tab.get::<i8>(Self::VT_TYPE, Some(0)) }.unwrap_or(0)
    }
}

impl Verifiable for FbTrigger<'_> {
    #[inline]
    fn run_verifier(v: &mut Verifier, pos: usize) -> Result<(), InvalidFlatbuffer> {
        v.visit_table(pos)?
            .visit_field::<i64>("timestamp", Self::VT_TIMESTAMP, false)?
            .visit_field::<i8>("type", Self::VT_TYPE, false)?
            .finish();
        Ok(())
    }
}

table_type!(
    /// `table TriggerPacket { elements: [Trigger]; }`
    TriggerPacket
);

impl<'a> TriggerPacket<'a> {
    /// vtable slot of `elements`.
    pub const VT_ELEMENTS: VOffsetT = 4;

    /// The triggers, or `None` when the field is absent.
    #[inline]
    pub fn elements(&self) -> Option<Vector<'a, ForwardsUOffset<FbTrigger<'a>>>> {
        // SAFETY: verified table.
        unsafe {
            self._tab
                .get::<ForwardsUOffset<Vector<'a, ForwardsUOffset<FbTrigger>>>>(
                    Self::VT_ELEMENTS,
                    None,
                )
        }
    }
}

impl Verifiable for TriggerPacket<'_> {
    #[inline]
    fn run_verifier(v: &mut Verifier, pos: usize) -> Result<(), InvalidFlatbuffer> {
        v.visit_table(pos)?
            .visit_field::<ForwardsUOffset<Vector<'_, ForwardsUOffset<FbTrigger>>>>(
                "elements",
                Self::VT_ELEMENTS,
                false,
            )?
            .finish();
        Ok(())
    }
}

/// Verifies a size-prefixed `TriggerPacket` buffer and returns its root.
pub fn size_prefixed_root_as_trigger_packet(
    buf: &[u8],
) -> Result<TriggerPacket<'_>, InvalidFlatbuffer> {
    flatbuffers::size_prefixed_root::<TriggerPacket>(buf)
}

/// Builds a finished, size-prefixed `TriggerPacket` buffer into `fbb` from `(timestamp, type)`
/// pairs, fields added largest-first as flatc's builder does (dv-processing's layout).
pub fn build_trigger_packet(fbb: &mut FlatBufferBuilder, triggers: &[(i64, i8)]) {
    let mut tables = Vec::with_capacity(triggers.len());
    for &(timestamp, type_) in triggers {
        let start = fbb.start_table();
        fbb.push_slot::<i64>(FbTrigger::VT_TIMESTAMP, timestamp, 0);
        fbb.push_slot::<i8>(FbTrigger::VT_TYPE, type_, 0);
        let t = fbb.end_table(start);
        tables.push(WIPOffset::<FbTrigger>::new(t.value()));
    }
    let elements = fbb.create_vector(&tables);
    let start = fbb.start_table();
    fbb.push_slot_always::<WIPOffset<_>>(TriggerPacket::VT_ELEMENTS, elements);
    let root = fbb.end_table(start);
    fbb.finish_size_prefixed(
        WIPOffset::<TriggerPacket>::new(root.value()),
        Some(TRIGGER_PACKET_IDENTIFIER),
    );
}

// ---------------------------------------------------------------------------------------------
// FileDataTable.fbs
// ---------------------------------------------------------------------------------------------

/// `FileDataTable.fbs` file identifier.
pub const FILE_DATA_TABLE_IDENTIFIER: &str = "FTAB";

/// `struct PacketHeader { StreamID: int32; Size: int32; }`: 8 bytes, aligned to 4.
#[repr(transparent)]
#[derive(Clone, Copy, PartialEq, Default)]
pub struct FbPacketHeader(pub [u8; 8]);

impl FbPacketHeader {
    /// Packs a packet header.
    pub fn new(stream_id: i32, size: i32) -> Self {
        let mut b = [0u8; 8];
        b[..4].copy_from_slice(&stream_id.to_le_bytes());
        b[4..].copy_from_slice(&size.to_le_bytes());
        Self(b)
    }

    /// `StreamID`.
    pub fn stream_id(&self) -> i32 {
        let [a, b, c, d, ..] = self.0;
        i32::from_le_bytes([a, b, c, d])
    }

    /// `Size`.
    pub fn size(&self) -> i32 {
        let [.., a, b, c, d] = self.0;
        i32::from_le_bytes([a, b, c, d])
    }
}

impl<'a> Follow<'a> for &'a FbPacketHeader {
    type Inner = &'a FbPacketHeader;
    #[inline]
    unsafe fn follow(buf: &'a [u8], loc: usize) -> Self::Inner {
        // SAFETY: forwarded from the caller; a byte array with alignment 1.
        unsafe { flatbuffers::follow_cast_ref::<FbPacketHeader>(buf, loc) }
    }
}

impl<'a> Follow<'a> for FbPacketHeader {
    type Inner = &'a FbPacketHeader;
    #[inline]
    unsafe fn follow(buf: &'a [u8], loc: usize) -> Self::Inner {
        // SAFETY: forwarded from the caller.
        unsafe { <&'a FbPacketHeader>::follow(buf, loc) }
    }
}

impl Push for FbPacketHeader {
    type Output = FbPacketHeader;
    #[inline]
    unsafe fn push(&self, dst: &mut [u8], _written_len: usize) {
        dst[..8].copy_from_slice(&self.0);
    }
    #[inline]
    fn alignment() -> flatbuffers::PushAlignment {
        flatbuffers::PushAlignment::new(4)
    }
}

impl Verifiable for FbPacketHeader {
    #[inline]
    fn run_verifier(v: &mut Verifier, pos: usize) -> Result<(), InvalidFlatbuffer> {
        v.in_buffer::<Self>(pos)
    }
}

table_type!(
    /// `table FileDataDefinition { ByteOffset: int64; PacketInfo: PacketHeader; NumElements:
    /// int64; TimestampStart: int64; TimestampEnd: int64; }`
    FileDataDefinition
);

/// One data-table entry, as plain values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DataTableEntry {
    /// Byte offset of the packet body (after its 8-byte header).
    pub byte_offset: i64,
    /// The packet's stream.
    pub stream_id: i32,
    /// The packet's (compressed) size.
    pub size: i32,
    /// Elements in the packet.
    pub num_elements: i64,
    /// First element's timestamp.
    pub timestamp_start: i64,
    /// Last element's timestamp.
    pub timestamp_end: i64,
}

impl<'a> FileDataDefinition<'a> {
    /// vtable slot of `ByteOffset`.
    pub const VT_BYTEOFFSET: VOffsetT = 4;
    /// vtable slot of `PacketInfo`.
    pub const VT_PACKETINFO: VOffsetT = 6;
    /// vtable slot of `NumElements`.
    pub const VT_NUMELEMENTS: VOffsetT = 8;
    /// vtable slot of `TimestampStart`.
    pub const VT_TIMESTAMPSTART: VOffsetT = 10;
    /// vtable slot of `TimestampEnd`.
    pub const VT_TIMESTAMPEND: VOffsetT = 12;

    /// The entry's values.
    pub fn entry(&self) -> DataTableEntry {
        // SAFETY (all gets): verified table.
        let int = |slot| unsafe { self._tab.get::<i64>(slot, Some(0)) }.unwrap_or(0);
        let header = unsafe { self._tab.get::<FbPacketHeader>(Self::VT_PACKETINFO, None) }
            .copied()
            .unwrap_or_default();
        DataTableEntry {
            byte_offset: int(Self::VT_BYTEOFFSET),
            stream_id: header.stream_id(),
            size: header.size(),
            num_elements: int(Self::VT_NUMELEMENTS),
            timestamp_start: int(Self::VT_TIMESTAMPSTART),
            timestamp_end: int(Self::VT_TIMESTAMPEND),
        }
    }
}

impl Verifiable for FileDataDefinition<'_> {
    #[inline]
    fn run_verifier(v: &mut Verifier, pos: usize) -> Result<(), InvalidFlatbuffer> {
        v.visit_table(pos)?
            .visit_field::<i64>("ByteOffset", Self::VT_BYTEOFFSET, false)?
            .visit_field::<FbPacketHeader>("PacketInfo", Self::VT_PACKETINFO, false)?
            .visit_field::<i64>("NumElements", Self::VT_NUMELEMENTS, false)?
            .visit_field::<i64>("TimestampStart", Self::VT_TIMESTAMPSTART, false)?
            .visit_field::<i64>("TimestampEnd", Self::VT_TIMESTAMPEND, false)?
            .finish();
        Ok(())
    }
}

table_type!(
    /// `table FileDataTable { Table: [FileDataDefinition]; }`
    FileDataTable
);

impl<'a> FileDataTable<'a> {
    /// vtable slot of `Table`.
    pub const VT_TABLE: VOffsetT = 4;

    /// The entries, or `None` when the field is absent.
    pub fn table(&self) -> Option<Vector<'a, ForwardsUOffset<FileDataDefinition<'a>>>> {
        // SAFETY: verified table.
        unsafe {
            self._tab
                .get::<ForwardsUOffset<Vector<'a, ForwardsUOffset<FileDataDefinition>>>>(
                    Self::VT_TABLE,
                    None,
                )
        }
    }
}

impl Verifiable for FileDataTable<'_> {
    #[inline]
    fn run_verifier(v: &mut Verifier, pos: usize) -> Result<(), InvalidFlatbuffer> {
        v.visit_table(pos)?
            .visit_field::<ForwardsUOffset<Vector<'_, ForwardsUOffset<FileDataDefinition>>>>(
                "Table",
                Self::VT_TABLE,
                false,
            )?
            .finish();
        Ok(())
    }
}

/// Verifies a size-prefixed `FileDataTable` buffer and returns its root.
///
/// The verifier's default limit of a million tables would reject the table of a recording of
/// more than a million packets (about 80 minutes of DV's events and IMU at 10 ms a packet): a
/// table takes at least 4 bytes, so the buffer's own size bounds the count instead.
pub fn size_prefixed_root_as_file_data_table(
    buf: &[u8],
) -> Result<FileDataTable<'_>, InvalidFlatbuffer> {
    let opts = flatbuffers::VerifierOptions {
        max_tables: (buf.len() / 4).max(1_000_000),
        ..Default::default()
    };
    flatbuffers::size_prefixed_root_with_opts::<FileDataTable>(&opts, buf)
}

/// Builds a finished, size-prefixed `FileDataTable` buffer into `fbb`.
pub fn build_file_data_table(fbb: &mut FlatBufferBuilder, entries: &[DataTableEntry]) {
    let mut tables = Vec::with_capacity(entries.len());
    for e in entries {
        let start = fbb.start_table();
        fbb.push_slot::<i64>(FileDataDefinition::VT_BYTEOFFSET, e.byte_offset, 0);
        fbb.push_slot::<i64>(FileDataDefinition::VT_NUMELEMENTS, e.num_elements, 0);
        fbb.push_slot::<i64>(FileDataDefinition::VT_TIMESTAMPSTART, e.timestamp_start, 0);
        fbb.push_slot::<i64>(FileDataDefinition::VT_TIMESTAMPEND, e.timestamp_end, 0);
        fbb.push_slot_always::<&FbPacketHeader>(
            FileDataDefinition::VT_PACKETINFO,
            &FbPacketHeader::new(e.stream_id, e.size),
        );
        let t = fbb.end_table(start);
        tables.push(WIPOffset::<FileDataDefinition>::new(t.value()));
    }
    let list = fbb.create_vector(&tables);
    let start = fbb.start_table();
    fbb.push_slot_always::<WIPOffset<_>>(FileDataTable::VT_TABLE, list);
    let root = fbb.end_table(start);
    fbb.finish_size_prefixed(
        WIPOffset::<FileDataTable>::new(root.value()),
        Some(FILE_DATA_TABLE_IDENTIFIER),
    );
}

/// Iterates a verified vector of tables (re-exported so callers need not name flatbuffers types).
pub type TableIter<'a, T> = VectorIter<'a, ForwardsUOffset<T>>;
