//! Which streams of a file to read, as the user names them: the event, IMU and trigger stream
//! of an AEDAT4 file with several (two cameras), or the event and IMU topics of a ROS bag.
//! Every reader of several streams takes a [`StreamSelection`]; how a name picks a stream is
//! the format's (`aedat/selection.rs`, `ros/mod.rs`). The live inputs and the command line's
//! `--stream`, `--imu-stream` and `--trigger-stream` use the same type.

use std::fmt;
use std::str::FromStr;

/// A stream named by the user: its id, or a name matched against the stream's output name
/// (`events`), its camera (`source`, e.g. `DVXplorer_DXA00093`) or both as `SOURCE/NAME`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StreamChoice {
    /// The stream id that packets carry.
    Id(i32),
    /// An output name, a camera name, or `SOURCE/NAME`.
    Name(String),
}

impl FromStr for StreamChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim();
        if s.is_empty() {
            return Err("a stream is named by its id or its name, not by nothing".into());
        }
        Ok(s.parse::<i32>()
            .map_or_else(|_| Self::Name(s.to_string()), Self::Id))
    }
}

impl fmt::Display for StreamChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Id(id) => write!(f, "{id}"),
            Self::Name(name) => f.write_str(name),
        }
    }
}

/// The user's picks, one per decoded kind (`None`: the default rule).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct StreamSelection {
    /// The event stream (`--stream`).
    pub events: Option<StreamChoice>,
    /// The IMU stream (`--imu-stream`).
    pub imu: Option<StreamChoice>,
    /// The trigger stream (`--trigger-stream`).
    pub triggers: Option<StreamChoice>,
}
