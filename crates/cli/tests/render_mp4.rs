//! Tests of `evtac render`'s MP4 output, decoded by ffmpeg's own tools (`ffprobe` for the
//! stream, `ffmpeg -f rawvideo` for the pixels), and of its message when ffmpeg is missing.

use crate::common::evtac;
use crate::render::{SIZE, render_file};
use std::path::Path;
use std::process::Command;

/// A recording with an 8x8 block of ON events at 150 ms (centered on crop pixel (50, 60)) and
/// nothing else: a block rather than one pixel, because H.264 in yuv420p shares each 2x2
/// block's colour, and a lossy encoder blurs a lone pixel.
fn write_block(path: &Path) {
    let mut text = String::from("t,x,y,p\n0,0,0,0\n");
    for y in 56..64 {
        for x in 46..54 {
            text.push_str(&format!("150000,{x},{y},1\n"));
        }
    }
    text.push_str("300000,239,239,0\n");
    std::fs::write(path, text).unwrap();
}

/// The stdout of `command` (ffprobe or ffmpeg), which must succeed.
fn stdout_of(command: &mut Command) -> Vec<u8> {
    let out = command.output().expect("ffmpeg's tools run");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{command:?}: {stderr}");
    out.stdout
}

/// What ffprobe says of the first video stream: codec, width, height, decoded frame count.
fn probe(path: &Path) -> String {
    let out = stdout_of(
        Command::new("ffprobe")
            .args(["-v", "error", "-select_streams", "v:0", "-count_frames"])
            .args([
                "-show_entries",
                "stream=codec_name,width,height,nb_read_frames",
            ])
            .args(["-of", "csv=p=0"])
            .arg(path),
    );
    String::from_utf8_lossy(&out).trim().to_string()
}

/// Every frame of `path` decoded by ffmpeg to RGB, one buffer per frame of `size`.
fn decode(path: &Path, size: (usize, usize)) -> Vec<Vec<u8>> {
    let out = stdout_of(
        Command::new("ffmpeg")
            .args(["-v", "error", "-i"])
            .arg(path)
            .args(["-f", "rawvideo", "-pix_fmt", "rgb24", "-"]),
    );
    let frame = size.0 * size.1 * 3;
    assert_eq!(out.len() % frame, 0, "not whole frames");
    out.chunks(frame).map(<[u8]>::to_vec).collect()
}

#[test]
fn mp4_decodes_to_one_frame_per_interval_with_the_block_lit_in_its_own() {
    if !evtac_testkit::ffmpeg() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    write_block(&dir.path().join("rec.csv"));
    let out = dir.path().join("r.mp4");
    render_file(&dir.path().join("rec.csv"), &out, &[]);
    // The default panels' frame is even on both sides, so it is encoded at its own size.
    assert_eq!(probe(&out), format!("h264,{},{},3", SIZE.0, SIZE.1));
    let frames = decode(&out, SIZE);
    assert_eq!(frames.len(), 3);
    let (x, y) = (10 + 50, 48 + 60);
    let at = |f: &[u8]| {
        let i = 3 * (y * SIZE.0 + x);
        [f[i], f[i + 1], f[i + 2]]
    };
    // The ON colour (255, 60, 60) within the encoder's error in the second frame; black in
    // the others.
    let lit = at(&frames[1]);
    assert!(lit[0] > 200 && lit[1] < 110 && lit[2] < 110, "{lit:?}");
    for f in [&frames[0], &frames[2]] {
        assert!(at(f).iter().all(|&c| c < 40), "{:?}", at(f));
    }
    // Nothing else is left beside the output.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
}

#[test]
fn without_ffmpeg_mp4_fails_saying_how_to_install_it_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("rec.csv");
    write_block(&input);
    let empty = dir.path().join("empty-path");
    std::fs::create_dir(&empty).unwrap();
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let out = evtac()
        .args(["render", input.to_str().unwrap(), "--out"])
        .arg(out_dir.join("r.mp4"))
        .env("PATH", &empty)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    for part in [
        "r.mp4: writing MP4 needs ffmpeg",
        "apt install ffmpeg",
        ".gif or .png",
    ] {
        assert!(err.contains(part), "no `{part}` in: {err}");
    }
    assert_eq!(std::fs::read_dir(&out_dir).unwrap().count(), 0);
}
