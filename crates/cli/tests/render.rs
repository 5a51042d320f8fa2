//! Tests of `evtac render`: the written GIF and PNG decoded again (the `gif` crate's decoder,
//! the `png` crate, and Pillow as a decoder from outside Rust) for frame count, size, frame
//! duration, and the ON event's pixel lit in its frame only.

use crate::common::{evtac, run_ok};
use std::fs::File;
use std::path::Path;

/// Frame size for the default panels (events, static, dynamic, combined): four 240-pixel
/// columns with 10-pixel margins; a 26-pixel header, a 22-pixel title and a 10-pixel margin.
pub const SIZE: (usize, usize) = (10 + 4 * 250, 26 + 22 + 240 + 10);
/// Where crop pixel (50, 60) of the events panel lands in a frame.
pub const ON_PIXEL: (usize, usize) = (10 + 50, 48 + 60);
/// The events panel's ON colour.
const ON: [u8; 3] = [255, 60, 60];

/// A 240x240 CSV recording (read as already cropped): one ON event at (50, 60) at 150 ms, and
/// OFF events at (100, 100) through the range.
pub fn write_recording(path: &Path) {
    let mut text = String::from("t,x,y,p\n");
    for k in 0..30 {
        text.push_str(&format!("{},100,100,0\n", k * 10_000));
    }
    text.push_str("150000,50,60,1\n");
    let mut lines: Vec<&str> = text.lines().skip(1).collect();
    lines.sort_by_key(|l| l.split(',').next().and_then(|t| t.parse::<i64>().ok()));
    std::fs::write(path, format!("t,x,y,p\n{}\n", lines.join("\n"))).unwrap();
}

/// Renders `write_recording`'s recording from 0 to 300 ms at 10 fps (three frames) to `out` in
/// `dir`, with `extra` arguments.
pub fn render(dir: &Path, out: &str, extra: &[&str]) -> std::path::PathBuf {
    let input = dir.join("rec.csv");
    write_recording(&input);
    let out = dir.join(out);
    render_file(&input, &out, extra);
    out
}

/// Renders the recording `input` from 0 to 300 ms at 10 fps (three frames) to `out`, with
/// `extra` arguments.
pub fn render_file(input: &Path, out: &Path, extra: &[&str]) {
    let mut args = vec![
        "render",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--from-us",
        "0",
        "--to-us",
        "300000",
        "--fps",
        "10",
    ];
    args.extend_from_slice(extra);
    run_ok(&args);
}

#[test]
fn gif_has_one_frame_per_interval_and_the_on_event_lit_in_its_own() {
    let dir = tempfile::tempdir().unwrap();
    let out = render(dir.path(), "r.gif", &[]);
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options.read_info(File::open(&out).unwrap()).unwrap();
    assert_eq!(
        (usize::from(decoder.width()), usize::from(decoder.height())),
        SIZE
    );
    let mut on_pixel = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert_eq!((usize::from(frame.width), usize::from(frame.height)), SIZE);
        assert_eq!(frame.delay, 10, "10 fps is 10 hundredths of a second");
        let i = 4 * (ON_PIXEL.1 * SIZE.0 + ON_PIXEL.0);
        on_pixel.push([frame.buffer[i], frame.buffer[i + 1], frame.buffer[i + 2]]);
    }
    // Intervals (0, 100], (100, 200], (200, 300] ms: the ON event at 150 ms is in the second.
    assert_eq!(on_pixel, vec![[0, 0, 0], ON, [0, 0, 0]]);
}

#[test]
fn png_sheet_holds_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let out = render(dir.path(), "r.png", &[]);
    let decoder = png::Decoder::new(std::io::BufReader::new(File::open(&out).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    // Three frames in a grid about as tall as wide: 1 column (frames are 3.4 times wider than
    // tall), 3 rows.
    assert_eq!(
        (info.width as usize, info.height as usize),
        (SIZE.0, 3 * SIZE.1)
    );
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let at = |x: usize, y: usize| {
        let i = 3 * (y * SIZE.0 + x);
        [buf[i], buf[i + 1], buf[i + 2]]
    };
    assert_eq!(at(ON_PIXEL.0, SIZE.1 + ON_PIXEL.1), ON);
    assert_eq!(at(ON_PIXEL.0, ON_PIXEL.1), [0, 0, 0]);
}

/// Pillow's view of a GIF: size, frame count, each frame's duration (ms) and the colour of
/// pixel (x, y) in each frame.
const PILLOW_GIF: &str = r#"
import sys
from PIL import Image, ImageSequence
x, y = int(sys.argv[2]), int(sys.argv[3])
with Image.open(sys.argv[1]) as im:
    print(im.format, *im.size, im.n_frames)
    for frame in ImageSequence.Iterator(im):
        print(frame.info["duration"], *frame.convert("RGB").getpixel((x, y)))
"#;

#[test]
fn pillow_reads_the_gif_frames_duration_and_the_lit_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let out = render(dir.path(), "r.gif", &[]);
    let (x, y) = (ON_PIXEL.0.to_string(), ON_PIXEL.1.to_string());
    let Some(text) = evtac_testkit::run_python(PILLOW_GIF, &[out.to_str().unwrap(), &x, &y]) else {
        return;
    };
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], format!("GIF {} {} 3", SIZE.0, SIZE.1), "{text}");
    // 10 fps: 100 ms a frame; the ON event at 150 ms lights its pixel in the second only.
    assert_eq!(
        lines[1..],
        ["100 0 0 0", "100 255 60 60", "100 0 0 0"],
        "{text}"
    );
}

/// Pillow's view of a PNG: format, size, mode and the colour of each pixel given.
const PILLOW_PNG: &str = r#"
import sys
from PIL import Image
with Image.open(sys.argv[1]) as im:
    print(im.format, *im.size, im.mode)
    xy = [int(v) for v in sys.argv[2:]]
    for x, y in zip(xy[::2], xy[1::2]):
        print(*im.getpixel((x, y)))
"#;

#[test]
fn pillow_reads_the_png_sheet() {
    let dir = tempfile::tempdir().unwrap();
    let out = render(dir.path(), "r.png", &[]);
    let at = |frame: usize| {
        [
            ON_PIXEL.0.to_string(),
            (frame * SIZE.1 + ON_PIXEL.1).to_string(),
        ]
    };
    let (a, b) = (at(0), at(1));
    let args = [out.to_str().unwrap(), &a[0], &a[1], &b[0], &b[1]];
    let Some(text) = evtac_testkit::run_python(PILLOW_PNG, &args) else {
        return;
    };
    // Three frames, one column: the ON pixel dark in the first frame, lit in the second.
    assert_eq!(
        text.lines().collect::<Vec<_>>(),
        [
            format!("PNG {} {} RGB", SIZE.0, 3 * SIZE.1).as_str(),
            "0 0 0",
            "255 60 60"
        ],
        "{text}"
    );
}

#[test]
fn unknown_panel_and_format_and_angles_without_a_model_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("rec.csv");
    write_recording(&input);
    let cases = [
        ("r.gif", "events,colour", "unknown panel `colour`"),
        ("r.mp3", "events", "r.mp3: unknown output format"),
        ("r.gif", "events,angles", "needs a model (--model)"),
    ];
    for (file, panels, message) in cases {
        let out = evtac()
            .args(["render", input.to_str().unwrap(), "--out"])
            .arg(dir.path().join(file))
            .args(["--panels", panels])
            .output()
            .unwrap();
        assert!(!out.status.success(), "{file} {panels} accepted");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(message), "{err}");
    }
}

/// A contact sheet with the default --fps and --speed spreads 24 frames over a whole simulated
/// trial (141 frames at 30 fps would not fit in one).
#[test]
fn a_png_sheet_with_the_defaults_spreads_24_frames_over_the_trial() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("sim");
    crate::common::simulate_tiny("exp1", 0, &data, 1);
    let out = dir.path().join("sheet.png");
    let o = run_ok(&[
        "render",
        data.to_str().unwrap(),
        "--trial",
        "t0000",
        "--out",
        out.to_str().unwrap(),
    ]);
    let said =
        String::from_utf8_lossy(&o.stderr).into_owned() + &String::from_utf8_lossy(&o.stdout);
    assert!(said.contains("24 frames"), "{said}");
    assert!(out.is_file());
}

#[test]
fn time_surface_and_voxel_grid_panels_draw_their_values() {
    let dir = tempfile::tempdir().unwrap();
    let panels = "events,time-surface,voxel-grid";
    let out = render(dir.path(), "r.png", &["--panels", panels]);
    let decoder = png::Decoder::new(std::io::BufReader::new(File::open(&out).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    // Three panels of 250 pixels; the three frames in a 2 x 2 grid, row by row.
    let size = (10 + 3 * 250, SIZE.1);
    assert_eq!(
        (info.width as usize, info.height as usize),
        (2 * size.0, 2 * size.1)
    );
    let at = |frame: usize, column: usize, (x, y): (usize, usize)| {
        let (left, top) = ((frame % 2) * size.0, (frame / 2) * size.1);
        let (x, y) = (left + 10 + column * 250 + x, top + 48 + y);
        let i = 3 * (y * 2 * size.0 + x);
        [buf[i], buf[i + 1], buf[i + 2]]
    };
    // The time surface (default tau 100 ms) at the ON pixel: nothing before the event, then
    // exp(-50 ms / 100 ms) and exp(-150 ms / 100 ms) of full red at the frames' ends.
    let level = |v: f64| (v * 255.0).round() as u8;
    assert_eq!(at(0, 1, (50, 60)), [0, 0, 0]);
    assert_eq!(at(1, 1, (50, 60)), [level((-0.5f64).exp()), 0, 0]);
    assert_eq!(at(2, 1, (50, 60)), [level((-1.5f64).exp()), 0, 0]);
    // The OFF pixel, its latest event 10 ms before each frame's end (events at the end itself
    // wait for the next sample, as tonic's slices do): blue.
    assert_eq!(at(0, 1, (100, 100)), [0, 0, level((-0.1f64).exp())]);
    // The voxel grid (default 640 ms window, 5 bins) sums its signed bins: the OFF pixel's
    // ten or more events outweigh the single ON event, which shows red at a tenth or less.
    let [r, g, b] = at(1, 2, (100, 100));
    assert_eq!((r, g, b), (0, 0, 255));
    let [r, _, b] = at(1, 2, (50, 60));
    assert!(r > 0 && r < 40 && b == 0, "{r} {b}");
}
