//! Masks read from files: a uint8 `H x W` NPY array (numpy's `np.save` of the array
//! dv-processing's `EventMaskFilter` takes) or an 8-bit greyscale PNG, row by row, one value a
//! pixel.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;

use evtac_events::Resolution;

/// A mask as read: its size and its values, row by row.
#[derive(Debug, Clone, PartialEq)]
pub struct MaskImage {
    /// Columns and rows.
    pub size: Resolution,
    /// One value a pixel, row by row.
    pub values: Vec<u8>,
}

/// Reads the mask at `path`: NPY by its magic, PNG by its signature; anything else, a mask of
/// another type than uint8, or of other than two dimensions, is an error saying so.
pub fn read(path: &Path) -> Result<MaskImage, String> {
    let mut head = Vec::with_capacity(8);
    File::open(path)
        .and_then(|f| f.take(8).read_to_end(&mut head))
        .map_err(|e| format!("cannot read it: {e}"))?;
    if head.starts_with(b"\x93NUMPY") {
        read_npy(path)
    } else if head.starts_with(b"\x89PNG\r\n\x1a\n") {
        read_png(path)
    } else {
        Err("it is neither an NPY file (magic `\\x93NUMPY`) nor a PNG image".into())
    }
}

fn size(width: usize, height: usize) -> Result<Resolution, String> {
    match (u16::try_from(width), u16::try_from(height)) {
        (Ok(w), Ok(h)) if w > 0 && h > 0 => Ok(Resolution::new(w, h)),
        _ => Err(format!(
            "its size {width}x{height} is no sensor's (1 to 65535 a side)"
        )),
    }
}

fn read_npy(path: &Path) -> Result<MaskImage, String> {
    let array: ndarray::Array2<u8> = ndarray_npy::read_npy(path).map_err(|e| {
        format!("it is not a 2-D uint8 NPY array (rows x columns, as np.save writes one): {e}")
    })?;
    let (height, width) = array.dim();
    Ok(MaskImage {
        size: size(width, height)?,
        values: array.iter().copied().collect(),
    })
}

fn read_png(path: &Path) -> Result<MaskImage, String> {
    let file = File::open(path).map_err(|e| format!("cannot read it: {e}"))?;
    let decoder = png::Decoder::new(BufReader::new(file));
    let mut reader = decoder
        .read_info()
        .map_err(|e| format!("it is not a PNG image evtac can read: {e}"))?;
    let info = reader.info();
    if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Eight {
        return Err(format!(
            "it is a {:?} PNG of {:?} bits a channel; a mask is 8-bit greyscale (one uint8 a \
             pixel)",
            info.color_type, info.bit_depth
        ));
    }
    let (width, height) = (info.width as usize, info.height as usize);
    let size = size(width, height)?;
    // The decoder's own buffer size, from the header it has checked against its limits.
    let mut values = vec![0; reader.output_buffer_size().unwrap_or(0)];
    let frame = reader
        .next_frame(&mut values)
        .map_err(|e| format!("its image data is broken: {e}"))?;
    values.truncate(frame.buffer_size());
    if values.len() != width * height {
        return Err(format!(
            "its image data holds {} values, not {width}x{height}",
            values.len()
        ));
    }
    Ok(MaskImage { size, values })
}
