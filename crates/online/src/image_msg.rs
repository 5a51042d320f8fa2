//! `sensor_msgs/msg/Image`, the message the representation's frames are logged as
//! (`evtac online --mcap-frames`): the ROS 2 image type Foxglove's Image panel, `rosbags` and
//! `ros2 bag play` all know, so a log of frames needs nothing evtac-specific to be seen.
//!
//! A frame's 0/1 pixels are written `mono8` as 0 and 255 (black and white in any viewer),
//! row-major, `step` = width. Serialized by the same CDR serializer as the estimates
//! ([`crate::ros2::Vector3Stamped::to_cdr`]).

use crate::frames::Frame;
use crate::ros2::{Header, Time, header_definitions};
use serde::{Deserialize, Serialize};

/// The ROS 2 type name of [`Image`].
pub const IMAGE_TYPE: &str = "sensor_msgs/msg/Image";

/// The `.msg` definition of [`IMAGE_TYPE`] with its dependencies, as `rosbag2` stores it in an
/// MCAP schema (see [`crate::ros2::MSG_DEFINITION`] for the layout).
pub const IMAGE_DEFINITION: &str = concat!(
    "std_msgs/Header header\n",
    "uint32 height\n",
    "uint32 width\n",
    "string encoding\n",
    "uint8 is_bigendian\n",
    "uint32 step\n",
    "uint8[] data\n",
    header_definitions!(),
);

/// The value a set pixel is written as (`mono8` white).
pub const SET: u8 = 255;

/// `sensor_msgs/msg/Image`, field for field.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Image {
    /// `stamp` = the frame's time, `frame_id` as the estimates'.
    pub header: Header,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// `mono8`.
    pub encoding: String,
    /// 0 (one byte per pixel: no byte order).
    pub is_bigendian: u8,
    /// Bytes per row (= width).
    pub step: u32,
    /// 0 or [`SET`] per pixel, row-major.
    pub data: Vec<u8>,
}

impl Image {
    /// The image of `frame` taken at `t_us`.
    pub fn from_frame(frame: &Frame, t_us: i64, frame_id: &str) -> Self {
        Self {
            header: Header {
                stamp: Time::from_micros(t_us),
                frame_id: frame_id.to_owned(),
            },
            height: frame.height,
            width: frame.width,
            encoding: "mono8".into(),
            is_bigendian: 0,
            step: frame.width,
            data: frame
                .pixels
                .iter()
                .map(|&p| if p != 0 { SET } else { 0 })
                .collect(),
        }
    }

    /// Appends the CDR encoding with its 4-byte encapsulation header (little-endian CDR).
    pub fn to_cdr(&self, out: &mut Vec<u8>) -> Result<(), rustdds::serialization::Error> {
        crate::ros2::to_cdr(self, out)
    }
}
