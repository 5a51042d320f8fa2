//! Mask files: a PNG mask filters as the same NPY mask does, and a file that is no mask, or a
//! mask of another size than the sensor, is an error naming the SPEC and saying why.

use std::path::Path;

use evtac_events::Resolution;
use evtac_filters::FilterSpec;

use crate::common::{SENSOR, stream};

fn save_png(path: &Path, size: Resolution, values: &[u8], color: png::ColorType) {
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = png::Encoder::new(file, u32::from(size.width), u32::from(size.height));
    encoder.set_color(color);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .write_header()
        .unwrap()
        .write_image_data(values)
        .unwrap();
}

fn build(spec: &str, sensor: Resolution) -> Result<&'static str, String> {
    let spec: FilterSpec = spec.parse().map_err(|e| format!("{e}"))?;
    spec.build(sensor)
        .map(|f| f.name())
        .map_err(|e| e.to_string())
}

#[test]
fn a_png_mask_keeps_what_the_same_npy_mask_keeps() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (usize::from(SENSOR.width), usize::from(SENSOR.height));
    // Stripes and a block, so both kept and removed pixels lie everywhere.
    let values: Vec<u8> = (0..w * h)
        .map(|k| u8::from((k % w) % 3 != 0 && (k / w) % 5 != 1) * 7)
        .collect();
    let npy = dir.path().join("mask.npy");
    let array = ndarray::Array2::from_shape_vec((h, w), values.clone()).unwrap();
    ndarray_npy::write_npy(&npy, &array).unwrap();
    let png = dir.path().join("mask.png");
    save_png(&png, SENSOR, &values, png::ColorType::Grayscale);
    let events = stream(11, SENSOR, 5_000, 0);
    let run = |spec: String| {
        let mut filter = spec.parse::<FilterSpec>().unwrap().build(SENSOR).unwrap();
        let mut kept = Vec::new();
        filter.retain(&events, &mut kept);
        (kept, filter.removed())
    };
    let (from_npy, removed) = run(format!("mask={}", npy.display()));
    assert_eq!(
        run(format!("mask={}", png.display())),
        (from_npy.clone(), removed)
    );
    // The reference: the mask's value at (row y, column x).
    let expected: Vec<_> = events
        .iter()
        .filter(|e| values[usize::from(e.y) * w + usize::from(e.x)] != 0)
        .copied()
        .collect();
    assert_eq!(from_npy, expected);
    assert!(removed > 0 && !from_npy.is_empty());
    // hot-pixels= removes exactly the others.
    let (hot_kept, hot_removed) = run(format!("hot-pixels={}", npy.display()));
    assert_eq!(hot_kept.len() as u64, removed);
    assert_eq!(hot_removed, from_npy.len() as u64);
}

#[test]
fn bad_masks_are_errors_naming_the_spec() {
    let dir = tempfile::tempdir().unwrap();
    let wrong = dir.path().join("wrong.npy");
    ndarray_npy::write_npy(&wrong, &ndarray::Array2::<u8>::ones((48, 63))).unwrap();
    let spec = format!("mask={}", wrong.display());
    assert_eq!(
        build(&spec, SENSOR).unwrap_err(),
        format!("filter `{spec}`: the mask is 63x48 (columns x rows), the sensor 64x48")
    );
    let floats = dir.path().join("floats.npy");
    ndarray_npy::write_npy(&floats, &ndarray::Array2::<f32>::ones((48, 64))).unwrap();
    let message = build(&format!("hot-pixels={}", floats.display()), SENSOR).unwrap_err();
    assert!(
        message.contains("is not a 2-D uint8 NPY array"),
        "{message}"
    );
    let rgb = dir.path().join("rgb.png");
    save_png(&rgb, SENSOR, &vec![1; 64 * 48 * 3], png::ColorType::Rgb);
    let message = build(&format!("mask={}", rgb.display()), SENSOR).unwrap_err();
    assert!(message.contains("a mask is 8-bit greyscale"), "{message}");
    let text = dir.path().join("mask.txt");
    std::fs::write(&text, "1 0 1").unwrap();
    let message = build(&format!("mask={}", text.display()), SENSOR).unwrap_err();
    assert!(message.contains("neither an NPY file"), "{message}");
    let missing = dir.path().join("none.npy");
    let message = build(&format!("mask={}", missing.display()), SENSOR).unwrap_err();
    assert!(
        message.contains("none.npy") && message.contains("cannot read it"),
        "{message}"
    );
    assert_eq!(
        build("mask=", SENSOR).unwrap_err(),
        "filter `mask=`: expected mask=FILE, a uint8 H x W NPY array or 8-bit greyscale PNG"
    );
}
