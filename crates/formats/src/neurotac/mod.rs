//! The Bristol NeuroTac lab's own event files: the data-collection code
//! (`core/sensor/tactile_sensor_neuro.py`) saves each trial as two pickles,
//! `<trial>_events_on` and `<trial>_events_off` (often ON only), each holding one cell per pixel
//! with the list of that pixel's event times in **milliseconds** since logging started:
//!
//! - the dv-processing version: a numpy object array indexed `[y, x]` (shape height x width);
//! - the DV-network version: nested Python lists indexed `[x][y]` (640 x 480 for a DVXplorer).
//!
//! The same structures also come as `.npy` files saved with `allow_pickle=True`. The index order
//! is the structure's (an array is `[y, x]`, nested lists `[x][y]`), and the sensor size is the
//! structure's shape in that order; a sensor size given by the user that disagrees is an error
//! that says which order each reading would mean, never a silent transpose.
//!
//! The pickle is read as data ([`crate::neurotac::pickle`]): numpy's array reconstruction is the only call
//! accepted, anything else (`os.system`, any class) is an error naming it, and nothing runs.
//! The times become microseconds (`round(ms * 1000)`); events are ordered by time, then row,
//! column and polarity (OFF first), so the order does not depend on the pixel layout. Opening
//! either file of a pair reads both; a missing partner is read as ON-only (or OFF-only), which
//! [`NeurotacFile::note`] says.

use std::path::{Path, PathBuf};

pub(crate) mod family;
pub mod pickle;

use crate::{Event, Resolution};
use pickle::{PickleError, Value};

/// What is wrong with a NeuroTac file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum NeurotacError {
    /// The file could not be read.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        error: std::io::Error,
    },
    /// The pickle stream is broken.
    #[error("{}: {error}", path.display())]
    Pickle {
        /// The file.
        path: PathBuf,
        /// The cause.
        error: PickleError,
    },
    /// The pickle is readable but not the lab's structure.
    #[error(
        "{}: not a NeuroTac event file (a numpy object array [y, x] or nested lists [x][y] of \
         per-pixel event times): {what}",
        path.display()
    )]
    Structure {
        /// The file.
        path: PathBuf,
        /// What was found instead, and where.
        what: String,
    },
    /// The ON and OFF files disagree on the sensor size.
    #[error("{} is {on} but {} is {off}", on_path.display(), off_path.display())]
    PairMismatch {
        /// The ON file.
        on_path: PathBuf,
        /// Its size.
        on: Resolution,
        /// The OFF file.
        off_path: PathBuf,
        /// Its size.
        off: Resolution,
    },
}

/// How a file indexes its pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum PixelOrder {
    /// A numpy object array `[y, x]` (the dv-processing version).
    RowMajor,
    /// Nested lists `[x][y]` (the DV-network version).
    ColumnLists,
}

impl PixelOrder {
    /// `[y, x]` or `[x][y]`, with what it is.
    pub fn describe(self) -> &'static str {
        match self {
            Self::RowMajor => "numpy object array indexed [y, x]",
            Self::ColumnLists => "nested lists indexed [x][y]",
        }
    }
}

/// One file's pixels: the size in the file's order and every pixel's times in ms.
struct PixelTimes {
    order: PixelOrder,
    resolution: Resolution,
    /// `(x, y, times)` per non-empty pixel.
    cells: Vec<(u16, u16, Vec<f64>)>,
}

/// A pair (or a lone file) read whole.
#[derive(Debug, Clone)]
pub struct NeurotacFile {
    /// The sensor size, from the structure's shape.
    pub resolution: Resolution,
    /// How the file indexed its pixels.
    pub order: PixelOrder,
    /// The ON file, if there is one.
    pub on_path: Option<PathBuf>,
    /// The OFF file, if there is one.
    pub off_path: Option<PathBuf>,
    /// Every event, in time order.
    pub events: Vec<Event>,
}

impl NeurotacFile {
    /// What a user should know about this file: which polarities it holds and that its times
    /// are milliseconds.
    pub fn note(&self) -> String {
        let polarity = match (&self.on_path, &self.off_path) {
            (Some(_), Some(_)) => "ON and OFF events".to_string(),
            (Some(on), None) => format!(
                "ON events only (no {} beside it)",
                partner_name(on).unwrap_or_else(|| "OFF file".into())
            ),
            (None, _) => "OFF events only (no ON file beside it)".to_string(),
        };
        format!(
            "NeuroTac pickle ({}), {polarity}; its times are milliseconds, so dynamic windows \
             below a few milliseconds are not resolved",
            self.order.describe()
        )
    }
}

/// The partner's file name of a `..._events_on` / `..._events_off` file.
fn partner_name(path: &Path) -> Option<String> {
    partner(path).and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
}

/// The other file of a pair: `X_events_on.ext` <-> `X_events_off.ext`.
fn partner(path: &Path) -> Option<PathBuf> {
    let name = path.file_name()?.to_str()?;
    let (stem, ext) = match name.split_once('.') {
        Some((s, e)) => (s, Some(e)),
        None => (name, None),
    };
    let other = if let Some(base) = stem.strip_suffix("events_on") {
        format!("{base}events_off")
    } else {
        format!("{}events_on", stem.strip_suffix("events_off")?)
    };
    let other = match ext {
        Some(e) => format!("{other}.{e}"),
        None => other,
    };
    Some(path.with_file_name(other))
}

/// Whether `path` names the ON file of a pair (else OFF; a name without either suffix is ON).
fn is_off(path: &Path) -> bool {
    path.file_name()
        .and_then(|n| n.to_str())
        .and_then(|n| n.split('.').next())
        .is_some_and(|stem| stem.ends_with("events_off"))
}

/// Whether `head` (a file's first bytes) starts a pickle of protocol 2 to 5, or an NPY array of
/// Python objects (saved with `allow_pickle=True`).
pub fn sniff(head: &[u8]) -> bool {
    matches!(head, [0x80, 2..=5, ..]) || npy_pickle_offset(head).is_some()
}

/// Where the pickle of an object-dtype NPY file starts, if `bytes` is one.
fn npy_pickle_offset(bytes: &[u8]) -> Option<usize> {
    let rest = bytes.strip_prefix(crate::npy::MAGIC)?;
    let (&major, rest) = rest.split_first()?;
    let rest = rest.get(1..)?;
    let (len, start): (usize, usize) = match major {
        1 => (
            usize::from(u16::from_le_bytes([*rest.first()?, *rest.get(1)?])),
            10,
        ),
        2 | 3 => (
            usize::try_from(u32::from_le_bytes(rest.get(..4)?.try_into().ok()?)).ok()?,
            12,
        ),
        _ => return None,
    };
    let header = std::str::from_utf8(bytes.get(start..start.checked_add(len)?)?).ok()?;
    let descr = header.split("'descr':").nth(1)?.trim_start();
    (descr.starts_with("'|O'") || descr.starts_with("'O'")).then_some(start + len)
}

/// Reads the file at `path` and its partner, if there is one.
pub fn read_pair(path: &Path) -> Result<NeurotacFile, NeurotacError> {
    let other = partner(path).filter(|p| p.is_file());
    let (on_path, off_path) = if is_off(path) {
        (other, Some(path.to_path_buf()))
    } else {
        (Some(path.to_path_buf()), other)
    };
    let mut events = Vec::new();
    let mut found: Option<(Resolution, PixelOrder, PathBuf)> = None;
    for (file, polarity) in [(&off_path, false), (&on_path, true)] {
        let Some(file) = file else { continue };
        let bytes = std::fs::read(file).map_err(|error| NeurotacError::Io {
            path: file.clone(),
            error,
        })?;
        let pixels = decode(file, &bytes)?;
        // The OFF file is read first, so a second file is the ON one.
        if let Some((off, _, off_path)) = &found
            && *off != pixels.resolution
        {
            return Err(NeurotacError::PairMismatch {
                on_path: file.clone(),
                on: pixels.resolution,
                off_path: off_path.clone(),
                off: *off,
            });
        }
        found = Some((pixels.resolution, pixels.order, file.clone()));
        push_events(&pixels, polarity, &mut events);
    }
    let (resolution, order, _) = found.ok_or_else(|| NeurotacError::Structure {
        path: path.to_path_buf(),
        what: "neither file of the pair exists".into(),
    })?;
    sort(&mut events);
    Ok(NeurotacFile {
        resolution,
        order,
        on_path,
        off_path,
        events,
    })
}

/// Events in time order; ties by row, column, then OFF before ON.
fn sort(events: &mut [Event]) {
    events.sort_unstable_by_key(|e| (e.t, e.y, e.x, e.polarity));
}

fn push_events(pixels: &PixelTimes, polarity: bool, out: &mut Vec<Event>) {
    for (x, y, times) in &pixels.cells {
        out.extend(times.iter().map(|&ms| Event {
            t: (ms * 1000.0).round() as i64,
            x: *x,
            y: *y,
            polarity,
        }));
    }
}

/// The bytes of one file (a pickle, or an object NPY) as per-pixel times.
fn decode(path: &Path, bytes: &[u8]) -> Result<PixelTimes, NeurotacError> {
    let start = npy_pickle_offset(bytes).unwrap_or(0);
    let (pickle, _) = pickle::read(&bytes[start..]).map_err(|error| NeurotacError::Pickle {
        path: path.to_path_buf(),
        error,
    })?;
    let structure = |what: String| NeurotacError::Structure {
        path: path.to_path_buf(),
        what,
    };
    let mut budget = Budget::new(bytes.len());
    pixel_times(&pickle.value, &mut budget).map_err(structure)
}

/// How many values the walk may visit: a few per input byte. A pickle that refers to its own
/// lists (a cycle, or one list shared a million times) runs out instead of running forever.
struct Budget(usize);

impl Budget {
    fn new(bytes: usize) -> Self {
        Self(bytes.saturating_mul(4).saturating_add(64))
    }

    fn spend(&mut self, n: usize) -> Result<(), String> {
        self.0 = self.0.checked_sub(n).ok_or_else(|| {
            "it refers to its own values more often than its size allows (a cycle?)".to_string()
        })?;
        Ok(())
    }
}

fn side(n: usize, what: &str) -> Result<u16, String> {
    u16::try_from(n)
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| format!("{what} is {n} pixels, not 1 to 65535"))
}

fn pixel_times(root: &Value, budget: &mut Budget) -> Result<PixelTimes, String> {
    match root {
        Value::Object(_) => {
            let array = ndarray(root)?;
            let [height, width] = array.shape[..] else {
                return Err(format!(
                    "a numpy array of shape {:?}, not 2-D (height x width)",
                    array.shape
                ));
            };
            let Data::Objects(cells) = &array.data else {
                return Err(format!(
                    "a numpy array of {}, not of Python objects (per-pixel lists)",
                    array.dtype
                ));
            };
            let (w, h) = (side(width, "the width")?, side(height, "the height")?);
            let cells = cells.borrow();
            if cells.len() != width * height {
                return Err(format!(
                    "a {height} x {width} array holds {} cells",
                    cells.len()
                ));
            }
            let mut out = Vec::new();
            for (i, cell) in cells.iter().enumerate() {
                let (y, x) = (i / width, i % width);
                // An array saved in Fortran order lists its cells column by column.
                let (x, y) = if array.fortran {
                    (i / height, i % height)
                } else {
                    (x, y)
                };
                let times =
                    cell_times(cell, budget).map_err(|e| format!("cell [{y}, {x}]: {e}"))?;
                if !times.is_empty() {
                    out.push((x as u16, y as u16, times));
                }
            }
            Ok(PixelTimes {
                order: PixelOrder::RowMajor,
                resolution: Resolution::new(w, h),
                cells: out,
            })
        }
        Value::List(columns) => {
            let columns = columns.borrow();
            budget.spend(columns.len())?;
            let w = side(columns.len(), "the outer list ([x])")?;
            let mut height = None;
            let mut out = Vec::new();
            for (x, column) in columns.iter().enumerate() {
                let Value::List(rows) = column else {
                    return Err(format!(
                        "[{x}] is {}, not a list of pixels",
                        column.describe()
                    ));
                };
                let rows = rows.borrow();
                budget.spend(rows.len())?;
                match height {
                    None => height = Some(rows.len()),
                    Some(h) if h != rows.len() => {
                        return Err(format!(
                            "[{x}] has {} pixels but [0] has {h}: not a [x][y] grid",
                            rows.len()
                        ));
                    }
                    Some(_) => {}
                }
                for (y, cell) in rows.iter().enumerate() {
                    let times = cell_times(cell, budget).map_err(|e| format!("[{x}][{y}]: {e}"))?;
                    if !times.is_empty() {
                        out.push((x as u16, y as u16, times));
                    }
                }
            }
            let h = side(height.unwrap_or(0), "the inner lists ([x][y])")?;
            Ok(PixelTimes {
                order: PixelOrder::ColumnLists,
                resolution: Resolution::new(w, h),
                cells: out,
            })
        }
        other => Err(format!("the file holds {}", other.describe())),
    }
}

/// One pixel's times in ms: a list of numbers, or a 1-D numeric numpy array.
fn cell_times(cell: &Value, budget: &mut Budget) -> Result<Vec<f64>, String> {
    let times: Vec<f64> = match cell {
        Value::List(items) => {
            let items = items.borrow();
            budget.spend(items.len().max(1))?;
            items
                .iter()
                .enumerate()
                .map(|(k, v)| match v {
                    Value::Float(f) => Ok(*f),
                    Value::Int(i) => Ok(*i as f64),
                    other => Err(format!("time {k} is {}, not a number", other.describe())),
                })
                .collect::<Result<_, _>>()?
        }
        Value::None => Vec::new(),
        Value::Object(_) => {
            let array = ndarray(cell)?;
            match &array.data {
                Data::Numbers(values) => {
                    budget.spend(values.len().max(1))?;
                    values.clone()
                }
                Data::Objects(_) => return Err("a numpy array of objects, not of times".into()),
            }
        }
        other => return Err(format!("{}, not a list of times", other.describe())),
    };
    if let Some((k, t)) = times
        .iter()
        .enumerate()
        .find(|(_, t)| !(t.is_finite() && (-9.2e15..=9.2e15).contains(*t)))
    {
        return Err(format!("time {k} is {t} ms, not a finite time"));
    }
    Ok(times)
}

/// A numpy array rebuilt from its pickle.
struct NdArray {
    shape: Vec<usize>,
    fortran: bool,
    dtype: String,
    data: Data,
}

enum Data {
    /// The cells of an object array.
    Objects(pickle::List),
    /// A numeric array's values.
    Numbers(Vec<f64>),
}

/// The callables numpy's array pickles use (older and newer numpy name the module differently).
const RECONSTRUCT: [&str; 2] = [
    "numpy.core.multiarray._reconstruct",
    "numpy._core.multiarray._reconstruct",
];

fn ndarray(value: &Value) -> Result<NdArray, String> {
    let Value::Object(object) = value else {
        return Err(format!("{}, not a numpy array", value.describe()));
    };
    let object = object.borrow();
    let name = object.callable.global_name().unwrap_or_default();
    if !RECONSTRUCT.contains(&name.as_str()) {
        return Err(format!(
            "a call to `{name}`, which is not numpy's array reconstruction (nothing is run)"
        ));
    }
    let Some(Value::Tuple(state)) = &object.state else {
        return Err("a numpy array without its state".into());
    };
    let [_, Value::Tuple(shape), dtype, Value::Bool(fortran), data] = &state[..] else {
        return Err("a numpy array state that is not (version, shape, dtype, order, data)".into());
    };
    let shape = shape
        .iter()
        .map(|d| match d {
            Value::Int(n) => usize::try_from(*n).map_err(|_| format!("shape entry {n}")),
            other => Err(format!("shape entry {}", other.describe())),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let (kind, little) = dtype_of(dtype)?;
    let data = match (kind.as_str(), data) {
        ("O8" | "O4" | "O", Value::List(cells)) => Data::Objects(cells.clone()),
        (_, Value::Bytes(bytes)) => Data::Numbers(numbers(&kind, little, bytes)?),
        (_, other) => return Err(format!("numpy data of {}", other.describe())),
    };
    Ok(NdArray {
        shape,
        fortran: *fortran,
        dtype: kind,
        data,
    })
}

/// A pickled `numpy.dtype`: its type string (`f8`, `O8`, ...) and whether it is little-endian.
fn dtype_of(value: &Value) -> Result<(String, bool), String> {
    let Value::Object(object) = value else {
        return Err(format!("dtype {}", value.describe()));
    };
    let object = object.borrow();
    if object.callable.global_name().as_deref() != Some("numpy.dtype") {
        return Err(format!("dtype {}", value.describe()));
    }
    let kind = match &object.args {
        Value::Tuple(args) => match args.first() {
            Some(Value::Str(s)) => s.to_string(),
            _ => return Err("a numpy dtype without its type".into()),
        },
        _ => return Err("a numpy dtype without its type".into()),
    };
    let little = match &object.state {
        Some(Value::Tuple(state)) => !matches!(state.get(1), Some(Value::Str(o)) if &**o == ">"),
        _ => true,
    };
    Ok((kind, little))
}

/// The values of a numeric array's raw bytes.
fn numbers(kind: &str, little: bool, bytes: &[u8]) -> Result<Vec<f64>, String> {
    macro_rules! read {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            if bytes.len() % N != 0 {
                return Err(format!("{} bytes of {kind}", bytes.len()));
            }
            bytes
                .chunks_exact(N)
                .map(|c| {
                    let raw: [u8; N] = c.try_into().unwrap_or([0; N]);
                    let v = if little {
                        <$t>::from_le_bytes(raw)
                    } else {
                        <$t>::from_be_bytes(raw)
                    };
                    v as f64
                })
                .collect()
        }};
    }
    Ok(match kind {
        "f8" => read!(f64),
        "f4" => read!(f32),
        "i8" => read!(i64),
        "i4" => read!(i32),
        "u8" => read!(u64),
        "u4" => read!(u32),
        other => return Err(format!("a numpy array of {other}, not of times")),
    })
}

/// The fuzzing entry point: decodes `data` as one NeuroTac file (nothing on disk).
pub fn fuzz_decode(data: &[u8]) -> usize {
    match decode(Path::new("fuzz"), data) {
        Ok(pixels) => {
            let mut events = Vec::new();
            push_events(&pixels, true, &mut events);
            sort(&mut events);
            events.len()
        }
        Err(_) => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partners_pair_on_and_off_files() {
        let p = |s: &str| partner(Path::new(s)).map(|p| p.display().to_string());
        assert_eq!(
            p("d/t3_events_on.pickle").as_deref(),
            Some("d/t3_events_off.pickle")
        );
        assert_eq!(p("d/t3_events_off").as_deref(), Some("d/t3_events_on"));
        assert_eq!(p("d/t3_events.npy"), None);
        assert!(is_off(Path::new("a/x_events_off.npy")));
        assert!(!is_off(Path::new("a/x_events_on.npy")));
    }

    #[test]
    fn the_object_npy_header_is_recognised() {
        let header = "{'descr': '|O', 'fortran_order': False, 'shape': (2, 3), }";
        let mut npy = crate::npy::MAGIC.to_vec();
        npy.extend_from_slice(&[1, 0]);
        npy.extend_from_slice(&(header.len() as u16).to_le_bytes());
        npy.extend_from_slice(header.as_bytes());
        assert_eq!(npy_pickle_offset(&npy), Some(npy.len()));
        assert!(sniff(&npy));
        // A record (or any non-object) dtype is an event NPY, not a pickle.
        let records: Vec<u8> = npy
            .iter()
            .map(|&b| if b == b'O' { b'V' } else { b })
            .collect();
        assert_eq!(npy_pickle_offset(&records), None);
    }
}
