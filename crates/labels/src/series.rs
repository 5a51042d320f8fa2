//! A tilt and contact-angle trajectory and its CSV file: the labels evtac writes
//! (`labels/<trial>.csv`) and the simulator's ground truth (`truth/<trial>.csv`) share it.
//!
//! The file has a header and one row per sample, times strictly increasing:
//!
//! ```text
//! t_us,theta_deg,pitch_deg,roll_deg
//! 1000000,0,0,0
//! 1001250,0.0125,0.0118,0.0041
//! ```
//!
//! Numbers are written in Rust's shortest round-trip form, so reading a written file gives back
//! the same bits.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The header row of a labels or truth CSV.
pub const HEADER: &str = "t_us,theta_deg,pitch_deg,roll_deg";

/// What can go wrong reading or writing a labels or truth CSV.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SeriesError {
    /// The file could not be read or written.
    #[error("cannot access {path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's message.
        message: String,
    },
    /// The first line is not [`HEADER`].
    #[error("{path}:1: header must be `{HEADER}`, found `{found}`")]
    Header {
        /// The file.
        path: PathBuf,
        /// The first line as found.
        found: String,
    },
    /// A row does not have four cells.
    #[error("{path}:{line}: expected 4 comma-separated cells, found {found}")]
    Cells {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// Cells found.
        found: usize,
    },
    /// A cell is not a number (or not a finite one).
    #[error("{path}:{line}: column `{column}`: `{value}` is not a finite number")]
    Value {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The column's name.
        column: &'static str,
        /// The cell as found.
        value: String,
    },
    /// Times do not strictly increase.
    #[error("{path}:{line}: t_us {t_us} is not after the previous row's {previous_us}")]
    NotIncreasing {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The row's time.
        t_us: i64,
        /// The previous row's time.
        previous_us: i64,
    },
    /// The file has a header but no rows.
    #[error("{path}: no rows after the header")]
    Empty {
        /// The file.
        path: PathBuf,
    },
}

/// A trajectory of tilt and contact angles (degrees) at strictly increasing times (microseconds).
///
/// The four vectors have the same length, at least 1.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LabelSeries {
    /// Sample times in microseconds.
    pub t_us: Vec<i64>,
    /// Tilt magnitude `theta`.
    pub theta_deg: Vec<f64>,
    /// Contact pitch (see [`crate::geometry`]).
    pub pitch_deg: Vec<f64>,
    /// Contact roll (see [`crate::geometry`]).
    pub roll_deg: Vec<f64>,
}

impl LabelSeries {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t_us.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.t_us.is_empty()
    }

    /// `(pitch_deg, roll_deg)` at `t_us`, linearly interpolated between samples and held at the
    /// first and last values outside them; `(0, 0)` for an empty series.
    ///
    /// At the IMU's rate (about 1 ms apart) interpolating the angles rather than `theta` differs
    /// by less than 1e-7 deg.
    pub fn at(&self, t_us: i64) -> (f64, f64) {
        match self.locate(t_us) {
            Some((i, j, w)) => (
                lerp(self.pitch_deg[i], self.pitch_deg[j], w),
                lerp(self.roll_deg[i], self.roll_deg[j], w),
            ),
            None => (0.0, 0.0),
        }
    }

    /// `theta_deg` at `t_us`, interpolated as [`Self::at`].
    pub fn theta_at(&self, t_us: i64) -> f64 {
        match self.locate(t_us) {
            Some((i, j, w)) => lerp(self.theta_deg[i], self.theta_deg[j], w),
            None => 0.0,
        }
    }

    /// The two samples around `t_us` and the weight of the second.
    fn locate(&self, t_us: i64) -> Option<(usize, usize, f64)> {
        let n = self.t_us.len();
        if n == 0 {
            return None;
        }
        let j = self.t_us.partition_point(|&t| t < t_us);
        if j == 0 {
            return Some((0, 0, 0.0));
        }
        if j == n {
            return Some((n - 1, n - 1, 0.0));
        }
        let (t0, t1) = (self.t_us[j - 1], self.t_us[j]);
        Some((j - 1, j, (t_us - t0) as f64 / (t1 - t0) as f64))
    }

    /// The CSV text of this series (see the module docs).
    pub fn to_csv(&self) -> String {
        let mut out = String::with_capacity(64 * (self.len() + 1));
        out.push_str(HEADER);
        out.push('\n');
        for i in 0..self.len() {
            // Writing to a String cannot fail.
            let _ = writeln!(
                out,
                "{},{},{},{}",
                self.t_us[i], self.theta_deg[i], self.pitch_deg[i], self.roll_deg[i]
            );
        }
        out
    }

    /// Writes the CSV to `path`, creating its parent folder.
    pub fn write_csv(&self, path: impl AsRef<Path>) -> Result<(), SeriesError> {
        let path = path.as_ref();
        let io = |e: std::io::Error| SeriesError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent).map_err(io)?;
        }
        evtac_events::output::write_atomic(path, self.to_csv().as_bytes()).map_err(io)
    }

    /// Reads a labels or truth CSV from `path`.
    pub fn read_csv(path: impl AsRef<Path>) -> Result<Self, SeriesError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| SeriesError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        Self::parse(&text, path)
    }

    /// Parses CSV `text`; `path` only names the source in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, SeriesError> {
        let mut lines = text.lines();
        let header = lines.next().unwrap_or("").trim_end_matches('\r');
        if header.trim() != HEADER {
            return Err(SeriesError::Header {
                path: path.to_path_buf(),
                found: header.to_owned(),
            });
        }
        let mut s = Self::default();
        for (k, raw) in lines.enumerate() {
            let line = k + 2;
            let raw = raw.trim_end_matches('\r');
            if raw.trim().is_empty() {
                continue;
            }
            let cells: Vec<&str> = raw.split(',').map(str::trim).collect();
            if cells.len() != 4 {
                return Err(SeriesError::Cells {
                    path: path.to_path_buf(),
                    line,
                    found: cells.len(),
                });
            }
            let bad = |column: &'static str, value: &str| SeriesError::Value {
                path: path.to_path_buf(),
                line,
                column,
                value: value.to_owned(),
            };
            let t: i64 = cells[0].parse().map_err(|_| bad("t_us", cells[0]))?;
            let num = |i: usize, column: &'static str| {
                cells[i]
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| bad(column, cells[i]))
            };
            let (theta, pitch, roll) = (
                num(1, "theta_deg")?,
                num(2, "pitch_deg")?,
                num(3, "roll_deg")?,
            );
            if let Some(&previous_us) = s.t_us.last()
                && t <= previous_us
            {
                return Err(SeriesError::NotIncreasing {
                    path: path.to_path_buf(),
                    line,
                    t_us: t,
                    previous_us,
                });
            }
            s.t_us.push(t);
            s.theta_deg.push(theta);
            s.pitch_deg.push(pitch);
            s.roll_deg.push(roll);
        }
        if s.is_empty() {
            return Err(SeriesError::Empty {
                path: path.to_path_buf(),
            });
        }
        Ok(s)
    }
}

fn lerp(a: f64, b: f64, w: f64) -> f64 {
    a + w * (b - a)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> LabelSeries {
        LabelSeries {
            t_us: vec![0, 1_000, 3_000],
            theta_deg: vec![0.0, 1.0, 3.0],
            pitch_deg: vec![0.0, 0.1, 1.0 / 3.0],
            roll_deg: vec![-0.0, -2.5e-17, 7.25],
        }
    }

    #[test]
    fn interpolates_and_holds() {
        let s = sample();
        assert_eq!(s.at(-10), (0.0, 0.0));
        assert_eq!(s.at(1_000), (0.1, -2.5e-17));
        let (p, r) = s.at(2_000);
        assert!((p - (0.1 + 1.0 / 3.0) / 2.0).abs() < 1e-15);
        assert!((r - 3.625).abs() < 1e-12);
        assert_eq!(s.at(5_000), (1.0 / 3.0, 7.25));
        assert!((s.theta_at(500) - 0.5).abs() < 1e-15);
        assert_eq!(LabelSeries::default().at(5), (0.0, 0.0));
    }

    #[test]
    fn csv_round_trips_bit_for_bit() {
        let s = sample();
        let back = LabelSeries::parse(&s.to_csv(), Path::new("x.csv")).unwrap();
        assert_eq!(back, s);
    }

    #[test]
    fn csv_errors_name_file_line_and_column() {
        let p = Path::new("labels/t1.csv");
        let err = LabelSeries::parse("t,theta\n", p).unwrap_err();
        assert!(matches!(err, SeriesError::Header { .. }));
        let err = LabelSeries::parse(&format!("{HEADER}\n0,1,2,3\n5,1,nan,3\n"), p).unwrap_err();
        assert_eq!(
            err.to_string(),
            "labels/t1.csv:3: column `pitch_deg`: `nan` is not a finite number"
        );
        let err = LabelSeries::parse(&format!("{HEADER}\n5,1,2,3\n5,1,2,3\n"), p).unwrap_err();
        assert!(matches!(err, SeriesError::NotIncreasing { line: 3, .. }));
        let err = LabelSeries::parse(&format!("{HEADER}\n5,1,2\n"), p).unwrap_err();
        assert!(matches!(err, SeriesError::Cells { found: 3, .. }));
        let err = LabelSeries::parse(&format!("{HEADER}\n"), p).unwrap_err();
        assert!(matches!(err, SeriesError::Empty { .. }));
    }
}

#[cfg(test)]
mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn csv_round_trips(rows in prop::collection::vec((1i64..1_000_000, any::<f64>(), any::<f64>(), any::<f64>()), 1..40)) {
            let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
            let mut t = i64::MIN / 2;
            let mut s = LabelSeries::default();
            for (dt, a, b, c) in rows {
                t += dt;
                s.t_us.push(t);
                s.theta_deg.push(finite(a));
                s.pitch_deg.push(finite(b));
                s.roll_deg.push(finite(c));
            }
            let back = LabelSeries::parse(&s.to_csv(), Path::new("p.csv")).unwrap();
            prop_assert_eq!(back, s);
        }
    }
}
