//! The plain data types every part of evtac passes around: events, IMU samples, triggers,
//! sensor resolution and the region of interest (ROI) that crops the sensor to the pin array.

use serde::{Deserialize, Serialize};

/// One change-detection event from an event camera.
///
/// `t` is in microseconds (the AEDAT4 unit); `x` grows to the right and `y` downwards from the
/// top-left pixel of the full sensor; `polarity` is `true` for an ON (brightness increase) event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub struct Event {
    /// Timestamp in microseconds.
    pub t: i64,
    /// Column, 0 at the left.
    pub x: u16,
    /// Row, 0 at the top.
    pub y: u16,
    /// `true` for ON (positive) events.
    pub polarity: bool,
}

/// One inertial measurement: what a DVXplorer's IMU reports.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ImuSample {
    /// Timestamp in microseconds, on the same clock as the events.
    pub t: i64,
    /// Acceleration in g along the IMU's x, y and z axes.
    pub accelerometer: [f32; 3],
    /// Angular velocity in degrees per second about the IMU's x, y and z axes.
    pub gyroscope: [f32; 3],
    /// Temperature in degrees Celsius.
    pub temperature: f32,
}

/// An external trigger or special event, as AEDAT4 stores them: DV records the camera's trigger
/// input (e.g. a robot's sync pulses) as a `Trigger` stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Trigger {
    /// Timestamp in microseconds, on the same clock as the events.
    pub t: i64,
    /// The AEDAT4 trigger type code (dv-processing's `TriggerType`): 0 `TIMESTAMP_RESET`,
    /// 1 / 2 / 3 external signal rising edge / falling edge / pulse, 4 / 5 external generator
    /// rising / falling edge, 6 .. 9 APS frame start / end and exposure start / end. Prophesee
    /// external triggers read from EVT files are 1 (rising) or 2 (falling).
    pub kind: i8,
}

impl Trigger {
    /// The type code of an external signal's rising edge, as DV records a robot's sync pulse.
    pub const RISING_EDGE: i8 = 1;
}

/// Width and height of a sensor (or of a crop of it), in pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Resolution {
    /// Number of columns.
    pub width: u16,
    /// Number of rows.
    pub height: u16,
}

impl Resolution {
    /// A resolution of `width` x `height` pixels.
    pub const fn new(width: u16, height: u16) -> Self {
        Self { width, height }
    }

    /// Number of pixels.
    pub const fn pixels(self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Whether `(x, y)` lies on the sensor.
    pub const fn contains(self, x: u16, y: u16) -> bool {
        x < self.width && y < self.height
    }
}

impl std::fmt::Display for Resolution {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

impl std::str::FromStr for Resolution {
    type Err = String;

    /// Parses `WIDTHxHEIGHT`, e.g. `640x480`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (w, h) = s
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("resolution `{s}` is not of the form WIDTHxHEIGHT"))?;
        let parse = |v: &str, what: &str| {
            v.trim()
                .parse::<u16>()
                .ok()
                .filter(|&n| n > 0)
                .ok_or_else(|| {
                    format!("{what} `{v}` in `{s}` is not a whole number from 1 to 65535")
                })
        };
        Ok(Self::new(parse(w, "width")?, parse(h, "height")?))
    }
}

/// A rectangular region of interest: the crop that evtac applies to the sensor before building
/// representations (the paper uses the centered 240x240 region).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Roi {
    /// Left column of the crop on the full sensor.
    pub x0: u16,
    /// Top row of the crop on the full sensor.
    pub y0: u16,
    /// Size of the crop.
    pub size: Resolution,
}

impl Roi {
    /// The whole sensor: a crop that keeps every event and changes no coordinate.
    pub const fn full(sensor: Resolution) -> Self {
        Self {
            x0: 0,
            y0: 0,
            size: sensor,
        }
    }

    /// The crop of `size` centered on `sensor` (offsets rounded down), or `None` when `size` does
    /// not fit inside `sensor`.
    pub fn centered(sensor: Resolution, size: Resolution) -> Option<Self> {
        if size.width > sensor.width || size.height > sensor.height {
            return None;
        }
        Some(Self {
            x0: (sensor.width - size.width) / 2,
            y0: (sensor.height - size.height) / 2,
            size,
        })
    }

    /// Maps an event on the full sensor into the crop's coordinates, or `None` when the event
    /// lies outside the crop (such events are dropped).
    #[inline]
    pub fn map(&self, event: Event) -> Option<Event> {
        let x = event.x.checked_sub(self.x0)?;
        let y = event.y.checked_sub(self.y0)?;
        self.size.contains(x, y).then_some(Event { x, y, ..event })
    }

    /// Crops a slice of events into `out` (cleared first), keeping their order.
    pub fn crop_into(&self, events: &[Event], out: &mut Vec<Event>) {
        out.clear();
        out.extend(events.iter().filter_map(|&e| self.map(e)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centered_roi_maps_and_drops() {
        let roi = Roi::centered(Resolution::new(640, 480), Resolution::new(240, 240)).unwrap();
        assert_eq!((roi.x0, roi.y0), (200, 120));
        let e = |x, y| Event {
            t: 5,
            x,
            y,
            polarity: true,
        };
        assert_eq!(roi.map(e(200, 120)), Some(e(0, 0)));
        assert_eq!(roi.map(e(439, 359)), Some(e(239, 239)));
        assert_eq!(roi.map(e(440, 200)), None);
        assert_eq!(roi.map(e(199, 200)), None);
        assert_eq!(roi.map(e(300, 119)), None);
        assert!(Roi::centered(Resolution::new(100, 100), Resolution::new(240, 240)).is_none());
    }

    #[test]
    fn resolution_parses() {
        assert_eq!(
            "640x480".parse::<Resolution>(),
            Ok(Resolution::new(640, 480))
        );
        assert!("640".parse::<Resolution>().is_err());
        assert!("0x480".parse::<Resolution>().is_err());
        assert!("70000x1".parse::<Resolution>().is_err());
    }
}
