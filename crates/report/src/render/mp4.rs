//! The MP4 video: each frame drawn into an RGB buffer and piped, raw, to an `ffmpeg` found on
//! the `PATH`, which encodes it as H.264 (libx264, yuv420p, the format every player reads).
//!
//! ffmpeg rather than an encoder crate: the H.264 encoders on crates.io either bundle a C
//! codec build (openh264) or write only baseline streams several times the size, while ffmpeg
//! is one `apt install` away on the machines evtac runs on and is what people already use to
//! cut and convert the result. Without it, GIF and PNG still work; the error says so.

use super::Error;
use super::draw::{Scene, draw_frame};
use super::frames::Frame;
use plotters::prelude::*;
use std::io::{Read, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::thread::JoinHandle;

/// The program run: `ffmpeg`, looked up on the `PATH`.
const FFMPEG: &str = "ffmpeg";

/// Streams frames into an MP4 file through an `ffmpeg` child process.
pub struct Mp4Writer<'p> {
    path: &'p Path,
    scene: Scene<'p>,
    /// The encoded size: the layout's, rounded up to even sides (yuv420p halves both).
    size: (u32, u32),
    child: Child,
    stdin: Option<ChildStdin>,
    /// ffmpeg's stderr, read on a thread so a chatty ffmpeg never blocks on a full pipe.
    stderr: Option<JoinHandle<String>>,
    rgb: Vec<u8>,
}

impl<'p> Mp4Writer<'p> {
    /// Starts ffmpeg writing `file` for frames of `scene` at its fps; errors name `path`, the
    /// output `file` becomes.
    pub fn create(file: &Path, path: &'p Path, scene: Scene<'p>) -> Result<Self, Error> {
        let (w, h) = scene.layout.size;
        let size = (w + w % 2, h + h % 2);
        let mut child = Command::new(FFMPEG)
            .args(["-hide_banner", "-loglevel", "error", "-y"])
            .args(["-f", "rawvideo", "-pix_fmt", "rgb24"])
            .args(["-s", &format!("{}x{}", size.0, size.1)])
            .args(["-r", &scene.timing.fps.to_string(), "-i", "-", "-an"])
            .args([
                "-c:v", "libx264", "-pix_fmt", "yuv420p", "-preset", "veryfast",
            ])
            // The index at the front, so a browser plays the file before it has all of it.
            .args(["-movflags", "+faststart", "-f", "mp4"])
            .arg(file)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| {
                if e.kind() == std::io::ErrorKind::NotFound {
                    Error::FfmpegMissing {
                        path: path.to_path_buf(),
                    }
                } else {
                    Error::Ffmpeg {
                        path: path.to_path_buf(),
                        message: format!("could not start {FFMPEG}: {e}"),
                    }
                }
            })?;
        let stdin = child.stdin.take();
        let stderr = child.stderr.take().map(|mut s| {
            std::thread::spawn(move || {
                let mut text = String::new();
                // A read error only loses ffmpeg's message, not the exit status checked later.
                let _ = s.read_to_string(&mut text);
                text
            })
        });
        Ok(Mp4Writer {
            path,
            scene,
            size,
            child,
            stdin,
            stderr,
            rgb: vec![0; size.0 as usize * size.1 as usize * 3],
        })
    }

    /// Draws `frame` and sends it to ffmpeg.
    pub fn push(&mut self, frame: &Frame<'_>) -> Result<(), Error> {
        {
            let area = BitMapBackend::with_buffer(&mut self.rgb, self.size).into_drawing_area();
            draw_frame(&area, &self.scene, frame, self.path)?;
            area.present().map_err(crate::plots::draw_err(self.path))?;
        }
        let sent = match self.stdin.as_mut() {
            Some(stdin) => stdin.write_all(&self.rgb),
            None => Err(std::io::ErrorKind::BrokenPipe.into()),
        };
        match sent {
            Ok(()) => Ok(()),
            // ffmpeg stopped reading: its own message says why, once it has exited.
            Err(e) => Err(self.failure(&format!("sending frame {}: {e}", frame.index + 1))),
        }
    }

    /// Closes ffmpeg's input and waits for it to write the file.
    pub fn finish(mut self) -> Result<(), Error> {
        drop(self.stdin.take());
        let status = self.child.wait().map_err(|e| Error::Ffmpeg {
            path: self.path.to_path_buf(),
            message: format!("waiting for {FFMPEG}: {e}"),
        })?;
        if status.success() {
            Ok(())
        } else {
            Err(self.failure(&format!("{FFMPEG} exited with {status}")))
        }
    }

    /// The error for ffmpeg failing: `what` happened, then ffmpeg's stderr after it exits.
    fn failure(&mut self, what: &str) -> Error {
        drop(self.stdin.take());
        // The exit status adds nothing to ffmpeg's message; waiting only reaps the process.
        let _ = self.child.wait();
        let said = self
            .stderr
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        Error::Ffmpeg {
            path: self.path.to_path_buf(),
            message: format!("{what}: {}", said.trim()),
        }
    }
}

impl Drop for Mp4Writer<'_> {
    /// A writer dropped before [`Mp4Writer::finish`] (an error drawing a frame) stops ffmpeg,
    /// so no process outlives the render; the partial file is the caller's to remove.
    fn drop(&mut self) {
        drop(self.stdin.take());
        if matches!(self.child.try_wait(), Ok(None)) {
            // Killing a process that has just exited fails harmlessly.
            let _ = self.child.kill();
        }
        let _ = self.child.wait();
    }
}
