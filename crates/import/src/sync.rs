//! Putting a robot's log on the recording's clock (`evtac import --sync`): a given offset, or
//! one found from the recording itself.
//!
//! - [`Sync::Offset`]: recording time = robot time + the offset, for every row.
//! - [`Sync::Trigger`]: the robot pulses the camera's trigger input at each motion's onset, and
//!   DV records the pulses as an AEDAT4 `Trigger` stream: the k-th trigger (of the given type)
//!   marks the k-th motion's onset (rows in the order of their onsets), so each row gets its own
//!   offset, which also absorbs the controller's timestamp jitter and slow clock drift. A count
//!   of triggers that differs from the log's rows is an error naming both files, and so is an
//!   offset that jumps by more than [`MAX_OFFSET_STEP_US`] from one motion to the next (a
//!   missed pulse and an extra one elsewhere pair every row between them with the wrong
//!   trigger, though the counts agree).
//! - [`Sync::Imu`]: one offset, the one that best aligns the gyroscope's rate magnitude with the
//!   rate the log commands ([`crate::imu_sync`]), reported with its residual.
//!
//! The triggers are read in a pass of their own before the cut, which therefore reads the
//! session a second time; the pass decodes the trigger packets only (the event and IMU
//! packets are read past, not decompressed). One pass cutting trials as their triggers arrive
//! would need bounded memory it cannot have: a trial starts [`crate::import::DEFAULT_PRE_MS`]
//! (1 s) before the onset its trigger marks, and a trigger reaches the file only when its
//! packet is written, after the events it marks by as long as the recorder keeps the packet
//! open: DV's by about 10 ms, evtac's own writer's by a whole trial and the gap after it (it
//! closes a trigger packet when the next trigger comes), and AEDAT4 puts no bound on it (a
//! recorder may hold the packet to the end of the file). Every stream would have to be held
//! from the earliest instant a trial not yet announced could start until its trigger arrives:
//! seconds of events for DV, a trial's worth for evtac's sessions, the whole session at worst.
//! The pairing's checks also need the triggers first: a count that differs from the log's rows
//! is known only at the end, and a single pass would have cut every trial by then.

use crate::imu_sync::{ImuSyncError, imu_offset};
use crate::robot_log::{LogError, RobotLog};
use std::path::{Path, PathBuf};

/// The most the trigger offsets of two motions in a row may differ, us: far more than a
/// controller's timestamp jitter or a clock's drift between two motions, far less than the time
/// between two motions, which a wrongly paired trigger adds.
pub const MAX_OFFSET_STEP_US: i64 = 100_000;

/// How the log's times are put on the recording's clock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sync {
    /// Recording time = robot time + this offset, microseconds.
    Offset(i64),
    /// The k-th trigger of this type code marks the k-th motion's onset.
    Trigger(i8),
    /// The offset that best aligns the gyroscope with the commanded rate.
    Imu,
}

/// Errors of a synchronisation; each names the files at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SyncError {
    /// The session could not be read.
    #[error(transparent)]
    Recording(#[from] evtac_formats::Error),
    /// The gyroscope could not be aligned with the log.
    #[error(transparent)]
    Imu(#[from] ImuSyncError),
    /// A row's trigger offset jumps from the row before it.
    #[error(
        "{}:{line}: column `motion_start_us`: the trigger paired with this motion puts it \
         {jump_us} us off the motion before it (line {previous}); a missed or extra trigger \
         pairs every motion after it with the wrong one (check {} for spurious or missing \
         pulses, or give the offset with --clock-offset-us)",
        log.display(),
        session.display()
    )]
    TriggerJump {
        /// The session recording.
        session: PathBuf,
        /// The log.
        log: PathBuf,
        /// The row's line in the log.
        line: usize,
        /// The line of the motion before it.
        previous: usize,
        /// Its offset minus the previous motion's, us.
        jump_us: i64,
    },
    /// The synchronised log is not a log (its motions overlap).
    #[error(transparent)]
    Log(#[from] LogError),
    /// The session's triggers and the log's rows do not pair up.
    #[error(
        "{}: {triggers} trigger(s) of type {kind}, but {} has {rows} row(s): with --sync trigger \
         the k-th trigger marks the k-th motion's onset (check the trigger wiring and \
         --trigger-kind, or give the offset with --clock-offset-us)",
        session.display(),
        log.display()
    )]
    TriggerCount {
        /// The session recording.
        session: PathBuf,
        /// The log.
        log: PathBuf,
        /// Triggers of type `kind` in the session.
        triggers: usize,
        /// Rows of the log.
        rows: usize,
        /// The trigger type code counted.
        kind: i8,
    },
}

/// What a synchronisation found: each row's offset (recording time minus robot time, in log
/// order).
#[derive(Debug, Clone, PartialEq)]
pub struct Synced {
    /// The log on the recording's clock.
    pub log: RobotLog,
    /// Each row's offset, microseconds, in log order.
    pub offsets: Vec<i64>,
    /// With [`Sync::Imu`]: the RMS of the gyroscope's rate magnitude minus the commanded rate
    /// at the offset found, deg/s.
    pub residual_deg_s: Option<f64>,
}

impl Synced {
    /// The smallest, median and largest offset, microseconds (`None` for an empty log).
    pub fn offset_range(&self) -> Option<[i64; 3]> {
        let mut sorted = self.offsets.clone();
        sorted.sort_unstable();
        Some([*sorted.first()?, sorted[sorted.len() / 2], *sorted.last()?])
    }
}

/// Puts `log` (read on the robot's clock, offset 0) on the clock of the recording `session`.
pub fn synchronise(session: &Path, log: RobotLog, sync: Sync) -> Result<Synced, SyncError> {
    let mut residual_deg_s = None;
    let offsets = match sync {
        Sync::Offset(offset) => vec![offset; log.rows.len()],
        Sync::Trigger(kind) => trigger_offsets(session, &log, kind)?,
        Sync::Imu => {
            let fit = imu_offset(session, &log)?;
            residual_deg_s = Some(fit.residual_deg_s);
            vec![fit.offset_us; log.rows.len()]
        }
    };
    let log = log.shifted(&offsets)?;
    Ok(Synced {
        log,
        offsets,
        residual_deg_s,
    })
}

/// Each row's offset from the session's triggers of type `kind` (rows paired with triggers in
/// the order of their onsets), in log order.
fn trigger_offsets(session: &Path, log: &RobotLog, kind: i8) -> Result<Vec<i64>, SyncError> {
    // A pass of its own before the cuts (which depend on it; see the module docs for why not
    // one pass), decoding the triggers only.
    let mut reader = evtac_formats::open(session)?;
    reader.triggers_only();
    let mut triggers = Vec::new();
    while let Some(chunk) = reader.next_chunk()? {
        triggers.extend(
            chunk
                .triggers
                .iter()
                .filter(|t| t.kind == kind)
                .map(|t| t.t),
        );
    }
    triggers.sort_unstable();
    if triggers.len() != log.rows.len() {
        return Err(SyncError::TriggerCount {
            session: session.to_path_buf(),
            log: log.path.clone(),
            triggers: triggers.len(),
            rows: log.rows.len(),
            kind,
        });
    }
    let order = log.by_onset();
    let mut offsets = vec![0; log.rows.len()];
    for (&row, trigger) in order.iter().zip(triggers) {
        offsets[row] = trigger - log.rows[row].1.motion_start_us;
    }
    for pair in order.windows(2) {
        let jump_us = offsets[pair[1]] - offsets[pair[0]];
        if jump_us.abs() > MAX_OFFSET_STEP_US {
            return Err(SyncError::TriggerJump {
                session: session.to_path_buf(),
                log: log.path.clone(),
                line: log.rows[pair[1]].0,
                previous: log.rows[pair[0]].0,
                jump_us,
            });
        }
    }
    Ok(offsets)
}
