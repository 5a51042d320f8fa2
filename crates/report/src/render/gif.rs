//! The animated GIF: each frame drawn into an RGB buffer, mapped to one fixed global palette and
//! encoded by the `gif` crate.
//!
//! A fixed palette (the panels' exact colours, the angles panel's curve colours, 32 greys for
//! the features, a 6x6x6 colour cube for the anti-aliased text) instead of a per-frame quantizer: the panels have few colours,
//! the colours stay the same from frame to frame, and a 32x32x32 lookup table maps a pixel in
//! a few nanoseconds where NeuQuant would dominate the render time.

use super::Error;
use super::draw::{Scene, draw_frame};
use super::frames::Frame;
use crate::plots::images::{BOTH, OFF, ON};
use plotters::prelude::*;
use std::borrow::Cow;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;
use std::sync::OnceLock;

/// The palette, RGB triples: exact panel colours first, then greys, then the colour cube.
fn palette() -> &'static [[u8; 3]] {
    static PALETTE: OnceLock<Vec<[u8; 3]>> = OnceLock::new();
    PALETTE.get_or_init(|| {
        let mut p = vec![[0, 0, 0], [255, 255, 255]];
        let curves = evtac_repr::ReprKind::PAPER.map(crate::plots::repr_color);
        for c in [ON, OFF, BOTH].into_iter().chain(curves) {
            p.push([c.0, c.1, c.2]);
        }
        // The features' greys (`grey()` rounds v * 255): 32 levels, 0 and 255 included.
        for k in 1..31u32 {
            let g = (k * 255 / 31) as u8;
            p.push([g, g, g]);
        }
        for r in 0..6u8 {
            for g in 0..6u8 {
                for b in 0..6u8 {
                    p.push([r * 51, g * 51, b * 51]);
                }
            }
        }
        p
    })
}

/// The palette index nearest to every colour with 5 bits per channel.
fn lookup() -> &'static [u8] {
    static LUT: OnceLock<Vec<u8>> = OnceLock::new();
    LUT.get_or_init(|| {
        let palette = palette();
        (0..32 * 32 * 32u32)
            .map(|i| {
                // The centre of the 8x8x8 cell of 8-bit colours this entry stands for.
                let c = [(i >> 10) & 31, (i >> 5) & 31, i & 31].map(|v| (v * 8 + 4) as i32);
                let nearest = palette
                    .iter()
                    .enumerate()
                    .min_by_key(|(_, p)| {
                        (0..3).map(|k| (i32::from(p[k]) - c[k]).pow(2)).sum::<i32>()
                    })
                    .map_or(0, |(j, _)| j);
                nearest as u8
            })
            .collect()
    })
}

/// The palette index of each pixel of the RGB buffer `rgb`, written to `out`.
fn quantize(rgb: &[u8], out: &mut Vec<u8>) {
    let lut = lookup();
    out.clear();
    out.extend(rgb.chunks_exact(3).map(|p| {
        let i =
            (usize::from(p[0] >> 3) << 10) | (usize::from(p[1] >> 3) << 5) | usize::from(p[2] >> 3);
        lut[i]
    }));
}

/// Streams frames into a GIF file.
pub struct GifWriter<'p> {
    path: &'p Path,
    scene: Scene<'p>,
    encoder: gif::Encoder<BufWriter<File>>,
    rgb: Vec<u8>,
    indices: Vec<u8>,
}

impl<'p> GifWriter<'p> {
    /// Creates `file` for frames of `scene`, played at its fps and looping; errors name `path`,
    /// the output `file` becomes.
    pub fn create(file: &Path, path: &'p Path, scene: Scene<'p>) -> Result<Self, Error> {
        let err = |m: String| Error::Gif {
            path: path.to_path_buf(),
            message: m,
        };
        let (w, h) = scene.layout.size;
        let (w16, h16) = match (u16::try_from(w), u16::try_from(h)) {
            (Ok(a), Ok(b)) => (a, b),
            _ => {
                return Err(err(format!(
                    "a {w}x{h} frame exceeds GIF's 65535 pixels a side"
                )));
            }
        };
        let file = File::create(file).map_err(|e| err(e.to_string()))?;
        let flat: Vec<u8> = palette().iter().flatten().copied().collect();
        let mut encoder = gif::Encoder::new(BufWriter::new(file), w16, h16, &flat)
            .map_err(|e| err(e.to_string()))?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(|e| err(e.to_string()))?;
        let pixels = w as usize * h as usize;
        Ok(GifWriter {
            path,
            scene,
            encoder,
            rgb: vec![0; pixels * 3],
            indices: Vec::with_capacity(pixels),
        })
    }

    /// Draws and appends `frame`.
    pub fn push(&mut self, frame: &Frame<'_>) -> Result<(), Error> {
        let (w, h) = self.scene.layout.size;
        {
            let area = BitMapBackend::with_buffer(&mut self.rgb, (w, h)).into_drawing_area();
            draw_frame(&area, &self.scene, frame, self.path)?;
            area.present().map_err(crate::plots::draw_err(self.path))?;
        }
        quantize(&self.rgb, &mut self.indices);
        let out = gif::Frame {
            // `create` checked that the size fits in u16.
            width: w as u16,
            height: h as u16,
            buffer: Cow::Borrowed(&self.indices),
            // GIF delays are whole hundredths of a second: 30 fps plays at 1/0.03 = 33.3 fps.
            delay: (100.0 / self.scene.timing.fps).round().clamp(1.0, 65535.0) as u16,
            ..gif::Frame::default()
        };
        self.encoder.write_frame(&out).map_err(|e| Error::Gif {
            path: self.path.to_path_buf(),
            message: e.to_string(),
        })
    }

    /// Writes the GIF's trailer and flushes the file (dropping the writer would do both but
    /// lose their errors).
    pub fn finish(self) -> Result<(), Error> {
        let path = self.path;
        let err = |e: &dyn std::fmt::Display| Error::Gif {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let mut file = self.encoder.into_inner().map_err(|e| err(&e))?;
        file.flush().map_err(|e| err(&e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::angles_chart::TRUTH;

    #[test]
    fn panel_colours_map_to_themselves() {
        for c in [
            [0, 0, 0],
            [255, 255, 255],
            [ON.0, ON.1, ON.2],
            [OFF.0, OFF.1, OFF.2],
            [TRUTH.0, TRUTH.1, TRUTH.2],
            [31, 119, 180],
        ] {
            let mut out = Vec::new();
            quantize(&c, &mut out);
            assert_eq!(palette()[usize::from(out[0])], c);
        }
        assert!(palette().len() <= 256, "{} colours", palette().len());
    }
}
