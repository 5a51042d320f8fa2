//! Filters as the command line names them: `NAME=VALUE[,VALUE...]` SPECs, parsed into a
//! [`FilterSpec`] and built for a sensor into a [`Filter`].
//!
//! | SPEC | meaning |
//! | --- | --- |
//! | `background-activity=DURATION` | keep events with a neighbour's event less than DURATION before |
//! | `fast-decay[=HALF_LIFE[,SUBDIVISION[,THRESHOLD]]]` | keep events in cells with a decaying count above THRESHOLD (defaults 10ms, 4, 6) |
//! | `k-noise=DURATION` | keep events supported by the neighbouring columns' and rows' last events |
//! | `polarity=on\|off` | keep one polarity |
//! | `region=X,Y,W,H` | keep the rectangle `X <= x < X+W`, `Y <= y < Y+H` |
//! | `refractory=DURATION` | remove events less than DURATION after their pixel's previous one |
//! | `circle=CX,CY,R` | keep the disc `(x-CX)^2 + (y-CY)^2 <= R^2` |
//! | `mask=FILE` | keep the pixels a uint8 `H x W` mask (NPY or 8-bit greyscale PNG) marks non-zero |
//! | `hot-pixels=FILE` | remove the pixels such a mask marks non-zero (a mask of hot pixels) |
//! | `hot-pixels=auto` | remove the hot pixels learned from the recording being filtered |
//!
//! DURATIONs take a unit: `us`, `ms` or `s` (`500us`, `2ms`, `1.5ms`). A SPEC written back
//! ([`std::fmt::Display`]) parses to the same filter. `hot-pixels=auto` is the one SPEC that needs
//! more than the sensor to be built: the hot pixels of the recording it filters, which the caller
//! learns (as `evtac stats` measures them, `evtac_import::sensor_stats::hot_pixels`) and hands to
//! [`FilterSpec::build_with`]. A mask file named `auto` is written `hot-pixels=./auto`.

use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

use evtac_events::Resolution;

use crate::duration::{Micros, ParseDurationError};
use crate::{
    BackgroundActivity, Circle, FastDecay, Filter, HotPixels, KNoise, Mask, PolarityFilter,
    Refractory, Region, Rule, mask_file,
};

/// The filters' names, as SPECs begin.
pub const NAMES: [&str; 9] = [
    "background-activity",
    "fast-decay",
    "k-noise",
    "polarity",
    "region",
    "refractory",
    "circle",
    "mask",
    "hot-pixels",
];

/// One filter and its settings, as a SPEC gives them.
#[derive(Debug, Clone, PartialEq)]
pub enum FilterSpec {
    /// `background-activity=DURATION`: [`BackgroundActivity`].
    BackgroundActivity {
        /// How long an event supports its neighbours.
        duration: Micros,
    },
    /// `fast-decay=HALF_LIFE,SUBDIVISION,THRESHOLD`: [`FastDecay`].
    FastDecay {
        /// The time a cell's count takes to halve.
        half_life: Micros,
        /// A cell's side, in pixels (at least 1).
        subdivision: u16,
        /// The count a cell must exceed for its events to be kept.
        threshold: f32,
    },
    /// `k-noise=DURATION`: [`KNoise`].
    KNoise {
        /// How long an event supports its neighbours (inclusive).
        duration: Micros,
    },
    /// `polarity=on|off`: [`PolarityFilter`].
    Polarity {
        /// `true` keeps ON events, `false` OFF events.
        on: bool,
    },
    /// `region=X,Y,W,H`: [`Region`].
    Region {
        /// Left column.
        x: u16,
        /// Top row.
        y: u16,
        /// Columns (at least 1).
        width: u16,
        /// Rows (at least 1).
        height: u16,
    },
    /// `refractory=DURATION`: [`Refractory`].
    Refractory {
        /// The period after each event of a pixel in which its next events are removed.
        period: Micros,
    },
    /// `circle=CX,CY,R`: [`Circle`].
    Circle {
        /// Centre column.
        cx: f64,
        /// Centre row.
        cy: f64,
        /// Radius, in pixels (positive).
        radius: f64,
    },
    /// `mask=FILE`: [`Mask`], keeping the pixels the file marks.
    Mask {
        /// The mask: a uint8 `H x W` NPY array or an 8-bit greyscale PNG.
        path: PathBuf,
    },
    /// `hot-pixels=FILE`: [`Mask::removing`], removing the pixels the file marks.
    HotPixels {
        /// The mask of hot pixels, as for `mask=`.
        path: PathBuf,
    },
    /// `hot-pixels=auto`: [`Mask::removing`] the hot pixels learned from the recording being
    /// filtered (see [`FilterSpec::build_with`]).
    HotPixelsAuto,
}

/// A SPEC that does not parse, or a filter that does not fit the sensor.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The name before `=` is none of [`NAMES`].
    #[error(
        "unknown filter `{spec}`: expected one of background-activity, fast-decay, k-noise, \
         polarity, region, refractory, circle, mask, hot-pixels"
    )]
    UnknownFilter {
        /// The SPEC as given.
        spec: String,
    },
    /// The values after `=` are missing, or too few or too many.
    #[error("filter `{spec}`: expected {usage}")]
    Values {
        /// The SPEC as given.
        spec: String,
        /// The filter's SPEC form.
        usage: &'static str,
    },
    /// A duration that is not a positive whole number of microseconds with a unit.
    #[error("filter `{spec}`: the duration `{value}` {reason}")]
    Duration {
        /// The SPEC as given.
        spec: String,
        /// The duration as given.
        value: String,
        /// What is wrong with it.
        reason: ParseDurationError,
    },
    /// A number that does not parse or is out of its range.
    #[error("filter `{spec}`: the {what} `{value}` is not {expected}")]
    Number {
        /// The SPEC as given.
        spec: String,
        /// Which value (`subdivision`, `width`, ...).
        what: &'static str,
        /// The value as given.
        value: String,
        /// What it must be.
        expected: &'static str,
    },
    /// `polarity=` with neither `on` nor `off`.
    #[error("filter `{spec}`: the polarity `{value}` is neither `on` nor `off`")]
    Polarity {
        /// The SPEC as given.
        spec: String,
        /// The polarity as given.
        value: String,
    },
    /// A region that does not lie wholly on the sensor.
    #[error(
        "filter `{spec}`: the region's columns {x}..{x_end} and rows {y}..{y_end} do not fit \
         the {sensor} sensor",
        x_end = u32::from(*.x) + u32::from(*.width),
        y_end = u32::from(*.y) + u32::from(*.height)
    )]
    RegionOffSensor {
        /// The SPEC, written back.
        spec: String,
        /// Left column.
        x: u16,
        /// Top row.
        y: u16,
        /// Columns.
        width: u16,
        /// Rows.
        height: u16,
        /// The sensor.
        sensor: Resolution,
    },
    /// A circle whose centre is off the sensor.
    #[error(
        "filter `{spec}`: the circle's centre ({cx}, {cy}) is off the {sensor} sensor (columns \
         0 to {}, rows 0 to {})",
        .sensor.width.saturating_sub(1),
        .sensor.height.saturating_sub(1)
    )]
    CircleOffSensor {
        /// The SPEC, written back.
        spec: String,
        /// Centre column.
        cx: f64,
        /// Centre row.
        cy: f64,
        /// The sensor.
        sensor: Resolution,
    },
    /// A mask file that cannot be read as a mask.
    #[error("filter `{spec}`: the mask {path} {reason}")]
    MaskFile {
        /// The SPEC, written back.
        spec: String,
        /// The file.
        path: String,
        /// Why it is no mask.
        reason: String,
    },
    /// `hot-pixels=auto` where nothing was learned: no recording to learn from (a live input,
    /// say), or a caller that builds without learning.
    #[error(
        "filter `{spec}`: learns the hot pixels from the recording it filters, and there is none \
         to learn from here; learn them from a recording with `evtac stats RECORDING \
         --hot-pixels MASK.npy` and give `hot-pixels=MASK.npy`"
    )]
    NotLearned {
        /// The SPEC, written back.
        spec: String,
    },
    /// A mask of another size than the sensor.
    #[error("filter `{spec}`: the mask is {found} (columns x rows), the sensor {sensor}")]
    MaskSize {
        /// The SPEC, written back.
        spec: String,
        /// The mask's size.
        found: Resolution,
        /// The sensor.
        sensor: Resolution,
    },
}

/// Each filter's SPEC form, for the errors.
const USAGE_BACKGROUND: &str = "background-activity=DURATION, e.g. background-activity=2ms";
const USAGE_FAST_DECAY: &str =
    "fast-decay[=HALF_LIFE[,SUBDIVISION[,THRESHOLD]]], e.g. fast-decay=10ms,4,6";
const USAGE_K_NOISE: &str = "k-noise=DURATION, e.g. k-noise=1ms";
const USAGE_POLARITY: &str = "polarity=on or polarity=off";
const USAGE_REGION: &str = "region=X,Y,W,H, e.g. region=40,0,240,240";
const USAGE_REFRACTORY: &str = "refractory=DURATION, e.g. refractory=250us";
const USAGE_CIRCLE: &str = "circle=CX,CY,R, e.g. circle=120,120,110";
const USAGE_MASK: &str = "mask=FILE, a uint8 H x W NPY array or 8-bit greyscale PNG";
const USAGE_HOT_PIXELS: &str =
    "hot-pixels=FILE (a uint8 H x W NPY array or 8-bit greyscale PNG) or hot-pixels=auto";

impl FromStr for FilterSpec {
    type Err = Error;

    fn from_str(spec: &str) -> Result<Self, Self::Err> {
        let (name, value) = match spec.split_once('=') {
            Some((name, value)) => (name.trim(), Some(value)),
            None => (spec.trim(), None),
        };
        let usage = match name {
            "background-activity" => USAGE_BACKGROUND,
            "fast-decay" => USAGE_FAST_DECAY,
            "k-noise" => USAGE_K_NOISE,
            "polarity" => USAGE_POLARITY,
            "region" => USAGE_REGION,
            "refractory" => USAGE_REFRACTORY,
            "circle" => USAGE_CIRCLE,
            "mask" => USAGE_MASK,
            "hot-pixels" => USAGE_HOT_PIXELS,
            _ => {
                return Err(Error::UnknownFilter {
                    spec: spec.to_string(),
                });
            }
        };
        let p = Parser { spec, usage };
        // Only fast-decay has defaults for all its values, as dv-processing's constructor does.
        let Some(value) = value else {
            return match name {
                "fast-decay" => Ok(Self::FastDecay {
                    half_life: Micros::new(FastDecay::DEFAULT_HALF_LIFE_US)
                        .expect("the default is positive"),
                    subdivision: FastDecay::DEFAULT_SUBDIVISION,
                    threshold: FastDecay::DEFAULT_THRESHOLD,
                }),
                _ => Err(p.values()),
            };
        };
        // A file's name is taken whole (it may hold commas), only an empty one refused.
        if matches!(name, "mask" | "hot-pixels") {
            let path = PathBuf::from(value.trim());
            if path.as_os_str().is_empty() {
                return Err(p.values());
            }
            if name == "hot-pixels" && value.trim() == "auto" {
                return Ok(Self::HotPixelsAuto);
            }
            return Ok(if name == "mask" {
                Self::Mask { path }
            } else {
                Self::HotPixels { path }
            });
        }
        let fields: Vec<&str> = value.split(',').map(str::trim).collect();
        match name {
            "background-activity" => Ok(Self::BackgroundActivity {
                duration: p.duration(p.exactly::<1>(&fields)?[0])?,
            }),
            "fast-decay" => p.fast_decay(&fields),
            "k-noise" => Ok(Self::KNoise {
                duration: p.duration(p.exactly::<1>(&fields)?[0])?,
            }),
            "polarity" => match p.exactly::<1>(&fields)?[0] {
                "on" => Ok(Self::Polarity { on: true }),
                "off" => Ok(Self::Polarity { on: false }),
                other => Err(Error::Polarity {
                    spec: spec.to_string(),
                    value: other.to_string(),
                }),
            },
            "region" => {
                let [x, y, width, height] = p.exactly::<4>(&fields)?;
                Ok(Self::Region {
                    x: p.integer("x", x, 0)?,
                    y: p.integer("y", y, 0)?,
                    width: p.integer("width", width, 1)?,
                    height: p.integer("height", height, 1)?,
                })
            }
            "refractory" => Ok(Self::Refractory {
                period: p.duration(p.exactly::<1>(&fields)?[0])?,
            }),
            "circle" => {
                let [cx, cy, radius] = p.exactly::<3>(&fields)?;
                let finite = "a finite number";
                Ok(Self::Circle {
                    cx: p.real("centre column", cx, finite, f64::is_finite)?,
                    cy: p.real("centre row", cy, finite, f64::is_finite)?,
                    radius: p.real("radius", radius, "a positive number", |r| {
                        r.is_finite() && r > 0.0
                    })?,
                })
            }
            _ => unreachable!("every name above has its usage"),
        }
    }
}

/// One SPEC's values, read with errors that name the SPEC.
struct Parser<'a> {
    spec: &'a str,
    usage: &'static str,
}

impl Parser<'_> {
    fn values(&self) -> Error {
        Error::Values {
            spec: self.spec.to_string(),
            usage: self.usage,
        }
    }

    fn exactly<'f, const N: usize>(&self, fields: &[&'f str]) -> Result<[&'f str; N], Error> {
        <[&str; N]>::try_from(fields).map_err(|_| self.values())
    }

    fn duration(&self, value: &str) -> Result<Micros, Error> {
        value.parse().map_err(|reason| Error::Duration {
            spec: self.spec.to_string(),
            value: value.to_string(),
            reason,
        })
    }

    fn integer(&self, what: &'static str, value: &str, min: u16) -> Result<u16, Error> {
        value
            .parse::<u16>()
            .ok()
            .filter(|&v| v >= min)
            .ok_or_else(|| Error::Number {
                spec: self.spec.to_string(),
                what,
                value: value.to_string(),
                expected: if min == 0 {
                    "a whole number from 0 to 65535"
                } else {
                    "a whole number from 1 to 65535"
                },
            })
    }

    fn real(
        &self,
        what: &'static str,
        value: &str,
        expected: &'static str,
        ok: impl Fn(f64) -> bool,
    ) -> Result<f64, Error> {
        value
            .parse::<f64>()
            .ok()
            .filter(|&v| ok(v))
            .ok_or_else(|| Error::Number {
                spec: self.spec.to_string(),
                what,
                value: value.to_string(),
                expected,
            })
    }

    /// `HALF_LIFE[,SUBDIVISION[,THRESHOLD]]`, the missing ones at their defaults.
    fn fast_decay(&self, fields: &[&str]) -> Result<FilterSpec, Error> {
        if fields.len() > 3 {
            return Err(self.values());
        }
        let subdivision = match fields.get(1) {
            Some(v) => self.integer("subdivision", v, 1)?,
            None => FastDecay::DEFAULT_SUBDIVISION,
        };
        let threshold = match fields.get(2) {
            Some(v) => v
                .parse::<f32>()
                .ok()
                .filter(|t| t.is_finite())
                .ok_or_else(|| Error::Number {
                    spec: self.spec.to_string(),
                    what: "threshold",
                    value: v.to_string(),
                    expected: "a finite number",
                })?,
            None => FastDecay::DEFAULT_THRESHOLD,
        };
        Ok(FilterSpec::FastDecay {
            half_life: self.duration(fields[0])?,
            subdivision,
            threshold,
        })
    }
}

impl FilterSpec {
    /// The filter's name, as its SPEC begins.
    pub fn name(&self) -> &'static str {
        match self {
            Self::BackgroundActivity { .. } => NAMES[0],
            Self::FastDecay { .. } => NAMES[1],
            Self::KNoise { .. } => NAMES[2],
            Self::Polarity { .. } => NAMES[3],
            Self::Region { .. } => NAMES[4],
            Self::Refractory { .. } => NAMES[5],
            Self::Circle { .. } => NAMES[6],
            Self::Mask { .. } => NAMES[7],
            Self::HotPixels { .. } | Self::HotPixelsAuto => NAMES[8],
        }
    }

    /// Whether building this filter needs what is learned from the recording it filters
    /// (`hot-pixels=auto`).
    pub fn learns(&self) -> bool {
        matches!(self, Self::HotPixelsAuto)
    }

    /// The filter for `sensor`, or why it does not fit: a region must lie wholly on the sensor,
    /// a circle's centre on it, a mask be the sensor's size (its file is read here).
    /// `hot-pixels=auto` is an error here ([`Error::NotLearned`]): see [`Self::build_with`].
    pub fn build(&self, sensor: Resolution) -> Result<Box<dyn Filter>, Error> {
        self.build_with(sensor, None)
    }

    /// [`Self::build`], with the hot pixels (column, row) learned from the recording to be
    /// filtered for `hot-pixels=auto`; pixels off the sensor are ignored.
    pub fn build_with(
        &self,
        sensor: Resolution,
        hot_pixels: Option<&[(u16, u16)]>,
    ) -> Result<Box<dyn Filter>, Error> {
        Ok(match *self {
            Self::HotPixelsAuto => {
                let hot = hot_pixels.ok_or_else(|| Error::NotLearned {
                    spec: self.to_string(),
                })?;
                Box::new(HotPixels::at(sensor, hot).counted())
            }
            Self::Mask { ref path } | Self::HotPixels { ref path } => {
                let image = mask_file::read(path).map_err(|reason| Error::MaskFile {
                    spec: self.to_string(),
                    path: path.display().to_string(),
                    reason,
                })?;
                if image.size != sensor {
                    return Err(Error::MaskSize {
                        spec: self.to_string(),
                        found: image.size,
                        sensor,
                    });
                }
                match self {
                    Self::Mask { .. } => Box::new(Mask::new(sensor, &image.values).counted()),
                    _ => Box::new(HotPixels::new(sensor, &image.values).counted()),
                }
            }
            Self::BackgroundActivity { duration } => {
                Box::new(BackgroundActivity::new(sensor, duration).counted())
            }
            Self::FastDecay {
                half_life,
                subdivision,
                threshold,
            } => Box::new(FastDecay::new(sensor, half_life, subdivision, threshold).counted()),
            Self::KNoise { duration } => Box::new(KNoise::new(sensor, duration).counted()),
            Self::Polarity { on } => Box::new(PolarityFilter::new(on).counted()),
            Self::Region {
                x,
                y,
                width,
                height,
            } => {
                let fits = |start: u16, len: u16, size: u16| {
                    u32::from(start) + u32::from(len) <= u32::from(size)
                };
                if !fits(x, width, sensor.width) || !fits(y, height, sensor.height) {
                    return Err(Error::RegionOffSensor {
                        spec: self.to_string(),
                        x,
                        y,
                        width,
                        height,
                        sensor,
                    });
                }
                Box::new(Region::new(x, y, width, height).counted())
            }
            Self::Refractory { period } => Box::new(Refractory::new(sensor, period).counted()),
            Self::Circle { cx, cy, radius } => {
                let on = |c: f64, size: u16| (0.0..=f64::from(size) - 1.0).contains(&c);
                if !on(cx, sensor.width) || !on(cy, sensor.height) {
                    return Err(Error::CircleOffSensor {
                        spec: self.to_string(),
                        cx,
                        cy,
                        sensor,
                    });
                }
                Box::new(Circle::new(cx, cy, radius).counted())
            }
        })
    }
}

impl fmt::Display for FilterSpec {
    /// The SPEC, every value written out (fast-decay's defaults too).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = self.name();
        match self {
            Self::BackgroundActivity { duration } | Self::KNoise { duration } => {
                write!(f, "{name}={duration}")
            }
            Self::Refractory { period } => write!(f, "{name}={period}"),
            Self::FastDecay {
                half_life,
                subdivision,
                threshold,
            } => write!(f, "{name}={half_life},{subdivision},{threshold}"),
            Self::Polarity { on } => write!(f, "{name}={}", if *on { "on" } else { "off" }),
            Self::Region {
                x,
                y,
                width,
                height,
            } => write!(f, "{name}={x},{y},{width},{height}"),
            Self::Circle { cx, cy, radius } => write!(f, "{name}={cx},{cy},{radius}"),
            Self::Mask { path } | Self::HotPixels { path } => {
                // A file named `auto` keeps a directory part, so it does not read back as auto.
                let shown = if path.as_os_str() == "auto" {
                    std::path::Path::new(".").join(path)
                } else {
                    path.clone()
                };
                write!(f, "{name}={}", shown.display())
            }
            Self::HotPixelsAuto => write!(f, "{name}=auto"),
        }
    }
}

impl serde::Serialize for FilterSpec {
    /// As its SPEC ([`fmt::Display`]), so a file that records filters says them as a user
    /// types them.
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for FilterSpec {
    /// From its SPEC, the parse error as the serde error.
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let spec = String::deserialize(deserializer)?;
        spec.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<FilterSpec, Error> {
        s.parse()
    }

    fn us(v: i64) -> Micros {
        Micros::new(v).unwrap()
    }

    #[test]
    fn every_filter_parses() {
        assert_eq!(
            parse("background-activity=2ms"),
            Ok(FilterSpec::BackgroundActivity {
                duration: us(2_000)
            })
        );
        assert_eq!(
            parse("fast-decay"),
            Ok(FilterSpec::FastDecay {
                half_life: us(10_000),
                subdivision: 4,
                threshold: 6.0
            })
        );
        assert_eq!(
            parse("fast-decay=5ms"),
            Ok(FilterSpec::FastDecay {
                half_life: us(5_000),
                subdivision: 4,
                threshold: 6.0
            })
        );
        assert_eq!(
            parse("fast-decay=5ms, 2"),
            Ok(FilterSpec::FastDecay {
                half_life: us(5_000),
                subdivision: 2,
                threshold: 6.0
            })
        );
        assert_eq!(
            parse("fast-decay=1s,1,2.5"),
            Ok(FilterSpec::FastDecay {
                half_life: us(1_000_000),
                subdivision: 1,
                threshold: 2.5
            })
        );
        assert_eq!(
            parse("k-noise=750us"),
            Ok(FilterSpec::KNoise { duration: us(750) })
        );
        assert_eq!(parse("polarity=on"), Ok(FilterSpec::Polarity { on: true }));
        assert_eq!(
            parse("polarity=off"),
            Ok(FilterSpec::Polarity { on: false })
        );
        assert_eq!(
            parse("region=40,0,240,240"),
            Ok(FilterSpec::Region {
                x: 40,
                y: 0,
                width: 240,
                height: 240
            })
        );
        assert_eq!(
            parse("refractory=250us"),
            Ok(FilterSpec::Refractory { period: us(250) })
        );
        assert_eq!(
            parse("circle=119.5,120,110"),
            Ok(FilterSpec::Circle {
                cx: 119.5,
                cy: 120.0,
                radius: 110.0
            })
        );
    }

    #[test]
    fn specs_written_back_parse_to_themselves() {
        for s in [
            "background-activity=2ms",
            "fast-decay=10ms,4,6",
            "fast-decay=1500us,3,0.25",
            "k-noise=1s",
            "polarity=off",
            "region=1,2,3,4",
            "refractory=250us",
            "circle=119.5,120,110.25",
            "hot-pixels=auto",
            "hot-pixels=./auto",
            "mask=masks/a,b.npy",
        ] {
            let spec = parse(s).unwrap();
            assert_eq!(spec.to_string(), s);
            assert_eq!(parse(&spec.to_string()), Ok(spec));
        }
        assert_eq!(
            parse("fast-decay").unwrap().to_string(),
            "fast-decay=10ms,4,6"
        );
    }

    #[test]
    fn errors_name_the_spec_and_what_is_wrong() {
        let message = |s: &str| parse(s).unwrap_err().to_string();
        assert_eq!(
            message("hot-pixel=3"),
            "unknown filter `hot-pixel=3`: expected one of background-activity, fast-decay, \
             k-noise, polarity, region, refractory, circle, mask, hot-pixels"
        );
        assert_eq!(
            message("k-noise"),
            "filter `k-noise`: expected k-noise=DURATION, e.g. k-noise=1ms"
        );
        assert_eq!(
            message("background-activity=0ms"),
            "filter `background-activity=0ms`: the duration `0ms` is not positive"
        );
        assert_eq!(
            message("refractory=-1ms"),
            "filter `refractory=-1ms`: the duration `-1ms` is not positive"
        );
        assert_eq!(
            message("k-noise=fast"),
            "filter `k-noise=fast`: the duration `fast` is not a number followed by us, ms or s"
        );
        assert_eq!(
            message("k-noise=5"),
            "filter `k-noise=5`: the duration `5` has no unit (write it with us, ms or s, e.g. 2ms)"
        );
        assert!(
            message("fast-decay=10ms,0")
                .contains("the subdivision `0` is not a whole number from 1")
        );
        assert!(
            message("fast-decay=10ms,4,nan").contains("the threshold `nan` is not a finite number")
        );
        assert!(
            message("fast-decay=10ms,4,6,1")
                .starts_with("filter `fast-decay=10ms,4,6,1`: expected")
        );
        assert!(
            message("region=1,2,3").starts_with("filter `region=1,2,3`: expected region=X,Y,W,H")
        );
        assert!(message("region=1,2,0,3").contains("the width `0` is not a whole number from 1"));
        assert_eq!(
            message("polarity=both"),
            "filter `polarity=both`: the polarity `both` is neither `on` nor `off`"
        );
        assert!(message("circle=1,2,0").contains("the radius `0` is not a positive number"));
        assert!(message("circle=1,inf,3").contains("the centre row `inf` is not a finite number"));
    }

    #[test]
    fn specs_serialize_as_they_are_written() {
        let specs: Vec<FilterSpec> = ["background-activity=10ms", "hot-pixels=auto"]
            .iter()
            .map(|s| parse(s).unwrap())
            .collect();
        let json = serde_json::to_string(&specs).unwrap();
        assert_eq!(json, r#"["background-activity=10ms","hot-pixels=auto"]"#);
        assert_eq!(
            serde_json::from_str::<Vec<FilterSpec>>(&json).unwrap(),
            specs
        );
        let err = serde_json::from_str::<FilterSpec>(r#""k-noise=0ms""#).unwrap_err();
        assert!(err.to_string().contains("filter `k-noise=0ms`"), "{err}");
    }

    #[test]
    fn hot_pixels_auto_removes_what_was_learned_and_only_then() {
        let sensor = Resolution::new(4, 3);
        let spec = parse("hot-pixels=auto").unwrap();
        assert!(spec.learns() && !parse("hot-pixels=auto.npy").unwrap().learns());
        assert_eq!(
            parse("hot-pixels=./auto"),
            Ok(FilterSpec::HotPixels {
                path: "./auto".into()
            })
        );
        let err = spec.build(sensor).map(|f| f.name()).unwrap_err();
        assert!(
            err.to_string().starts_with(
                "filter `hot-pixels=auto`: learns the hot pixels from the recording it filters"
            ),
            "{err}"
        );
        // (9, 9) is off the sensor and ignored.
        let mut f = spec.build_with(sensor, Some(&[(1, 2), (9, 9)])).unwrap();
        let e = |x, y| evtac_events::Event {
            t: 0,
            x,
            y,
            polarity: true,
        };
        assert!(!f.keep(&e(1, 2)));
        assert!(f.keep(&e(2, 1)) && f.keep(&e(0, 0)));
        assert_eq!((f.name(), f.removed()), ("hot-pixels", 1));
    }

    #[test]
    fn regions_and_circles_must_fit_the_sensor() {
        let sensor = Resolution::new(64, 48);
        let build = |s: &str| parse(s).unwrap().build(sensor).map(|f| f.name());
        assert_eq!(build("region=0,0,64,48"), Ok("region"));
        assert_eq!(
            build("region=10,0,55,48").unwrap_err().to_string(),
            "filter `region=10,0,55,48`: the region's columns 10..65 and rows 0..48 do not fit \
             the 64x48 sensor"
        );
        assert!(build("region=0,40,64,9").is_err());
        assert!(build("region=65535,0,65535,1").is_err());
        assert_eq!(build("circle=0,47,100"), Ok("circle"));
        assert_eq!(build("circle=63,0,1"), Ok("circle"));
        assert_eq!(
            build("circle=63.5,10,5").unwrap_err().to_string(),
            "filter `circle=63.5,10,5`: the circle's centre (63.5, 10) is off the 64x48 sensor \
             (columns 0 to 63, rows 0 to 47)"
        );
        assert!(build("circle=10,-1,5").is_err());
        // The mask filters read files: `tests/masks.rs` builds them.
        for s in NAMES
            .into_iter()
            .filter(|s| !matches!(*s, "mask" | "hot-pixels"))
        {
            let spec = match s {
                "polarity" => "polarity=on".to_string(),
                "region" => "region=0,0,1,1".to_string(),
                "circle" => "circle=1,1,1".to_string(),
                "fast-decay" => s.to_string(),
                _ => format!("{s}=1ms"),
            };
            assert_eq!(build(&spec), Ok(s));
        }
    }
}
