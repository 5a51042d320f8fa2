//! Things worth telling the user while a run goes on: connections lost, retried, given up;
//! input skipped.
//!
//! The library never prints; the pipeline hands notices to its caller (the `evtac` binary prints
//! them on stderr).

use std::time::Duration;

/// A change in the state of the input.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Notice {
    /// Connected to a network input.
    Connected {
        /// The input, e.g. `tcp://127.0.0.1:7777`.
        input: String,
    },
    /// A network input closed, failed or stalled; what arrived before is still estimated.
    Lost {
        /// The input.
        input: String,
        /// Why, e.g. "closed by the server" or "no data for 2.0 s".
        reason: String,
    },
    /// About to retry a lost network input.
    Retrying {
        /// The input.
        input: String,
        /// 1-based attempt number.
        attempt: u32,
        /// Attempts allowed in a row.
        attempts: u32,
        /// The wait before this attempt.
        delay: Duration,
    },
    /// A connection attempt failed.
    AttemptFailed {
        /// The input.
        input: String,
        /// 0 for the first connection, then the 1-based reconnection attempt.
        attempt: u32,
        /// Why it failed.
        reason: String,
    },
    /// Waiting for a silent input that cannot be reconnected to (a ROS 2 topic: DDS
    /// delivers whatever comes); the first sample ends the wait.
    Waiting {
        /// The input.
        input: String,
        /// 1-based attempt number.
        attempt: u32,
        /// Attempts allowed in a row.
        attempts: u32,
        /// The longest this attempt waits.
        wait: Duration,
    },
    /// A piece of the input that did not decode was skipped (a ROS 2 sample); the rest goes on.
    Skipped {
        /// The input.
        input: String,
        /// What was skipped and why.
        reason: String,
    },
    /// All reconnection attempts failed; the run ends after estimating what arrived.
    GaveUp {
        /// The input.
        input: String,
        /// Attempts made.
        attempts: u32,
    },
    /// Events were dropped because the estimator was behind (only with dropping enabled).
    Dropped {
        /// Events dropped in this chunk.
        events: usize,
    },
}

impl std::fmt::Display for Notice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Connected { input } => write!(f, "connected to {input}"),
            Self::Lost { input, reason } => write!(f, "lost {input}: {reason}"),
            Self::Retrying {
                input,
                attempt,
                attempts,
                delay,
            } => write!(
                f,
                "reconnecting to {input} in {:.1} s (attempt {attempt} of {attempts})",
                delay.as_secs_f64()
            ),
            Self::Waiting {
                input,
                attempt,
                attempts,
                wait,
            } => write!(
                f,
                "waiting up to {:.1} s more for {input} (attempt {attempt} of {attempts})",
                wait.as_secs_f64()
            ),
            Self::Skipped { input, reason } => write!(f, "{input}: skipped {reason}"),
            Self::AttemptFailed {
                input,
                attempt,
                reason,
            } if *attempt == 0 => write!(f, "could not reach {input}: {reason}"),
            Self::AttemptFailed {
                input,
                attempt,
                reason,
            } => write!(f, "attempt {attempt} to reach {input} failed: {reason}"),
            Self::GaveUp { input, attempts } => write!(
                f,
                "gave up on {input} after {attempts} reconnection attempts; ending the stream"
            ),
            Self::Dropped { events } => {
                write!(f, "estimator behind: dropped {events} events")
            }
        }
    }
}
