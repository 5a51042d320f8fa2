//! `--sensor WxH`: the sensor size, one flag with one meaning in every command that reads a
//! recording (`info`, `convert`, `represent`, `online`). Formats that state their size (AEDAT,
//! EVT, the NeuroTac pickles' shape, HDF5's `sensor_resolution`) are checked against it; CSV,
//! NPY, NPZ and DSEC's HDF5, which do not, need it.
//! `--resolution`, the name `convert` and `represent` used before, is still accepted.

use evtac_events::Resolution;

/// The sensor-size flag.
#[derive(Debug, Clone, Copy, Default, clap::Args)]
pub struct SensorArgs {
    /// Sensor size WIDTHxHEIGHT: required for inputs that do not state it (CSV, NPY, NPZ, DSEC's
    /// HDF5); checked
    /// against the size a file states and against every event.
    #[arg(long, alias = "resolution", value_name = "WxH")]
    pub sensor: Option<Resolution>,
}
