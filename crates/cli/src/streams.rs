//! `--stream`, `--imu-stream`, `--trigger-stream`: which streams of an AEDAT4 file with several
//! (two cameras, say) a command reads, and which topics of a ROS bag (`--topic` and
//! `--imu-topic` are the same flags under the names ROS users look for), flattened into each
//! command that reads a recording (`evtac_formats::StreamSelection` has the rule when they
//! are not given).

use evtac_formats::{StreamChoice, StreamSelection};

/// The stream flags.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct StreamArgs {
    /// The event stream to read from an AEDAT4 file with several (e.g. two cameras): its id, its
    /// name, its camera's name or CAMERA/NAME; or the event topic of a ROS bag
    /// (`/dvs/events`); as `evtac info` lists them. Default: the file's only one.
    #[arg(long, visible_alias = "topic", value_name = "NAME|ID")]
    pub stream: Option<StreamChoice>,
    /// The IMU stream (or a ROS bag's IMU topic), when the file has several. Default: the only
    /// one, or the chosen event stream's camera's.
    #[arg(long, visible_alias = "imu-topic", value_name = "NAME|ID")]
    pub imu_stream: Option<StreamChoice>,
    /// The trigger stream, when the file has several. Default: the only one, or the chosen event
    /// stream's camera's.
    #[arg(long, value_name = "NAME|ID")]
    pub trigger_stream: Option<StreamChoice>,
}

impl StreamArgs {
    /// The selection these flags ask for.
    pub fn selection(&self) -> StreamSelection {
        StreamSelection {
            events: self.stream.clone(),
            imu: self.imu_stream.clone(),
            triggers: self.trigger_stream.clone(),
        }
    }
}
