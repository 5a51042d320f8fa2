//! `evtac info` and `evtac convert` on the older formats (AEDAT 2.0 and 3.1, EVT 2.1), with
//! files written by a Python script from the format descriptions.

use crate::common::run_ok;

/// Writes three small recordings of the same 500 events on a 240x180 sensor: `a2.aedat`
/// (AEDAT 2.0, jAER's DAVIS240 addresses), `a31.aedat` (AEDAT 3.1, one polarity packet and one
/// IMU6 packet of 3 samples), `e21.raw` (EVT 2.1, one event per vector word). Prints
/// `count on first_t last_t`.
pub(crate) const PY_WRITE: &str = r##"
import random, struct, sys, os
d = sys.argv[1]
rng = random.Random(5)
ev, t = [], 1000
for _ in range(500):
    t += rng.randrange(0, 9)
    ev.append((t, rng.randrange(240), rng.randrange(180), rng.randint(0, 1)))
a2 = bytearray(b"#!AER-DAT2.0\r\n# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C\r\n")
for t, x, y, p in ev:
    a2 += struct.pack(">II", (179 - y) << 22 | (239 - x) << 12 | p << 11, t)
open(os.path.join(d, "a2.aedat"), "wb").write(a2)
a3 = bytearray(b"#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS240C\r\n#!END-HEADER\r\n")
a3 += struct.pack("<hhiiiiii", 1, 1, 8, 4, 0, len(ev), len(ev), len(ev))
for t, x, y, p in ev:
    a3 += struct.pack("<Ii", x << 17 | y << 2 | p << 1 | 1, t)
a3 += struct.pack("<hhiiiiii", 3, 1, 36, 4, 0, 3, 3, 3)
for i in range(3):
    a3 += struct.pack("<Ii7f", 1, 1500 + 1000 * i, 0.0, 0.0, 1.0, 0.5, 0.0, 0.0, 30.0)
open(os.path.join(d, "a31.aedat"), "wb").write(a3)
e21 = bytearray(b"% format EVT21;height=180;width=240\n% end\n")
high = None
for t, x, y, p in ev:
    if t >> 6 != high:
        high = t >> 6
        e21 += struct.pack("<Q", 0x8 << 60 | high << 32)
    e21 += struct.pack("<Q", p << 60 | (t & 63) << 54 | (x & ~31) << 43 | y << 32 | 1 << (x & 31))
open(os.path.join(d, "e21.raw"), "wb").write(e21)
print(len(ev), sum(e[3] for e in ev), ev[0][0], ev[-1][0])
"##;

#[test]
fn info_and_convert_read_the_older_formats() {
    let dir = tempfile::tempdir().unwrap();
    let Some(out) = evtac_testkit::run_python(PY_WRITE, &[dir.path().to_str().unwrap()]) else {
        return;
    };
    let want: Vec<i64> = out.split_whitespace().map(|v| v.parse().unwrap()).collect();
    let check = |path: &std::path::Path, format: &str, imu: u64| {
        let out = run_ok(&["info", path.to_str().unwrap(), "--json"]);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let name = path.display();
        assert_eq!(v["format"], format, "{name}");
        assert_eq!(
            (&v["width"], &v["height"]),
            (&240.into(), &180.into()),
            "{name}"
        );
        let got = [
            &v["events"],
            &v["on_events"],
            &v["first_t_us"],
            &v["last_t_us"],
        ]
        .map(|x| x.as_i64().unwrap());
        assert_eq!(got.to_vec(), want, "{name}");
        assert_eq!(v["imu_samples"], imu, "{name}");
    };
    for (name, format, imu) in [
        ("a2.aedat", "AEDAT2", 0),
        ("a31.aedat", "AEDAT3.1", 3),
        ("e21.raw", "EVT21", 0),
    ] {
        let input = dir.path().join(name);
        let output = dir.path().join(format!("{name}.aedat4"));
        check(&input, format, imu);
        run_ok(&["convert", input.to_str().unwrap(), output.to_str().unwrap()]);
        check(&output, "AEDAT4", imu);
    }
}
