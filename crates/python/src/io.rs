//! Reading and writing event files: `read` (a whole recording), `Reader` (a large file in
//! chunks, what `evtac.open` returns) and `write`, through `evtac_events` as `evtac convert`
//! uses it: every format the CLI reads, AEDAT4 / CSV / NPY written by the output's extension.

use evtac_formats::{StreamChoice, StreamSelection};
use std::path::PathBuf;
use std::sync::Mutex;

use evtac_events::check::EventCheck;
use evtac_events::{Event, ImuSample, Resolution, Roi, Trigger};
use evtac_formats::{EventReader, EventWriter};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;

use crate::error;
use crate::records::{self, Layout};

/// Maps an `evtac_events` error: a file's fault is an `OSError`, a caller's is a `ValueError`.
pub fn events_error(err: evtac_formats::Error) -> PyErr {
    match err {
        evtac_formats::Error::NotWritable { .. }
        | evtac_formats::Error::MissingResolution { .. }
        | evtac_formats::Error::ResolutionMismatch { .. }
        | evtac_formats::Error::Streams { .. } => error::value(err),
        evtac_formats::Error::Io { ref error, .. } => error::io(&err, error),
        _ => error::file(err),
    }
}

/// A recording, or one chunk of it: structured numpy arrays and what the file says.
#[pyclass(frozen, module = "evtac._evtac")]
pub struct Recording {
    /// Events: `t <i8 (us), x <i2, y <i2, p u1` (evtac's NPY dtype), in time order.
    #[pyo3(get)]
    events: Py<PyAny>,
    /// IMU samples: `t <i8, ax ay az <f4 (g), gx gy gz <f4 (deg/s), temperature <f4`.
    #[pyo3(get)]
    imu: Py<PyAny>,
    /// Triggers: `t <i8, kind i1` (the AEDAT4 trigger type).
    #[pyo3(get)]
    triggers: Py<PyAny>,
    /// `(width, height)` of the sensor (of the crop when one was taken), or `None` when the
    /// file does not state it (CSV, NPY, NPZ, DSEC's HDF5) and none was given.
    #[pyo3(get)]
    resolution: Option<(u16, u16)>,
    /// The file's format: `AEDAT4`, `AEDAT3.1`, `AEDAT2`, `EVT2`, `EVT21`, `EVT3`, `CSV` or
    /// `NPY`.
    #[pyo3(get)]
    format: &'static str,
    /// The camera that recorded it, when the file says.
    #[pyo3(get)]
    source: Option<String>,
}

#[pymethods]
impl Recording {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "Recording(format={}, resolution={}, events={}, imu={}, triggers={})",
            self.format,
            self.resolution
                .map_or_else(|| "None".to_string(), |(w, h)| format!("({w}, {h})")),
            self.events.bind(py).len()?,
            self.imu.bind(py).len()?,
            self.triggers.bind(py).len()?,
        ))
    }

    /// The recording with its events through the filters `specs` (the command line's SPECs, in
    /// order), IMU samples and triggers untouched; and each filter's SPEC with the events it
    /// removed. The recording must state its sensor size.
    fn filter(
        &self,
        py: Python<'_>,
        specs: Vec<String>,
    ) -> PyResult<(Recording, crate::filter::Removed)> {
        let Some((w, h)) = self.resolution else {
            return Err(error::value(
                "the recording does not state its sensor size: read it with resolution=(width, height) to filter it",
            ));
        };
        let view = self.events.bind(py).call_method1("view", ("u1",))?;
        let bytes: PyReadonlyArray1<'_, u8> = view.extract()?;
        let bytes = bytes.as_slice().map_err(error::value)?;
        let (kept, removed) =
            py.detach(|| crate::filter::run(bytes, Resolution::new(w, h), &specs))?;
        let recording = Recording {
            events: Layout::Event.to_numpy(py, kept)?.unbind(),
            imu: self.imu.clone_ref(py),
            triggers: self.triggers.clone_ref(py),
            resolution: self.resolution,
            format: self.format,
            source: self.source.clone(),
        };
        Ok((recording, removed))
    }
}

/// What a read produced, packed, before it reaches numpy.
struct Packed {
    events: Vec<u8>,
    imu: Vec<u8>,
    triggers: Vec<u8>,
    resolution: Option<Resolution>,
}

impl Packed {
    fn new(
        events: &[Event],
        imu: &[ImuSample],
        triggers: &[Trigger],
        resolution: Option<Resolution>,
    ) -> PyResult<Self> {
        Ok(Self {
            events: records::encode_events(events)?,
            imu: records::encode_imu(imu),
            triggers: records::encode_triggers(triggers),
            resolution,
        })
    }

    fn into_recording(
        self,
        py: Python<'_>,
        format: &'static str,
        source: Option<String>,
    ) -> PyResult<Recording> {
        Ok(Recording {
            events: Layout::Event.to_numpy(py, self.events)?.unbind(),
            imu: Layout::Imu.to_numpy(py, self.imu)?.unbind(),
            triggers: Layout::Trigger.to_numpy(py, self.triggers)?.unbind(),
            resolution: self.resolution.map(|r| (r.width, r.height)),
            format,
            source,
        })
    }
}

/// Opens `path` (its event stream `stream`, for AEDAT4 files with several), declares
/// `resolution` if given, and finds the crop of `roi` (centered).
fn open_cropped(
    path: &PathBuf,
    roi: Option<(u16, u16)>,
    resolution: Option<(u16, u16)>,
    stream: Option<&str>,
) -> PyResult<(EventReader, Option<Roi>)> {
    let selection = StreamSelection {
        events: stream
            .map(str::parse::<StreamChoice>)
            .transpose()
            .map_err(|e| error::value(format!("stream: {e}")))?,
        ..StreamSelection::default()
    };
    let mut reader = evtac_formats::open_with(path, &selection).map_err(events_error)?;
    if let Some((w, h)) = resolution {
        reader
            .set_resolution(Resolution::new(w, h))
            .map_err(events_error)?;
    }
    let Some((w, h)) = roi else {
        return Ok((reader, None));
    };
    let size = Resolution::new(w, h);
    let Some(sensor) = reader.resolution() else {
        return Err(error::value(format!(
            "{} is {} and does not state its sensor size: pass resolution=(width, height) to crop it",
            path.display(),
            reader.format()
        )));
    };
    let crop = Roi::centered(sensor, size).ok_or_else(|| {
        error::value(format!(
            "roi {size} does not fit inside the {sensor} sensor of {}",
            path.display()
        ))
    })?;
    Ok((reader, Some(crop)))
}

/// Reads the whole file at `path`, cropped to the centered `roi` if given.
#[pyfunction]
#[pyo3(signature = (path, roi = None, resolution = None, stream = None))]
pub fn read(
    py: Python<'_>,
    path: PathBuf,
    roi: Option<(u16, u16)>,
    resolution: Option<(u16, u16)>,
    stream: Option<String>,
) -> PyResult<Recording> {
    let (packed, format, source) = py.detach(|| -> PyResult<_> {
        let (reader, crop) = open_cropped(&path, roi, resolution, stream.as_deref())?;
        let rec = reader.into_recording().map_err(events_error)?;
        let (events, resolution) = match crop {
            Some(crop) => {
                let mut cropped = Vec::new();
                crop.crop_into(&rec.events, &mut cropped);
                (cropped, Some(crop.size))
            }
            None => (rec.events, rec.resolution),
        };
        let packed = Packed::new(&events, &rec.imu, &rec.triggers, resolution)?;
        Ok((packed, rec.format.name(), rec.source))
    })?;
    packed.into_recording(py, format, source)
}

/// A large event file read chunk by chunk (iterate it: each item is a `Recording` of one
/// chunk of at least `chunk_events` events, the last one shorter).
#[pyclass(frozen, module = "evtac._evtac")]
pub struct Reader {
    inner: Mutex<ReaderState>,
    /// The file's format.
    #[pyo3(get)]
    format: &'static str,
    /// The camera that recorded it, when the file says.
    #[pyo3(get)]
    source: Option<String>,
}

struct ReaderState {
    reader: EventReader,
    crop: Option<Roi>,
    chunk_events: usize,
    done: bool,
}

impl ReaderState {
    /// Gathers reader chunks until `chunk_events` events (or the end), cropped.
    fn next(&mut self) -> PyResult<Option<Packed>> {
        if self.done {
            return Ok(None);
        }
        let (mut events, mut imu, mut triggers) = (Vec::new(), Vec::new(), Vec::new());
        let mut any = false;
        while events.len() < self.chunk_events {
            let Some(chunk) = self.reader.next_chunk().map_err(events_error)? else {
                self.done = true;
                break;
            };
            any = true;
            match &self.crop {
                Some(crop) => events.extend(chunk.events.iter().filter_map(|&e| crop.map(e))),
                None => events.extend_from_slice(chunk.events),
            }
            imu.extend_from_slice(chunk.imu);
            triggers.extend_from_slice(chunk.triggers);
        }
        if !any {
            return Ok(None);
        }
        let resolution = self.crop.map(|c| c.size).or(self.reader.resolution());
        Packed::new(&events, &imu, &triggers, resolution).map(Some)
    }
}

#[pymethods]
impl Reader {
    #[new]
    #[pyo3(signature = (path, roi = None, resolution = None, chunk_events = 65536, stream = None))]
    fn new(
        py: Python<'_>,
        path: PathBuf,
        roi: Option<(u16, u16)>,
        resolution: Option<(u16, u16)>,
        chunk_events: usize,
        stream: Option<String>,
    ) -> PyResult<Self> {
        if chunk_events == 0 {
            return Err(error::value("chunk_events must be at least 1"));
        }
        let (reader, crop) =
            py.detach(|| open_cropped(&path, roi, resolution, stream.as_deref()))?;
        Ok(Self {
            format: reader.format().name(),
            source: reader.source().map(str::to_string),
            inner: Mutex::new(ReaderState {
                reader,
                crop,
                chunk_events,
                done: false,
            }),
        })
    }

    /// `(width, height)` of the sensor (of the crop when one is taken), or `None`.
    #[getter]
    fn resolution(&self) -> PyResult<Option<(u16, u16)>> {
        let state = self.state()?;
        let r = state.crop.map(|c| c.size).or(state.reader.resolution());
        Ok(r.map(|r| (r.width, r.height)))
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__(&self, py: Python<'_>) -> PyResult<Option<Recording>> {
        let packed = py.detach(|| self.state()?.next())?;
        packed
            .map(|p| p.into_recording(py, self.format, self.source.clone()))
            .transpose()
    }
}

impl Reader {
    fn state(&self) -> PyResult<std::sync::MutexGuard<'_, ReaderState>> {
        self.inner
            .lock()
            .map_err(|_| error::value("the reader failed in another thread and cannot go on"))
    }
}

/// Writes `events` (packed event records), and for AEDAT4 `imu` (packed IMU records), to
/// `path`; the extension picks the format (`.aedat4`, `.csv`, `.npy`).
#[pyfunction]
#[pyo3(signature = (path, events, imu = None, resolution = None, source = None))]
pub fn write(
    py: Python<'_>,
    path: PathBuf,
    events: PyReadonlyArray1<'_, u8>,
    imu: Option<PyReadonlyArray1<'_, u8>>,
    resolution: Option<(u16, u16)>,
    source: Option<String>,
) -> PyResult<()> {
    let events = events.as_slice().map_err(error::value)?;
    let imu = imu
        .as_ref()
        .map(|a| a.as_slice())
        .transpose()
        .map_err(error::value)?;
    py.detach(|| {
        let events = records::decode_events(events)?;
        let imu = imu
            .map(records::decode_imu)
            .transpose()?
            .unwrap_or_default();
        let resolution = resolution.map(|(w, h)| Resolution::new(w, h));
        // An extension evtac cannot write is the caller's mistake, not the file system's.
        evtac_formats::Format::for_writing(&path).map_err(error::value)?;
        EventCheck::new(resolution)
            .check(&events)
            .map_err(|e| error::value(format!("events to write: {e}")))?;
        let mut writer =
            EventWriter::create(&path, resolution, source.as_deref()).map_err(events_error)?;
        writer.write_events(&events).map_err(events_error)?;
        writer.write_imu(&imu).map_err(events_error)?;
        writer.finish().map_err(events_error)
    })
}
