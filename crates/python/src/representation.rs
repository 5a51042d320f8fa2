//! `Representation`: static, dynamic or combined frames and pooled features (or a time surface's,
//! a histogram's or a voxel grid's real-valued frames), as `evtac represent` builds them (the same crop, mask and `FeatureExtractor`), either in one
//! call over a whole recording (`features`, `frames`, `potentials`) or incrementally (`push`,
//! `advance_to`), which gives the same numbers for any chunking.
//!
//! Settings come as a JSON object with the fields of `evtac_repr::StaticConfig` and
//! `DynamicConfig` (those of the CLI's options, with the CLI's defaults), or for the real-valued
//! kinds those of `evtac_repr::DenseSettings` (`tau_ms`, `threshold`, `window_ms`, `bins`); a
//! setting that the kind does not take, or an unknown one, is a `ValueError` naming it.

use std::sync::{Mutex, MutexGuard};

use evtac_events::check::EventCheck;
use evtac_events::{Event, Resolution, Roi};
use evtac_repr::{
    CROP, DenseSettings, DynamicConfig, FeatureExtractor, FeatureProvenance, Mask, ReprConfig,
    ReprKind, StaticConfig,
};
use ndarray::{Array2, Array3, Array4};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use serde_json::{Map, Value};

use crate::error;
use crate::records;

/// The settings of the static part, as `StaticConfig` names them.
const STATIC_SETTINGS: &[&str] = &[
    "decay",
    "tau_ms",
    "eta",
    "threshold",
    "threshold_space",
    "comparison",
    "min_potential",
    "max_potential",
    "neutral_potential",
    "polarity",
    "synchronous_decay",
];
/// The settings of the dynamic part, as `DynamicConfig` names them.
const DYNAMIC_SETTINGS: &[&str] = &["window_ms", "count_threshold"];

/// The settings of the real-valued kinds, as `DenseSettings` names them.
const DENSE_SETTINGS: &[&str] = &["tau_ms", "threshold", "window_ms", "bins"];

/// A real-valued kind's config from `settings`: each one a number the kind takes.
fn parse_dense(kind: ReprKind, settings: Map<String, Value>) -> PyResult<ReprConfig> {
    let mut dense = DenseSettings::default();
    for (key, value) in settings {
        let number = value
            .as_f64()
            .ok_or_else(|| error::value(format!("`{key}` must be a number, not {value}")))?;
        match key.as_str() {
            "tau_ms" => dense.tau_ms = Some(number),
            "threshold" => dense.threshold = Some(number),
            "window_ms" => dense.window_ms = Some(number),
            "bins" => {
                let bins = value.as_u64().and_then(|b| u32::try_from(b).ok());
                dense.bins = Some(bins.ok_or_else(|| {
                    error::value(format!(
                        "`bins` must be a positive whole number, not {value}"
                    ))
                })?);
            }
            _ => {
                return Err(error::value(format!(
                    "unknown setting `{key}` of a {} representation; its settings are among: {}",
                    kind.name(),
                    DENSE_SETTINGS.join(", ")
                )));
            }
        }
    }
    kind.dense_config(dense).map_err(error::value)
}

/// The config of a `kind` representation with `settings` (a JSON object), the rest defaults.
pub fn parse_config(kind: &str, settings: &str) -> PyResult<ReprConfig> {
    let settings: Map<String, Value> = serde_json::from_str(settings)
        .map_err(|e| error::value(format!("settings must be a JSON object: {e}")))?;
    let kind: ReprKind = kind.parse().map_err(error::value)?;
    if kind.is_dense() {
        return parse_dense(kind, settings);
    }
    let (has_static, has_dynamic) = kind.parts();
    let (mut st, mut dy) = (Map::new(), Map::new());
    for (key, value) in settings {
        let (part, allowed) = if STATIC_SETTINGS.contains(&key.as_str()) {
            (&mut st, has_static)
        } else if DYNAMIC_SETTINGS.contains(&key.as_str()) {
            (&mut dy, has_dynamic)
        } else {
            return Err(error::value(format!(
                "unknown setting `{key}`; static settings: {}; dynamic settings: {}",
                STATIC_SETTINGS.join(", "),
                DYNAMIC_SETTINGS.join(", ")
            )));
        };
        if !allowed {
            return Err(error::value(format!(
                "`{key}` is not a setting of a {} representation",
                kind.name()
            )));
        }
        part.insert(key, value);
    }
    let static_part = |m| {
        serde_json::from_value::<StaticConfig>(Value::Object(m))
            .map_err(|e| error::value(format!("static settings: {e}")))
    };
    let dynamic_part = |m| {
        serde_json::from_value::<DynamicConfig>(Value::Object(m))
            .map_err(|e| error::value(format!("dynamic settings: {e}")))
    };
    // A part the kind does not take is left at its default (and ignored by `config`).
    let static_part = if has_static {
        static_part(st)?
    } else {
        StaticConfig::default()
    };
    let dynamic_part = if has_dynamic {
        dynamic_part(dy)?
    } else {
        DynamicConfig::default()
    };
    let config = kind.config(static_part, dynamic_part);
    config.validate().map_err(error::value)?;
    Ok(config)
}

/// A representation on a crop of a sensor, with its incremental state.
#[pyclass(frozen, module = "evtac._evtac")]
pub struct Representation {
    config: ReprConfig,
    /// The sensor events come from; `None`: events are already in crop coordinates.
    sensor: Option<Resolution>,
    roi: Roi,
    mask: Option<Mask>,
    state: Mutex<FeatureExtractor>,
}

/// The crop of a `roi`-sized region centered on `sensor` (the whole sensor when no `roi`), or
/// the whole of a `roi`-sized frame when events come cropped already (no `sensor`).
pub fn crop_of(sensor: Option<Resolution>, roi: Option<Resolution>) -> PyResult<Roi> {
    match (sensor, roi) {
        (Some(sensor), Some(size)) => Roi::centered(sensor, size).ok_or_else(|| {
            error::value(format!(
                "roi {size} does not fit inside the {sensor} sensor"
            ))
        }),
        (Some(sensor), None) => Ok(Roi::full(sensor)),
        (None, Some(size)) => Ok(Roi::full(size)),
        (None, None) => Err(error::value(
            "give the sensor size, the crop size (roi), or both",
        )),
    }
}

/// Decodes events and brings them to the coordinates of `roi`, checking them against `sensor`
/// (events without a sensor are taken as cropped already and checked later, by the extractor).
fn crop_events(sensor: Option<Resolution>, roi: &Roi, events: &[u8]) -> PyResult<Vec<Event>> {
    let events = records::decode_events(events)?;
    let Some(sensor) = sensor else {
        return Ok(events);
    };
    EventCheck::new(Some(sensor))
        .check(&events)
        .map_err(error::value)?;
    let mut cropped = Vec::with_capacity(events.len());
    roi.crop_into(&events, &mut cropped);
    Ok(cropped)
}

impl Representation {
    /// A representation of `config` on `roi` of `sensor` (`None`: events come cropped), with an
    /// optional no-contact mask of the crop's size.
    pub fn build(
        config: ReprConfig,
        sensor: Option<Resolution>,
        roi: Roi,
        mask: Option<Mask>,
    ) -> PyResult<Self> {
        if mask.is_some() && config.dense_part().is_some() {
            return Err(error::value(format!(
                "a no-contact mask applies to the static part: a {} representation has none",
                config.kind_name()
            )));
        }
        if let Some(mask) = &mask
            && mask.resolution() != roi.size
        {
            return Err(error::value(format!(
                "the mask is {} but the crop is {}",
                mask.resolution(),
                roi.size
            )));
        }
        let fx = FeatureExtractor::new(&[config], roi.size, mask.as_ref()).map_err(error::value)?;
        Ok(Self {
            config,
            sensor,
            roi,
            mask,
            state: Mutex::new(fx),
        })
    }

    /// The extractor, for incremental use.
    fn state(&self) -> PyResult<MutexGuard<'_, FeatureExtractor>> {
        self.state
            .lock()
            .map_err(|_| error::value("the representation failed in another thread"))
    }

    fn cropped(&self, events: &[u8]) -> PyResult<Vec<Event>> {
        crop_events(self.sensor, &self.roi, events)
    }

    /// Runs a fresh extractor over `events` at `times`, as `evtac represent` does, visiting
    /// it at each sample time.
    fn run(
        &self,
        events: &[u8],
        times: &[i64],
        visit: impl FnMut(usize, &FeatureExtractor),
    ) -> PyResult<()> {
        let cropped = self.cropped(events)?;
        let mut fx = FeatureExtractor::new(&[self.config], self.roi.size, self.mask.as_ref())
            .map_err(error::value)?;
        fx.run(&cropped, times, visit).map_err(error::value)
    }

    /// What `read` appends at each of `times` (`per_sample` values each), concatenated, with the
    /// interpreter released while the representation runs: the shared body of `features`,
    /// `frames` and `potentials`. Returns the number of samples with the values.
    fn sampled<T: Copy + Send + Sync>(
        &self,
        py: Python<'_>,
        events: &PyReadonlyArray1<'_, u8>,
        times: &PyReadonlyArray1<'_, i64>,
        per_sample: usize,
        read: impl Fn(&FeatureExtractor, &mut Vec<T>) + Sync,
    ) -> PyResult<(usize, Vec<T>)> {
        let (events, times) = (
            events.as_slice().map_err(error::value)?,
            times.as_slice().map_err(error::value)?,
        );
        py.detach(|| {
            let mut out = Vec::with_capacity(times.len() * per_sample);
            self.run(events, times, |_, fx| read(fx, &mut out))?;
            Ok((times.len(), out))
        })
    }

    /// `(height, width)` of a frame: the crop's, twice as high for stacked and late (the
    /// static frame above the dynamic one); a real-valued kind's channels are a dimension of
    /// their own.
    fn frame_dims(&self) -> (usize, usize) {
        let stacked = match self.config.dense_part() {
            Some(_) => 1,
            None => self.config.frames(),
        };
        (
            usize::from(self.roi.size.height) * stacked,
            usize::from(self.roi.size.width),
        )
    }
}

#[pymethods]
impl Representation {
    #[new]
    #[pyo3(signature = (kind, settings, sensor = None, roi = None, mask = None, mask_events = None))]
    fn new(
        py: Python<'_>,
        kind: &str,
        settings: &str,
        sensor: Option<(u16, u16)>,
        roi: Option<(u16, u16)>,
        mask: Option<PyReadonlyArray2<'_, u8>>,
        mask_events: Option<PyReadonlyArray1<'_, u8>>,
    ) -> PyResult<Self> {
        let config = parse_config(kind, settings)?;
        let sensor = sensor.map(|(w, h)| Resolution::new(w, h));
        let roi = crop_of(sensor, roi.map(|(w, h)| Resolution::new(w, h)))?;
        let frame = roi.size;
        let mask = match (mask, mask_events) {
            (Some(_), Some(_)) => {
                return Err(error::value("give a mask or no-contact events, not both"));
            }
            (Some(pixels), None) => {
                let flat: Vec<u8> = pixels.as_array().iter().copied().collect();
                Some(Mask::from_grid(frame, pixels.as_array().dim(), &flat).map_err(error::value)?)
            }
            (None, Some(events)) => {
                let Some(static_part) = config.static_part() else {
                    return Err(error::value(
                        "a no-contact mask applies to the static part: static or combined only",
                    ));
                };
                let events = events.as_slice().map_err(error::value)?;
                Some(py.detach(|| {
                    // Checked against the sensor, or against the crop when the events come
                    // cropped already (cropping then keeps them all).
                    let events = records::decode_events(events)?;
                    EventCheck::new(Some(sensor.unwrap_or(frame)))
                        .check(&events)
                        .map_err(error::value)?;
                    Mask::from_recording(&roi, static_part, &events).map_err(error::value)
                })?)
            }
            (None, None) => None,
        };
        Self::build(config, sensor, roi, mask)
    }

    /// Pooled features at each of `times` (non-decreasing, us): float32 `(N, features)`.
    fn features<'py>(
        &self,
        py: Python<'py>,
        events: PyReadonlyArray1<'py, u8>,
        times: PyReadonlyArray1<'py, i64>,
    ) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let len = self.state()?.feature_len(0);
        let (n, out) = self.sampled(py, &events, &times, len, |fx, out| {
            out.extend_from_slice(fx.features(0));
        })?;
        let out = Array2::from_shape_vec((n, len), out).map_err(error::value)?;
        Ok(out.into_pyarray(py))
    }

    /// Binary frames at each of `times`: uint8 `(N, height, width)`, 0 or 1 (stacked and late:
    /// `(N, 2 * height, width)`, the static frame above the dynamic one); for a time surface,
    /// histogram or voxel grid float32 `(N, channels, height, width)`, tonic's layout.
    fn frames<'py>(
        &self,
        py: Python<'py>,
        events: PyReadonlyArray1<'py, u8>,
        times: PyReadonlyArray1<'py, i64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (h, w) = self.frame_dims();
        if self.config.dense_part().is_some() {
            let c = self.config.frames();
            let (n, out) = self.sampled(py, &events, &times, c * h * w, |fx, out| {
                let mut values = Vec::new();
                fx.frame_values_into(0, &mut values);
                out.extend_from_slice(&values);
            })?;
            let out = Array4::from_shape_vec((n, c, h, w), out).map_err(error::value)?;
            return Ok(out.into_pyarray(py).into_any());
        }
        let (n, out) = self.sampled(py, &events, &times, h * w, |fx, out| {
            out.extend_from_slice(fx.frame(0));
        })?;
        let out = Array3::from_shape_vec((n, h, w), out).map_err(error::value)?;
        Ok(out.into_pyarray(py).into_any())
    }

    /// The static accumulator's potentials at each of `times`: float32 `(N, height, width)`.
    fn potentials<'py>(
        &self,
        py: Python<'py>,
        events: PyReadonlyArray1<'py, u8>,
        times: PyReadonlyArray1<'py, i64>,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        if self.config.static_part().is_none() {
            return Err(error::value(
                "a dynamic representation has no potentials (every kind with a static part has)",
            ));
        }
        let (h, w) = (
            usize::from(self.roi.size.height),
            usize::from(self.roi.size.width),
        );
        let (n, out) = self.sampled(py, &events, &times, h * w, |fx, out| {
            out.extend_from_slice(fx.potentials(0).unwrap_or_default());
        })?;
        let out = Array3::from_shape_vec((n, h, w), out).map_err(error::value)?;
        Ok(out.into_pyarray(py))
    }

    /// Queues events (time order, also across calls) for the incremental state.
    fn push(&self, py: Python<'_>, events: PyReadonlyArray1<'_, u8>) -> PyResult<()> {
        let events = events.as_slice().map_err(error::value)?;
        py.detach(|| {
            let cropped = self.cropped(events)?;
            self.state()?.push(&cropped).map_err(error::value)
        })
    }

    /// Applies the queued events up to `t_us` and returns the features then (a copy).
    fn advance_to<'py>(&self, py: Python<'py>, t_us: i64) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let features = py.detach(|| -> PyResult<_> {
            let mut fx = self.state()?;
            fx.advance_to(t_us).map_err(error::value)?;
            Ok(fx.features(0).to_vec())
        })?;
        Ok(features.into_pyarray(py))
    }

    /// The incremental state's current binary frame (a copy): uint8 `(height, width)`; for a
    /// real-valued kind float32 `(channels, height, width)`.
    fn frame<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (h, w) = self.frame_dims();
        if self.config.dense_part().is_some() {
            let mut values = Vec::new();
            self.state()?.frame_values_into(0, &mut values);
            let c = self.config.frames();
            let out = Array3::from_shape_vec((c, h, w), values).map_err(error::value)?;
            return Ok(out.into_pyarray(py).into_any());
        }
        let frame = self.state()?.frame(0).to_vec();
        Ok(Array2::from_shape_vec((h, w), frame)
            .map_err(error::value)?
            .into_pyarray(py)
            .into_any())
    }

    /// Forgets the incremental state (queued events, potentials, windows, sample time).
    fn reset(&self) -> PyResult<()> {
        self.state()?.reset();
        Ok(())
    }

    /// The latest time given to `advance_to`, or `None`.
    #[getter]
    fn time_us(&self) -> PyResult<Option<i64>> {
        Ok(self.state()?.sample_time())
    }

    /// The config as JSON (`evtac_repr::ReprConfig`'s serialization, with its `kind`).
    #[getter]
    fn config_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.config).map_err(error::value)
    }

    /// `static`, `dynamic`, `combined`, `stacked`, `late`, `time-surface`, `histogram` or
    /// `voxel-grid`.
    #[getter]
    fn kind(&self) -> &'static str {
        self.config.kind_name()
    }

    /// The cache key naming the config (as in evtac's feature caches).
    #[getter]
    fn cache_key(&self) -> String {
        self.config.cache_key()
    }

    /// `(width, height)` of the sensor, or `None` when events come cropped.
    #[getter]
    fn sensor(&self) -> Option<(u16, u16)> {
        self.sensor.map(|r| (r.width, r.height))
    }

    /// The crop: `(x0, y0, width, height)` on the sensor.
    #[getter]
    fn roi(&self) -> (u16, u16, u16, u16) {
        (
            self.roi.x0,
            self.roi.y0,
            self.roi.size.width,
            self.roi.size.height,
        )
    }

    /// The no-contact mask (a copy, uint8 `(height, width)`, 1 = masked), or `None`.
    #[getter]
    fn mask<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<u8>>>> {
        // The crop's size: a stacked frame is twice as high, its mask is not.
        let (h, w) = (
            usize::from(self.roi.size.height),
            usize::from(self.roi.size.width),
        );
        self.mask
            .as_ref()
            .map(|m| {
                Array2::from_shape_vec((h, w), m.pixels().to_vec())
                    .map(|a| a.into_pyarray(py))
                    .map_err(error::value)
            })
            .transpose()
    }

    /// What its features are made of (representation, crop, mask), as JSON: `Model.predict`
    /// compares it with the model's.
    #[getter]
    fn provenance(&self) -> PyResult<String> {
        let p = FeatureProvenance::new(&self.config, self.roi.size, self.mask.as_ref());
        serde_json::to_string(&p).map_err(error::value)
    }

    /// Features per sample (900 on the paper's 240x240 crop, 1800 for stacked and late).
    #[getter]
    fn feature_len(&self) -> PyResult<usize> {
        Ok(self.state()?.feature_len(0))
    }
}

impl Representation {
    /// The config.
    pub fn config(&self) -> ReprConfig {
        self.config
    }

    /// The mask, if any.
    pub fn mask_ref(&self) -> Option<&Mask> {
        self.mask.as_ref()
    }

    /// Whether features come from the paper's 240x240 crop, as a model bundle requires.
    pub fn on_crop(&self) -> bool {
        self.roi.size == CROP
    }
}
