//! `Model` (a trained model bundle: `evtac_learn::Model`, as `evtac predict` and
//! `evtac online` load it) and `Estimator` (the online path: `evtac_online::Estimator`, one
//! estimate per interval of event time, returned as soon as it is final).

use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use evtac_events::Resolution;
use evtac_learn::ModelBundle;
use evtac_online::Estimate;
use evtac_repr::{CROP, FeatureProvenance};
use ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::error;
use crate::records::{self, Layout};
use crate::representation::{Representation, crop_of};

/// A trained model bundle loaded for prediction.
#[pyclass(frozen, module = "evtac._evtac")]
pub struct Model {
    inner: evtac_learn::Model,
}

#[pymethods]
impl Model {
    /// Loads the bundle folder `dir` (`model.safetensors`, `config.json`, optional `mask.npy`).
    #[staticmethod]
    fn load(py: Python<'_>, dir: PathBuf) -> PyResult<Self> {
        let inner = py
            .detach(|| evtac_learn::Model::load(&dir))
            .map_err(error::file)?;
        Ok(Self { inner })
    }

    /// A model with seeded initial weights (PyTorch's initialisation) for `representation`'s
    /// config and mask, which must be on the 240x240 crop.
    #[staticmethod]
    fn untrained(seed: u64, representation: &Representation) -> PyResult<Self> {
        if !representation.on_crop() {
            return Err(error::value(format!(
                "a model's features come from the {CROP} crop; this representation's crop differs"
            )));
        }
        let bundle = ModelBundle::untrained(
            seed,
            evtac_learn::Representation::new(representation.config()),
            representation.mask_ref().cloned(),
        );
        let inner =
            evtac_learn::Model::from_bundle("untrained".as_ref(), bundle).map_err(error::value)?;
        Ok(Self { inner })
    }

    /// Writes the bundle to the folder `dir` (created if needed).
    fn save(&self, py: Python<'_>, dir: PathBuf) -> PyResult<()> {
        py.detach(|| self.inner.bundle.save(&dir))
            .map_err(error::file)
    }

    /// (pitch, roll) in degrees for each row of `features` (float32 `(N, 900)`, `(N, 1800)` for
    /// stacked and late models): float32 `(N, 2)`.
    fn predict<'py>(
        &self,
        py: Python<'py>,
        features: PyReadonlyArray2<'py, f32>,
    ) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let (n, width) = features.as_array().dim();
        let inputs = self.inner.predictor.inputs();
        if width != inputs {
            return Err(error::value(format!(
                "features must have shape (N, {inputs}), got ({n}, {width})"
            )));
        }
        let flat = features.as_slice().map_err(error::value)?;
        let out = py.detach(|| -> PyResult<_> {
            let rows = self.inner.predict(flat).map_err(error::value)?;
            Array2::from_shape_vec((rows.len(), 2), rows.into_iter().flatten().collect())
                .map_err(error::value)
        })?;
        Ok(out.into_pyarray(py))
    }

    /// Refuses features made otherwise than the model's (`provenance`: the JSON a
    /// `Representation` attaches to its features; `None`: a plain array, which says nothing).
    #[pyo3(signature = (provenance = None))]
    fn check_features(&self, provenance: Option<&str>) -> PyResult<()> {
        let expected = self.inner.feature_provenance();
        let Some(text) = provenance else {
            return Err(error::value(format!(
                "these features carry no record of what made them (a plain array); the model \
                 {} reads {expected}: compute them with model.representation(sensor).features(...), \
                 or pass check=False if you know they match",
                self.inner.dir.display()
            )));
        };
        let got: FeatureProvenance = serde_json::from_str(text)
            .map_err(|e| error::value(format!("the features' provenance is unreadable: {e}")))?;
        match got.mismatch(&expected) {
            None => Ok(()),
            Some(why) => Err(error::value(format!(
                "these features do not match the model {}: {why}",
                self.inner.dir.display()
            ))),
        }
    }

    /// The representation the model's features are computed with (its config and mask, on
    /// the centered 240x240 crop of `sensor`; `None`: events come cropped).
    #[pyo3(signature = (sensor = None))]
    fn representation(&self, sensor: Option<(u16, u16)>) -> PyResult<Representation> {
        let sensor = sensor.map(|(w, h)| Resolution::new(w, h));
        let roi = crop_of(sensor, Some(CROP))?;
        Representation::build(
            self.inner.repr_config(),
            sensor,
            roi,
            self.inner.mask().cloned(),
        )
    }

    /// `config.json` as JSON text.
    #[getter]
    fn config_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.inner.bundle.config).map_err(error::value)
    }

    /// The folder the model was loaded from.
    #[getter]
    fn dir(&self) -> PathBuf {
        self.inner.dir.clone()
    }
}

/// The online estimator: events in, estimates out as they become final.
#[pyclass(frozen, module = "evtac._evtac")]
pub struct Estimator {
    inner: Mutex<evtac_online::Estimator>,
}

fn encode(estimates: &[Estimate]) -> Vec<u8> {
    let mut out = Vec::with_capacity(estimates.len() * 24);
    for e in estimates {
        out.extend_from_slice(&e.t_us.to_le_bytes());
        out.extend_from_slice(&e.pitch_deg.to_le_bytes());
        out.extend_from_slice(&e.roll_deg.to_le_bytes());
        out.extend_from_slice(&(e.latency.as_secs_f64() * 1e6).to_le_bytes());
    }
    out
}

impl Estimator {
    fn run(
        &self,
        step: impl FnOnce(&mut evtac_online::Estimator, &mut dyn FnMut(&Estimate)) -> PyResult<()>,
    ) -> PyResult<Vec<u8>> {
        let mut inner = self
            .inner
            .lock()
            .map_err(|_| error::value("the estimator failed in another thread"))?;
        let mut out = Vec::new();
        step(&mut inner, &mut |e| out.push(*e))?;
        Ok(encode(&out))
    }
}

#[pymethods]
impl Estimator {
    #[new]
    fn new(model: &Model, sensor: (u16, u16), interval_us: i64) -> PyResult<Self> {
        let sensor = Resolution::new(sensor.0, sensor.1);
        let inner = evtac_online::Estimator::for_model(&model.inner, sensor, interval_us)
            .map_err(error::value)?;
        Ok(Self {
            inner: Mutex::new(inner),
        })
    }

    /// Takes a chunk of events (full-sensor coordinates, time order) and returns the
    /// estimates it made final. `horizon_us`: every event with `t <= horizon_us` has arrived.
    #[pyo3(signature = (events, horizon_us = None))]
    fn push<'py>(
        &self,
        py: Python<'py>,
        events: PyReadonlyArray1<'py, u8>,
        horizon_us: Option<i64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let arrival = Instant::now();
        let events = events.as_slice().map_err(error::value)?;
        let out = py.detach(|| {
            let events = records::decode_events(events)?;
            self.run(|est, emit| {
                est.process(&events, horizon_us, arrival, &mut |e| emit(e))
                    .map_err(error::value)
            })
        })?;
        Layout::Estimate.to_numpy(py, out)
    }

    /// Ends the stream: the estimates up to the last event's time.
    fn finish<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let arrival = Instant::now();
        let out = py.detach(|| {
            self.run(|est, emit| est.finish(arrival, &mut |e| emit(e)).map_err(error::value))
        })?;
        Layout::Estimate.to_numpy(py, out)
    }

    /// Events received, events inside the crop, and events skipped as out of order.
    #[getter]
    fn counters(&self) -> PyResult<(u64, u64, u64)> {
        let inner = self
            .inner
            .lock()
            .map_err(|_| error::value("the estimator failed in another thread"))?;
        let c = inner.counters();
        Ok((c.events, c.events_in_roi, c.events_out_of_order))
    }
}
