//! Train/validation/test splits of a dataset's trials (70:15:15), seeded, with balanced marginal
//! distributions of speed, depth and direction, stored as `splits.json` in the dataset folder.
//!
//! The paper picks validation and test trials "to maintain approximately balanced marginal
//! distributions of speed, depth, and direction". We assign trials greedily in a seeded random
//! order: each trial goes to the split that is furthest below its target share for the trial's
//! speed, depth and direction (and overall size), so every marginal ends within a trial or two of
//! 70:15:15. A plain random split leaves marginals off by several trials at these sizes.

use evtac_events::IoError;
use evtac_events::layout::SPLITS_FILE;
use evtac_events::output::write_atomic;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::path::Path;
use std::path::PathBuf;

/// Shares of the train, validation and test splits.
pub const RATIOS: [f64; 3] = [0.70, 0.15, 0.15];

/// Errors reading or writing splits.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The splits file could not be read or written.
    #[error(transparent)]
    Io(#[from] IoError),
    /// The splits file is not valid JSON of the expected shape.
    #[error("{}: not a splits file: {source}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: serde_json::Error,
    },
    /// The splits file names a trial the manifest does not have (or misses one it has).
    #[error("{}: splits do not match the manifest: {detail}", path.display())]
    Mismatch {
        /// The file.
        path: PathBuf,
        /// What differs.
        detail: String,
    },
}

/// One of the three splits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Split {
    /// Training trials.
    Train,
    /// Validation trials (checkpoint and hyperparameter selection).
    Val,
    /// Test trials (reported numbers).
    Test,
}

impl Split {
    /// All splits in order.
    pub const ALL: [Split; 3] = [Split::Train, Split::Val, Split::Test];

    /// The name used on the command line and in files.
    pub fn as_str(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Val => "val",
            Split::Test => "test",
        }
    }
}

impl std::str::FromStr for Split {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "train" => Ok(Split::Train),
            "val" | "validation" => Ok(Split::Val),
            "test" => Ok(Split::Test),
            _ => Err(format!("unknown split `{s}` (train, val or test)")),
        }
    }
}

/// The conditions of one trial that the split balances.
#[derive(Debug, Clone, PartialEq)]
pub struct Stratum {
    /// Trial name.
    pub trial: String,
    /// Rolling speed in deg/s.
    pub speed_deg_s: f64,
    /// Indentation depth in mm.
    pub depth_mm: f64,
    /// Tilt direction in degrees.
    pub direction_deg: f64,
}

impl Stratum {
    /// Every trial's conditions in `manifest`, in its order.
    pub fn of_manifest(manifest: &evtac_events::manifest::Manifest) -> Vec<Stratum> {
        manifest
            .trials
            .iter()
            .map(|t| Stratum {
                trial: t.trial.clone(),
                speed_deg_s: t.speed_deg_s,
                depth_mm: t.depth_mm,
                direction_deg: t.direction_deg,
            })
            .collect()
    }

    /// The most trials any one condition (speed, depth and direction) has among `trials`: the
    /// repeats per condition.
    pub fn most_repeats(trials: &[Stratum]) -> usize {
        let mut counts: HashMap<[String; 3], usize> = HashMap::new();
        for t in trials {
            *counts.entry(t.keys()).or_default() += 1;
        }
        counts.into_values().max().unwrap_or(0)
    }

    fn keys(&self) -> [String; 3] {
        [
            format!("speed={}", self.speed_deg_s),
            format!("depth={}", self.depth_mm),
            format!("direction={}", self.direction_deg),
        ]
    }
}

/// Trial names per split, as stored in `splits.json`.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Splits {
    /// The seed the splits were made with.
    pub seed: u64,
    /// Training trials.
    pub train: Vec<String>,
    /// Validation trials.
    pub val: Vec<String>,
    /// Test trials.
    pub test: Vec<String>,
}

impl Splits {
    /// Splits `trials` 70:15:15 with balanced marginals of speed, depth and direction, seeded.
    /// Each split keeps the manifest's order of trials.
    pub fn make(trials: &[Stratum], seed: u64) -> Splits {
        let n = trials.len();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        // Target sizes: round val and test, the rest trains (so tiny datasets still validate).
        let val = ((n as f64 * RATIOS[1]).round() as usize).max(usize::from(n >= 3));
        let test = ((n as f64 * RATIOS[2]).round() as usize).max(usize::from(n >= 3));
        let sizes = [n.saturating_sub(val + test), val, test];
        let mut value_counts: HashMap<String, usize> = HashMap::new();
        for t in trials {
            for k in t.keys() {
                *value_counts.entry(k).or_default() += 1;
            }
        }
        let mut order: Vec<usize> = (0..n).collect();
        order.shuffle(&mut rng);
        let mut assigned: Vec<HashMap<String, usize>> = vec![HashMap::new(); 3];
        let mut filled = [0usize; 3];
        let mut split_of = vec![0usize; n];
        for &i in &order {
            let keys = trials[i].keys();
            let mut best: Option<(f64, usize)> = None;
            for s in 0..3 {
                if filled[s] >= sizes[s] {
                    continue;
                }
                let share = sizes[s] as f64 / n as f64;
                // Deficit of this split for each of the trial's values, in trials.
                let need: f64 = keys
                    .iter()
                    .map(|k| {
                        value_counts[k] as f64 * share
                            - assigned[s].get(k).copied().unwrap_or(0) as f64
                    })
                    .sum::<f64>()
                    + (sizes[s] - filled[s]) as f64 / n as f64;
                // A tiny random jitter breaks ties without favouring a split.
                let score = need + rng.random::<f64>() * 1e-6;
                if best.is_none_or(|(b, _)| score > b) {
                    best = Some((score, s));
                }
            }
            let s = best.map_or(0, |(_, s)| s);
            filled[s] += 1;
            split_of[i] = s;
            for k in keys {
                *assigned[s].entry(k).or_default() += 1;
            }
        }
        let mut out = Splits {
            seed,
            ..Splits::default()
        };
        for (i, t) in trials.iter().enumerate() {
            let list = match split_of[i] {
                0 => &mut out.train,
                1 => &mut out.val,
                _ => &mut out.test,
            };
            list.push(t.trial.clone());
        }
        out
    }

    /// Splits like [`Splits::make`], but with every trial of one condition (speed, depth and
    /// direction) in the same split, so a condition's repeats never fall on both sides: the
    /// conditions are split 70:15:15 with balanced marginals, and each trial follows its own.
    /// Each split keeps the manifest's order of trials.
    pub fn make_grouped(trials: &[Stratum], seed: u64) -> Splits {
        let mut conditions: Vec<Stratum> = Vec::new();
        let mut index: HashMap<[String; 3], usize> = HashMap::new();
        let condition_of: Vec<usize> = trials
            .iter()
            .map(|t| {
                *index.entry(t.keys()).or_insert_with(|| {
                    conditions.push(t.clone());
                    conditions.len() - 1
                })
            })
            .collect();
        let by_condition = Splits::make(&conditions, seed);
        let split_of_condition: HashMap<&str, Split> = Split::ALL
            .into_iter()
            .flat_map(|split| {
                by_condition
                    .get(split)
                    .iter()
                    .map(move |name| (name.as_str(), split))
            })
            .collect();
        let mut out = Splits {
            seed,
            ..Splits::default()
        };
        for (t, &c) in trials.iter().zip(&condition_of) {
            let list = match split_of_condition[conditions[c].trial.as_str()] {
                Split::Train => &mut out.train,
                Split::Val => &mut out.val,
                Split::Test => &mut out.test,
            };
            list.push(t.trial.clone());
        }
        out
    }

    /// The trials of `split`.
    pub fn get(&self, split: Split) -> &[String] {
        match split {
            Split::Train => &self.train,
            Split::Val => &self.val,
            Split::Test => &self.test,
        }
    }

    /// Reads `DATASET/splits.json`; `None` when the file does not exist.
    pub fn read(dataset_dir: &Path) -> Result<Option<Splits>, Error> {
        let path = dataset_dir.join(SPLITS_FILE);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(source) => return Err(IoError::at(&path)(source).into()),
        };
        serde_json::from_str(&text)
            .map(Some)
            .map_err(|source| Error::Json { path, source })
    }

    /// Writes `DATASET/splits.json` (pretty JSON).
    pub fn write(&self, dataset_dir: &Path) -> Result<(), Error> {
        let path = dataset_dir.join(SPLITS_FILE);
        let text = serde_json::to_string_pretty(self).map_err(|source| Error::Json {
            path: path.clone(),
            source,
        })?;
        // The dataset's folder exists: the dataset was opened from it.
        write_atomic(&path, text.as_bytes()).map_err(IoError::at(&path))?;
        Ok(())
    }

    /// Checks that the splits cover exactly the manifest's `trials`, each once.
    pub fn check(&self, trials: &[String], dataset_dir: &Path) -> Result<(), Error> {
        let mut seen: HashMap<&str, usize> = HashMap::new();
        for t in self.train.iter().chain(&self.val).chain(&self.test) {
            *seen.entry(t.as_str()).or_default() += 1;
        }
        let mismatch = |detail: String| Error::Mismatch {
            path: dataset_dir.join(SPLITS_FILE),
            detail,
        };
        if let Some((t, _)) = seen.iter().find(|(_, c)| **c > 1) {
            return Err(mismatch(format!("trial `{t}` is in more than one split")));
        }
        for t in trials {
            if !seen.contains_key(t.as_str()) {
                return Err(mismatch(format!("trial `{t}` is in no split")));
            }
        }
        if seen.len() != trials.len() {
            return Err(mismatch(format!(
                "{} trials in the splits, {} in the manifest",
                seen.len(),
                trials.len()
            )));
        }
        Ok(())
    }

    /// Reads the splits, or makes and writes them (seeded) when the file is missing.
    pub fn read_or_make(
        dataset_dir: &Path,
        trials: &[Stratum],
        seed: u64,
    ) -> Result<Splits, Error> {
        let names: Vec<String> = trials.iter().map(|t| t.trial.clone()).collect();
        if let Some(s) = Splits::read(dataset_dir)? {
            s.check(&names, dataset_dir)?;
            return Ok(s);
        }
        let s = Splits::make(trials, seed);
        s.write(dataset_dir)?;
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper_grid() -> Vec<Stratum> {
        let mut v = Vec::new();
        for d in 0..20 {
            for s in 1..=5 {
                for depth in 0..5 {
                    for rep in 0..2 {
                        v.push(Stratum {
                            trial: format!("d{d}-s{s}-z{depth}-r{rep}"),
                            speed_deg_s: 2.0 * s as f64,
                            depth_mm: 1.0 + 0.5 * depth as f64,
                            direction_deg: 18.0 * d as f64,
                        });
                    }
                }
            }
        }
        v
    }

    #[test]
    fn grouped_splits_keep_each_conditions_repeats_on_one_side() {
        let trials = paper_grid();
        let s = Splits::make_grouped(&trials, 7);
        assert_eq!((s.train.len(), s.val.len(), s.test.len()), (700, 150, 150));
        let names: Vec<String> = trials.iter().map(|t| t.trial.clone()).collect();
        s.check(&names, Path::new(".")).unwrap();
        let split_of: HashMap<&str, Split> = Split::ALL
            .into_iter()
            .flat_map(|sp| s.get(sp).iter().map(move |n| (n.as_str(), sp)))
            .collect();
        // The grid's two repeats of a condition are neighbours: always the same split.
        for pair in trials.chunks(2) {
            assert_eq!(
                split_of[pair[0].trial.as_str()],
                split_of[pair[1].trial.as_str()]
            );
        }
        // The paper's split puts some conditions' repeats on both sides.
        let paper = Splits::make(&trials, 7);
        let paper_of: HashMap<&str, Split> = Split::ALL
            .into_iter()
            .flat_map(|sp| paper.get(sp).iter().map(move |n| (n.as_str(), sp)))
            .collect();
        let straddling = trials
            .chunks(2)
            .filter(|p| paper_of[p[0].trial.as_str()] != paper_of[p[1].trial.as_str()])
            .count();
        assert!(
            straddling > 100,
            "{straddling} conditions straddle the paper's split"
        );
        assert_eq!(Stratum::most_repeats(&trials), 2);
        // One trial per condition: the same as the plain split.
        let single: Vec<Stratum> = trials.iter().step_by(2).cloned().collect();
        assert_eq!(Splits::make_grouped(&single, 3), Splits::make(&single, 3));
        assert_eq!(Stratum::most_repeats(&single), 1);
        assert_eq!(Stratum::most_repeats(&[]), 0);
    }

    #[test]
    fn splits_are_70_15_15_and_marginals_balanced() {
        let trials = paper_grid();
        let s = Splits::make(&trials, 7);
        assert_eq!((s.train.len(), s.val.len(), s.test.len()), (700, 150, 150));
        let names: Vec<String> = trials.iter().map(|t| t.trial.clone()).collect();
        s.check(&names, Path::new(".")).unwrap();
        let by_name: HashMap<&str, &Stratum> =
            trials.iter().map(|t| (t.trial.as_str(), t)).collect();
        for (split, share) in Split::ALL.into_iter().zip(RATIOS) {
            let mut counts: HashMap<String, usize> = HashMap::new();
            for t in s.get(split) {
                for k in by_name[t.as_str()].keys() {
                    *counts.entry(k).or_default() += 1;
                }
            }
            let mut totals: HashMap<String, usize> = HashMap::new();
            for t in &trials {
                for k in t.keys() {
                    *totals.entry(k).or_default() += 1;
                }
            }
            for (k, total) in totals {
                let expected = total as f64 * share;
                let got = counts.get(&k).copied().unwrap_or(0) as f64;
                // 50 trials per direction: 7.5 expected in val/test; allow one trial off.
                assert!(
                    (got - expected).abs() <= 1.5,
                    "{split:?} {k}: {got} trials, expected {expected}"
                );
            }
        }
    }

    #[test]
    fn same_seed_same_splits_other_seed_other_splits() {
        let trials = paper_grid();
        assert_eq!(Splits::make(&trials, 3), Splits::make(&trials, 3));
        assert_ne!(Splits::make(&trials, 3).test, Splits::make(&trials, 4).test);
    }

    #[test]
    fn round_trip_and_mismatch() {
        let dir = tempfile::tempdir().unwrap();
        let trials = paper_grid();
        let s = Splits::read_or_make(dir.path(), &trials, 1).unwrap();
        assert_eq!(Splits::read(dir.path()).unwrap(), Some(s));
        let fewer = &trials[..10];
        assert!(matches!(
            Splits::read_or_make(dir.path(), fewer, 1),
            Err(Error::Mismatch { .. })
        ));
    }

    #[test]
    fn tiny_datasets_still_have_every_split() {
        let trials = &paper_grid()[..6];
        let s = Splits::make(trials, 0);
        assert!(!s.train.is_empty() && !s.val.is_empty() && !s.test.is_empty());
    }
}
