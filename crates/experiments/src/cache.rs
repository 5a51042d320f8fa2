//! Feature caches: the pooled features of every (trial, representation config) at the sample
//! times, computed once, in one pass over each trial's events for many configs at a time, and
//! stored as NPY under `DATASET/cache/`.
//!
//! Layout (one folder per sampling scheme, one per config and mask inside it):
//!
//! ```text
//! cache/m50-s0/samples-<labels id>/<trial>.csv     t_us,phase,pitch_deg,roll_deg (labels at samples,
//!                                                  per calibration and label settings)
//! cache/m50-s0/<cache_key>-<mask id>/config.json   the config and mask identity (for people)
//! cache/m50-s0/<cache_key>-<mask id>/<trial>.npy   N x 900 float32, one row per sample
//!                                                   (N x 1800 for stacked and late: two frames)
//! ```
//!
//! A file exists only once complete (written to a temporary name, then renamed), so an
//! interrupted run resumes with the files it finished. Trials run in parallel (rayon).

use crate::dataset::{self, Dataset};
use crate::sampling::{Phase, SampleTime, Sampling};
use evtac_events::IoError;
use evtac_events::layout::CACHE_DIR;
use evtac_events::manifest::TrialMeta;
use evtac_events::output::write_atomic;
use evtac_learn::FeatureSet;
use evtac_repr::CROP;
use evtac_repr::{FeatureExtractor, FeatureProvenance, Mask, ReprConfig};
use ndarray::Array2;
use rayon::prelude::*;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Number of features per pooled frame (30 x 30 cells of the 240 x 240 crop); a sample has
/// [`ReprConfig::frames`] of them side by side.
pub const FEATURES: usize = 900;

/// Features per sample of `config`.
pub fn width(config: &ReprConfig) -> usize {
    config.frames() * FEATURES
}

/// Errors computing or reading cached features.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The dataset could not be read (events, labels, mask).
    #[error(transparent)]
    Dataset(#[from] dataset::Error),
    /// The representation could not be computed.
    #[error("trial `{trial}`: representation: {source}")]
    Repr {
        /// The trial.
        trial: String,
        /// The cause.
        source: evtac_repr::ReprError,
    },
    /// A cache file could not be written or read.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A cache file does not have the expected shape.
    #[error("{path}: expected {expected_rows} x {expected_cols} features, found {rows} x {cols}")]
    Shape {
        /// The file.
        path: PathBuf,
        /// Rows expected (samples of the trial).
        expected_rows: usize,
        /// Columns expected (features per sample).
        expected_cols: usize,
        /// Rows found.
        rows: usize,
        /// Columns found.
        cols: usize,
    },
    /// A samples file is malformed.
    #[error("{path}:{line}: {message}")]
    Samples {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The samples left after filtering by phase form no set.
    #[error("{what}: {source}")]
    Set {
        /// Which set.
        what: String,
        /// The cause.
        source: evtac_learn::data::Error,
    },
}

fn io<E: Into<evtac_events::Cause>>(path: &Path) -> impl Fn(E) -> Error + '_ {
    move |e| Error::Io(IoError::at(path)(e))
}

/// One sample of a loaded set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleMeta {
    /// Index of the trial in the list the set was loaded from.
    pub trial: usize,
    /// Sample time in microseconds.
    pub t_us: i64,
    /// Phase of the sample.
    pub phase: Phase,
}

/// Features and labels of a list of trials plus per-sample meta, in trial then time order.
#[derive(Debug, Clone, Default)]
pub struct LoadedSet {
    /// Features (N x 900, or N x 1800 for two frames) and labels (N x 2, pitch then roll,
    /// degrees).
    pub set: FeatureSet,
    /// Per-sample meta (N).
    pub samples: Vec<SampleMeta>,
}

/// What [`FeatureCache::ensure`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CacheStats {
    /// (trial, config) pairs computed now.
    pub computed: usize,
    /// (trial, config) pairs found in the cache.
    pub reused: usize,
}

/// The feature cache of one dataset.
#[derive(Debug)]
pub struct FeatureCache<'a> {
    ds: &'a Dataset,
    no_contact: Option<crate::dataset::NoContact>,
    masks: std::sync::Mutex<HashMap<String, Option<Mask>>>,
}

/// Labels and phase at each sample time of a trial.
#[derive(Debug, Clone, PartialEq)]
pub struct TrialSamples {
    /// Sample times and phases.
    pub times: Vec<SampleTime>,
    /// (pitch, roll) in degrees at each time.
    pub labels: Vec<[f32; 2]>,
}

impl<'a> FeatureCache<'a> {
    /// The cache of `ds` (reads its no-contact recording once, for the masks).
    pub fn new(ds: &'a Dataset) -> Result<Self, Error> {
        Ok(Self {
            ds,
            no_contact: ds.no_contact()?,
            masks: std::sync::Mutex::new(HashMap::new()),
        })
    }

    /// The dataset.
    pub fn dataset(&self) -> &Dataset {
        self.ds
    }

    /// The no-contact mask for `config` (memoized).
    pub fn mask(&self, config: &ReprConfig) -> Result<Option<Mask>, Error> {
        let key = config.cache_key();
        if let Ok(map) = self.masks.lock()
            && let Some(m) = map.get(&key)
        {
            return Ok(m.clone());
        }
        let mask = self.ds.mask_for(config, self.no_contact.as_ref())?;
        if let Ok(mut map) = self.masks.lock() {
            map.insert(key, mask.clone());
        }
        Ok(mask)
    }

    /// What `config`'s features from this dataset are made of (representation, crop, mask and
    /// the dataset's filters), to compare with a model's.
    pub fn provenance(&self, config: &ReprConfig) -> Result<FeatureProvenance, Error> {
        let filters = self
            .ds
            .inputs
            .filters
            .iter()
            .map(|f| f.to_string())
            .collect();
        Ok(FeatureProvenance::new(config, CROP, self.mask(config)?.as_ref()).with_filters(filters))
    }

    fn sampling_dir(&self, sampling: Sampling) -> PathBuf {
        self.ds.dir.join(CACHE_DIR).join(sampling.key())
    }

    /// The folder of `config`'s features under `sampling`.
    pub fn config_dir(&self, config: &ReprConfig, sampling: Sampling) -> Result<PathBuf, Error> {
        let mask = self.mask(config)?;
        let mut name = format!("{}-{}", config.cache_key(), dataset::mask_id(mask.as_ref()));
        if let Some(filters) = dataset::filters_id(&self.ds.inputs.filters) {
            name = format!("{name}-{filters}");
        }
        Ok(self.sampling_dir(sampling).join(name))
    }

    /// The labels at `trial`'s samples: keyed by what the labels were computed with (the
    /// calibration and label settings, [`Dataset::labels_id`]), so that opening the dataset
    /// with another calibration never reuses them.
    fn samples_path(&self, trial: &str, sampling: Sampling) -> PathBuf {
        self.sampling_dir(sampling)
            .join(format!("samples-{}", self.ds.labels_id()))
            .join(format!("{trial}.csv"))
    }

    /// The sample times and labels of `meta` (cached as CSV; labels computed when missing).
    pub fn samples(&self, meta: &TrialMeta, sampling: Sampling) -> Result<TrialSamples, Error> {
        let path = self.samples_path(&meta.trial, sampling);
        if path.is_file() {
            return read_samples(&path);
        }
        let times = self.ds.sample_times(meta, sampling);
        let series = self.ds.labels(meta)?;
        let labels: Vec<[f32; 2]> = times
            .iter()
            .map(|s| {
                let (p, r) = series.at(s.t_us);
                [p as f32, r as f32]
            })
            .collect();
        let mut text = String::from("t_us,phase,pitch_deg,roll_deg\n");
        for (s, l) in times.iter().zip(&labels) {
            let _ = writeln!(text, "{},{},{},{}", s.t_us, s.phase.as_str(), l[0], l[1]);
        }
        crate::jobs::create_parent(&path)
            .and_then(|()| write_atomic(&path, text.as_bytes()))
            .map_err(io(&path))?;
        Ok(TrialSamples { times, labels })
    }

    /// Makes sure the features of every `config` exist for every trial: trials in parallel, each
    /// read once and run through one [`FeatureExtractor`] for all its missing configs.
    /// `progress` is called once per trial, with `true` when every feature the trial needed was
    /// cached already (no time spent: an ETA must not learn its pace from it).
    pub fn ensure(
        &self,
        trials: &[&TrialMeta],
        configs: &[ReprConfig],
        sampling: Sampling,
        progress: &(dyn Fn(bool) + Sync),
    ) -> Result<CacheStats, Error> {
        let dirs: Vec<PathBuf> = configs
            .iter()
            .map(|c| self.config_dir(c, sampling))
            .collect::<Result<_, _>>()?;
        let masks: Vec<Option<Mask>> = configs
            .iter()
            .map(|c| self.mask(c))
            .collect::<Result<_, _>>()?;
        for (dir, (config, mask)) in dirs.iter().zip(configs.iter().zip(&masks)) {
            let meta = dir.join("config.json");
            if !meta.is_file() {
                let mut json = serde_json::json!({
                    "representation": config,
                    "mask": dataset::mask_id(mask.as_ref()),
                    "sampling": sampling,
                });
                if !self.ds.inputs.filters.is_empty() {
                    json["filters"] = serde_json::json!(self.ds.inputs.filters);
                }
                crate::jobs::create_parent(&meta)
                    .and_then(|()| write_atomic(&meta, json.to_string().as_bytes()))
                    .map_err(io(&meta))?;
            }
        }
        let computed = AtomicUsize::new(0);
        let reused = AtomicUsize::new(0);
        trials
            .par_iter()
            .try_for_each(|meta| -> Result<(), Error> {
                // Configs that share a folder (stacked and late: the same features) once.
                let missing: Vec<usize> = (0..configs.len())
                    .filter(|&i| !dirs[..i].contains(&dirs[i]))
                    .filter(|&i| !dirs[i].join(format!("{}.npy", meta.trial)).is_file())
                    .collect();
                reused.fetch_add(configs.len() - missing.len(), Ordering::Relaxed);
                let samples = self.samples(meta, sampling)?;
                if !missing.is_empty() {
                    self.compute(meta, &samples, configs, &masks, &dirs, &missing)?;
                    computed.fetch_add(missing.len(), Ordering::Relaxed);
                }
                progress(missing.is_empty());
                Ok(())
            })?;
        Ok(CacheStats {
            computed: computed.into_inner(),
            reused: reused.into_inner(),
        })
    }

    fn compute(
        &self,
        meta: &TrialMeta,
        samples: &TrialSamples,
        configs: &[ReprConfig],
        masks: &[Option<Mask>],
        dirs: &[PathBuf],
        which: &[usize],
    ) -> Result<(), Error> {
        let events = self.ds.events(meta)?;
        let sel: Vec<ReprConfig> = which.iter().map(|&i| configs[i]).collect();
        let sel_masks: Vec<Option<&Mask>> = which.iter().map(|&i| masks[i].as_ref()).collect();
        let repr = |source| Error::Repr {
            trial: meta.trial.clone(),
            source,
        };
        let mut fx = FeatureExtractor::new_with_masks(&sel, CROP, &sel_masks).map_err(repr)?;
        let times: Vec<i64> = samples.times.iter().map(|s| s.t_us).collect();
        let mut out: Vec<Vec<f32>> = sel
            .iter()
            .map(|c| Vec::with_capacity(times.len() * width(c)))
            .collect();
        fx.run(&events, &times, |_, fx| {
            for (i, o) in out.iter_mut().enumerate() {
                o.extend_from_slice(fx.features(i));
            }
        })
        .map_err(repr)?;
        for (k, &i) in which.iter().enumerate() {
            let path = dirs[i].join(format!("{}.npy", meta.trial));
            let values = std::mem::take(&mut out[k]);
            let array = Array2::from_shape_vec((times.len(), width(&configs[i])), values)
                .map_err(io(&path))?;
            std::fs::create_dir_all(&dirs[i]).map_err(io(&dirs[i]))?;
            let tmp = crate::jobs::tmp_path(&path);
            ndarray_npy::write_npy(&tmp, &array).map_err(io(&tmp))?;
            std::fs::rename(&tmp, &path).map_err(io(&path))?;
        }
        Ok(())
    }

    /// Loads the cached features of `trials` for `config` (computing what is missing), keeping
    /// the samples whose phase is in `phases`.
    pub fn load(
        &self,
        trials: &[&TrialMeta],
        config: &ReprConfig,
        sampling: Sampling,
        phases: &[Phase],
    ) -> Result<LoadedSet, Error> {
        self.ensure(trials, std::slice::from_ref(config), sampling, &|_| {})?;
        let dir = self.config_dir(config, sampling)?;
        let parts: Vec<(Vec<f32>, Vec<f32>, Vec<SampleMeta>)> = trials
            .par_iter()
            .enumerate()
            .map(|(ti, meta)| -> Result<_, Error> {
                let samples = self.samples(meta, sampling)?;
                let path = dir.join(format!("{}.npy", meta.trial));
                let array: Array2<f32> = ndarray_npy::read_npy(&path).map_err(io(&path))?;
                let (rows, cols) = array.dim();
                if rows != samples.times.len() || cols != width(config) {
                    return Err(Error::Shape {
                        path,
                        expected_rows: samples.times.len(),
                        expected_cols: width(config),
                        rows,
                        cols,
                    });
                }
                let (mut f, mut l, mut m) = (
                    Vec::with_capacity(rows * cols),
                    Vec::with_capacity(rows * 2),
                    Vec::with_capacity(rows),
                );
                for (k, row) in array.outer_iter().enumerate() {
                    let s = samples.times[k];
                    if !phases.contains(&s.phase) {
                        continue;
                    }
                    f.extend(row.iter().copied());
                    l.extend_from_slice(&samples.labels[k]);
                    m.push(SampleMeta {
                        trial: ti,
                        t_us: s.t_us,
                        phase: s.phase,
                    });
                }
                Ok((f, l, m))
            })
            .collect::<Result<_, _>>()?;
        let mut out = LoadedSet {
            set: FeatureSet::empty(width(config)),
            samples: Vec::new(),
        };
        // Sized once: growing a paper-scale set (126 MB of features) by doubling copied it
        // and faulted in fresh pages several times over (perf: a fifth of a short run).
        out.set
            .features
            .reserve_exact(parts.iter().map(|p| p.0.len()).sum());
        out.set
            .labels
            .reserve_exact(parts.iter().map(|p| p.1.len()).sum());
        out.samples
            .reserve_exact(parts.iter().map(|p| p.2.len()).sum());
        for (f, l, m) in parts {
            out.set.features.extend(f);
            out.set.labels.extend(l);
            out.samples.extend(m);
        }
        Ok(out)
    }
}

fn read_samples(path: &Path) -> Result<TrialSamples, Error> {
    let text = std::fs::read_to_string(path).map_err(io(path))?;
    let bad = |line: usize, message: String| Error::Samples {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut out = TrialSamples {
        times: Vec::new(),
        labels: Vec::new(),
    };
    for (i, line) in text.lines().enumerate().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != 4 {
            return Err(bad(
                i + 1,
                format!("expected 4 cells, found {}", cells.len()),
            ));
        }
        let t_us = cells[0]
            .parse::<i64>()
            .map_err(|_| bad(i + 1, format!("t_us `{}` is not an integer", cells[0])))?;
        let phase = Phase::parse(cells[1])
            .ok_or_else(|| bad(i + 1, format!("phase `{}` is not motion or stop", cells[1])))?;
        let num = |s: &str| {
            s.parse::<f32>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| bad(i + 1, format!("`{s}` is not a finite number")))
        };
        out.times.push(SampleTime { t_us, phase });
        out.labels.push([num(cells[2])?, num(cells[3])?]);
    }
    Ok(out)
}
