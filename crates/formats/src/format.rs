//! The formats evtac knows, by name: what `info` prints, results record and errors name. Which
//! family reads each one, and how it is recognised, is the registry's ([`crate::registry`]).

use std::path::Path;

use crate::Error;

/// The event file formats evtac knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Format {
    /// iniVation AEDAT 4.0 (`.aedat4`): events, IMU and triggers.
    Aedat4,
    /// jAER AEDAT 2.0 (`.aedat`) from a DAVIS240 or DAVIS346: polarity events, read only.
    Aedat2,
    /// cAER AEDAT 3.1 (`.aedat`): polarity events, IMU6 and triggers, read only.
    Aedat31,
    /// Prophesee EVT 2.0 raw (`.raw`), read only.
    Evt2,
    /// Prophesee EVT 2.1 raw (`.raw`), read only.
    Evt21,
    /// Prophesee EVT 3.0 raw (`.raw`), read only.
    Evt3,
    /// `t,x,y,p` CSV (`.csv`).
    Csv,
    /// NPY with an event record dtype, `t <i8, x <i2, y <i2, p u1` as evtac writes it (`.npy`;
    /// other names and integer types read, see [`crate::npy`]).
    Npy,
    /// NPZ: numpy's zip of NPY arrays, one event record array or one array per field
    /// (`.npz`), read only (see [`crate::npy::npz`]).
    Npz,
    /// HDF5 with one dataset per event field (event_utils' and the NeuroTac code's layout, and
    /// DSEC's), read only (see [`crate::hdf5`]).
    Hdf5,
    /// The NeuroTac lab's per-pixel event times (a pickle, or an NPY of Python objects), read
    /// only (see [`crate::neurotac`]).
    Neurotac,
    /// A ROS 1 bag (`.bag`): `dvs_msgs/EventArray` or `event_camera_msgs/EventPacket` events and
    /// `sensor_msgs/Imu`, read only (see [`crate::ros`]).
    RosBag,
    /// A ROS 2 bag in MCAP storage (an `.mcap` file or a rosbag2 folder), with the same messages
    /// as [`Format::RosBag`], read only (see [`crate::ros`]).
    Mcap,
}

impl Format {
    /// Every format, in the order of the variants.
    pub const ALL: &[Format] = &[
        Self::Aedat4,
        Self::Aedat2,
        Self::Aedat31,
        Self::Evt2,
        Self::Evt21,
        Self::Evt3,
        Self::Csv,
        Self::Npy,
        Self::Npz,
        Self::Hdf5,
        Self::Neurotac,
        Self::RosBag,
        Self::Mcap,
    ];

    /// The short name shown to users (`AEDAT4`, `AEDAT2`, `AEDAT3.1`, `EVT2`, `EVT21`, `EVT3`,
    /// `CSV`, `NPY`, `NPZ`, `HDF5`, `NeuroTac pickle`, `ROS 1 bag`, `ROS 2 MCAP`).
    pub const fn name(self) -> &'static str {
        match self {
            Self::Aedat4 => "AEDAT4",
            Self::Aedat2 => "AEDAT2",
            Self::Aedat31 => "AEDAT3.1",
            Self::Evt2 => "EVT2",
            Self::Evt21 => "EVT21",
            Self::Evt3 => "EVT3",
            Self::Csv => "CSV",
            Self::Npy => "NPY",
            Self::Npz => "NPZ",
            Self::Hdf5 => "HDF5",
            Self::Neurotac => "NeuroTac pickle",
            Self::RosBag => "ROS 1 bag",
            Self::Mcap => "ROS 2 MCAP",
        }
    }

    /// Whether the format carries the sensor resolution itself (CSV, NPY and NPZ do not; HDF5
    /// does when it has a `sensor_resolution` attribute, which DSEC's files do not).
    pub const fn has_resolution(self) -> bool {
        !matches!(self, Self::Csv | Self::Npy | Self::Npz | Self::Hdf5)
    }

    /// The format an output path's extension asks for: `.aedat4`, `.csv` or `.npy`.
    pub fn for_writing(path: &Path) -> Result<Self, Error> {
        crate::registry::for_writing(path)
    }

    /// Recognises the format of the file at `path`: by its first bytes, else by its extension.
    /// A folder is read as a rosbag2 bag (its `.mcap` files).
    pub fn detect(path: &Path) -> Result<Self, Error> {
        crate::registry::detect(path)
    }
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
