//! A NeuroTac event-based tactile sensor simulator, evtac's built-in data source.
//!
//! It models the paper's setup (see `docs/simulator.md` for the model and every parameter): a
//! hemispherical silicone tip with pins in hexagonal rings ([`sensor`]), pressed into a rigid
//! plane and rolled about its centre ([`protocol`], [`trial`]), imaged from inside by a DVS
//! ([`dvs`], after v2e) with an IMU ([`imu`]).
//!
//! ```
//! use evtac_sim::{Protocol, Scale, SimParams, Simulator, plan};
//!
//! let params = SimParams::default();
//! let trials = plan(Protocol::Exp1, Scale::Tiny, 42, &params.timeline);
//! let sim = Simulator::new(params, 42);
//! let recording = sim.simulate(&trials[0]);
//! assert!(!recording.events.is_empty() && !recording.imu.is_empty());
//! ```

pub mod capture;
pub mod dataset;
pub mod dvs;
pub mod imu;
pub mod params;
pub mod params_file;
pub mod protocol;
pub mod rig;
pub mod sensor;
pub mod session;
pub mod trial;

pub use capture::{AsSimulated, Capture};
pub use dataset::{DatasetConfig, DatasetError, simulate_captured, simulate_dataset};
pub use params::SimParams;
pub use params_file::{ParamsError, read_params};
pub use protocol::{Design, Motion, Protocol, Scale, TrialSpec, plan, plan_design};
pub use sensor::SkinPose;
pub use session::{SessionConfig, SessionRecord, simulate_session};
pub use trial::{Simulator, TrialRecording, TruthSample};
