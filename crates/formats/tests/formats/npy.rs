//! NPY: round trips, chunk invariance, interop with numpy both ways, bad input.

use evtac_events::Event;
use evtac_formats::npy::{NpyError, NpyReader, NpyWriter};
use evtac_testkit::run_python;
use proptest::prelude::*;

use crate::common::{self, READ_SIZES, Trickle, synthetic_events};

fn write(events: &[Event]) -> Vec<u8> {
    let mut w = NpyWriter::new(std::io::Cursor::new(Vec::new())).unwrap();
    w.write_events(events).unwrap();
    w.finish().unwrap().into_inner()
}

fn read_all<R: std::io::Read>(source: R) -> Result<Vec<Event>, NpyError> {
    NpyReader::new(source)?.read_to_end()
}

#[test]
fn round_trip_and_chunk_invariance() {
    let events = synthetic_events(40_000, 1280, 720);
    let bytes = write(&events);
    for step in READ_SIZES {
        assert_eq!(
            read_all(Trickle {
                bytes: &bytes,
                step
            })
            .unwrap(),
            events,
            "read size {step}"
        );
    }
}

/// numpy reads what we write: same count, same values (summed per field), same dtype names.
#[test]
fn numpy_reads_our_npy() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ours.npy");
    let events = synthetic_events(1000, 640, 480);
    std::fs::write(&path, write(&events)).unwrap();
    let script = "import sys, numpy as np\n\
                  a = np.load(sys.argv[1])\n\
                  print(a.dtype.names, len(a), int(a['t'].sum()), int(a['x'].sum()), \
                  int(a['y'].sum()), int(a['p'].sum()), a['t'].dtype, a['x'].dtype, a['p'].dtype)";
    let Some(out) = run_python(script, &[path.to_str().unwrap()]) else {
        return;
    };
    let sum = |f: fn(&Event) -> i64| events.iter().map(f).sum::<i64>();
    let expected = format!(
        "('t', 'x', 'y', 'p') 1000 {} {} {} {} int64 int16 uint8",
        sum(|e| e.t),
        sum(|e| i64::from(e.x)),
        sum(|e| i64::from(e.y)),
        sum(|e| i64::from(e.polarity)),
    );
    assert_eq!(out.trim(), expected);
}

/// We read what numpy writes, packed and aligned, in numpy's own field order variants.
#[test]
fn we_read_numpy_written_npy() {
    let dir = tempfile::tempdir().unwrap();
    let script = "import sys, numpy as np\n\
                  n = 500\n\
                  t = np.arange(n, dtype=np.int64) * 3 + 7\n\
                  x = (np.arange(n) * 7 % 640).astype(np.int16)\n\
                  y = (np.arange(n) * 5 % 480).astype(np.int16)\n\
                  p = (np.arange(n) % 2).astype(np.uint8)\n\
                  for name, dt in [('packed', np.dtype([('t','<i8'),('x','<i2'),('y','<i2'),('p','u1')])),\n\
                                   ('aligned', np.dtype([('t','<i8'),('x','<i2'),('y','<i2'),('p','u1')], align=True)),\n\
                                   ('reordered', np.dtype([('p','?'),('x','<u2'),('y','<u2'),('t','<i8')]))]:\n\
                  \x20   a = np.zeros(n, dtype=dt)\n\
                  \x20   a['t'] = t; a['x'] = x; a['y'] = y; a['p'] = p\n\
                  \x20   np.save(sys.argv[1] + '/' + name + '.npy', a)\n";
    let Some(_) = run_python(script, &[dir.path().to_str().unwrap()]) else {
        return;
    };
    let expected: Vec<Event> = (0..500i64)
        .map(|i| Event {
            t: i * 3 + 7,
            x: (i * 7 % 640) as u16,
            y: (i * 5 % 480) as u16,
            polarity: i % 2 == 1,
        })
        .collect();
    for name in ["packed", "aligned", "reordered"] {
        let bytes = std::fs::read(dir.path().join(format!("{name}.npy"))).unwrap();
        assert_eq!(read_all(bytes.as_slice()).unwrap(), expected, "{name}");
    }
}

#[test]
fn wrong_dtypes_are_rejected_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let script = "import sys, numpy as np\n\
                  np.save(sys.argv[1] + '/float.npy', np.zeros(3))\n\
                  np.save(sys.argv[1] + '/xyz.npy', np.zeros(3, dtype=[('t','<i8'),('x','<i2'),('z','<i2'),('p','u1')]))\n\
                  np.save(sys.argv[1] + '/big.npy', np.zeros(3, dtype=[('t','>i8'),('x','<i2'),('y','<i2'),('p','u1')]))\n";
    let Some(_) = run_python(script, &[dir.path().to_str().unwrap()]) else {
        return;
    };
    for (name, needle) in [
        ("float", "not a record"),
        ("xyz", "unexpected field `z`"),
        ("big", "field `t` has type `>i8`"),
    ] {
        let bytes = std::fs::read(dir.path().join(format!("{name}.npy"))).unwrap();
        let err = read_all(bytes.as_slice()).unwrap_err().to_string();
        assert!(err.contains(needle), "{name}: {err}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    /// Any truncation is an error; any flipped byte gives events or an error, never a panic.
    #[test]
    fn corrupted_npy_never_panics(cut in 0usize..1500, flip in 0usize..1500, byte in any::<u8>()) {
        let bytes = write(&synthetic_events(100, 640, 480));
        if cut < bytes.len() {
            prop_assert!(read_all(&bytes[..cut]).is_err());
        }
        let mut flipped = bytes.clone();
        let i = flip % flipped.len();
        flipped[i] = byte;
        let _ = read_all(flipped.as_slice());
    }
}

/// The header of `write(&[Event::default(); 2])` with its dictionary replaced by `dict`.
fn with_dict(dict: &str) -> Vec<u8> {
    common::with_dict(&write(&[Event::default(); 2]), dict)
}

/// Found by review and the `npy` fuzz target's seeds: two padding fields of `usize::MAX` bytes
/// overflowed the record size (`attempt to add with overflow` in the header parser).
#[test]
fn padding_fields_summing_past_usize_are_an_error_not_an_overflow_panic() {
    let bytes = with_dict(
        "{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1'), \
         ('', '|V18446744073709551615'), ('', '|V18446744073709551615')], \
         'fortran_order': False, 'shape': (2,), }",
    );
    let err = read_all(bytes.as_slice()).unwrap_err();
    assert!(err.to_string().contains("padding field"), "{err}");
}

/// A padding field of a gigabyte made the reader allocate a chunk buffer of 16384 such
/// records (16 TB: an allocation failure abort) before reading a single one.
#[test]
fn a_padding_field_of_a_gigabyte_is_refused_before_allocating() {
    let bytes = with_dict(
        "{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1'), \
         ('', '|V1000000000')], 'fortran_order': False, 'shape': (2,), }",
    );
    let (result, largest) = crate::alloc::largest_allocation_during(|| read_all(bytes.as_slice()));
    let err = result.unwrap_err();
    assert!(err.to_string().contains("padding field"), "{err}");
    assert!(largest < 1 << 20, "allocated {largest} bytes");
}

/// The chunk buffer was sized by the declared record count (up to 16384 records) and the
/// header buffer by the declared header length, before the bytes were known to exist.
#[test]
fn declared_sizes_allocate_only_what_the_file_holds() {
    let bytes = with_dict(
        "{'descr': [('t', '<i8'), ('x', '<i2'), ('y', '<i2'), ('p', '|u1'), ('', '|V4000')], \
         'fortran_order': False, 'shape': (4294967296,), }",
    );
    let (result, largest) = crate::alloc::largest_allocation_during(|| read_all(bytes.as_slice()));
    assert!(
        matches!(result, Err(NpyError::Truncated { declared, .. }) if declared == 1 << 32),
        "{result:?}"
    );
    // 16384 records of 4013 bytes would be 66 MB.
    assert!(largest < 1 << 20, "allocated {largest} bytes");
    let mut claim = b"\x93NUMPY\x02\x00".to_vec();
    claim.extend_from_slice(&(1u32 << 20).to_le_bytes());
    claim.extend_from_slice(b"{'descr'");
    let (result, largest) = crate::alloc::largest_allocation_during(|| read_all(claim.as_slice()));
    assert!(
        matches!(result, Err(NpyError::TruncatedHeader { .. })),
        "{result:?}"
    );
    assert!(largest < 1 << 16, "allocated {largest} bytes");
}
