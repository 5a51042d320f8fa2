//! The two-thread pipeline: ingestion and estimation, a bounded queue between them.
//!
//! ```text
//!  source --(ingestion thread)--> [bounded queue of chunks] --(estimation thread)--> outputs
//!              stamps arrival          backpressure, or drop        Estimator             |
//!                   ^------------------ buffer pool (recycled Vec<Event>) ----------------'
//! ```
//!
//! Chunk buffers circulate through a pool instead of being allocated per chunk, the queue has a
//! fixed capacity, and the latency histogram is preallocated, so memory stays flat however long
//! the run. By default a full queue makes the ingestion thread wait (a network sender then sees
//! TCP backpressure, nothing is lost); with [`PipelineConfig::drop_when_behind`] the chunk is
//! dropped and counted instead.

use crate::estimator::{Error as EstimatorError, Estimate, Estimator};
use crate::frames::FrameSet;
use crate::input::{EventSource, InputError};
use crate::notice::Notice;
use crate::summary::Summary;
use crossbeam_channel::{Receiver, RecvTimeoutError, Sender, TryRecvError, TrySendError, bounded};
use evtac_events::Event;
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

/// Settings of the pipeline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PipelineConfig {
    /// Chunks the queue between the threads holds before ingestion waits (or drops).
    pub queue_chunks: usize,
    /// Drop a chunk when the queue is full instead of waiting for the estimator.
    pub drop_when_behind: bool,
    /// Let the estimation thread spin on the queue instead of sleeping until a chunk comes:
    /// it then occupies a core all the time, and no chunk waits for the thread to be woken
    /// (tens to hundreds of microseconds on a busy or virtualised machine).
    pub busy_poll: bool,
}

impl Default for PipelineConfig {
    /// 64 chunks (a DV stream sends a few hundred packets per second), never drop, sleep while
    /// idle.
    fn default() -> Self {
        Self {
            queue_chunks: 64,
            drop_when_behind: false,
            busy_poll: false,
        }
    }
}

/// What the pipeline hands to its caller, in order.
#[derive(Debug, Clone, PartialEq)]
pub enum Output {
    /// An estimate.
    Estimate(Estimate),
    /// A change in the input's state (connection lost, retried, ...).
    Notice(Notice),
    /// The representation's frames at an estimate's time, after that estimate (only when the
    /// estimator captures them: `Estimator::capture_frames`).
    Frames(FrameSet),
}

/// Errors of a run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The input failed; everything that arrived before was estimated (see `summary`).
    #[error("{source}")]
    Input {
        /// What failed.
        #[source]
        source: InputError,
        /// The run up to the failure.
        summary: Box<Summary>,
    },
    /// The estimator failed (a bug in evtac: its input is checked before it gets there).
    #[error("{source}")]
    Estimator {
        /// What failed.
        #[source]
        source: EstimatorError,
        /// The run up to the failure.
        summary: Box<Summary>,
    },
    /// A pipeline thread panicked (a bug in evtac).
    #[error("the {thread} thread panicked")]
    Panicked {
        /// Which thread.
        thread: &'static str,
    },
}

/// Messages from the ingestion thread to the estimation thread.
enum Msg {
    Chunk {
        events: Vec<Event>,
        horizon: Option<i64>,
        arrival: Instant,
    },
    Notice(Notice),
    End(Instant),
}

/// Counts kept by the ingestion thread, shared so that a stop can read them without joining it.
#[derive(Debug, Default)]
struct Ingested {
    dropped: AtomicU64,
    first_arrival: OnceLock<Instant>,
}

/// Shortest time between two "dropped" notices, so that a slow consumer is told without being
/// flooded.
const DROP_NOTICE_EVERY: Duration = Duration::from_secs(1);

/// Outputs buffered between the estimation thread and the caller.
const OUTPUT_QUEUE: usize = 4096;

/// Runs `source` through `estimator` on two threads until the source ends, `on_output`
/// returns [`ControlFlow::Break`], or the input fails; returns the run's summary.
///
/// `on_output` runs on the calling thread and receives every estimate and notice in order.
pub fn run<S: EventSource + 'static>(
    source: S,
    estimator: Estimator,
    config: &PipelineConfig,
    on_output: impl FnMut(Output) -> ControlFlow<()>,
) -> Result<Summary, Error> {
    run_until(
        source,
        estimator,
        config,
        &AtomicBool::new(false),
        on_output,
    )
}

/// How often the threads look at the stop flag while they wait for data.
const STOP_POLL: Duration = Duration::from_millis(20);

/// As [`run`], and also stops soon after `stop` becomes true (for example from a Ctrl-C
/// handler), still returning the summary of everything estimated so far.
///
/// A source may block in a read that nothing can interrupt (standard input with no data); the
/// ingestion thread is then left behind, detached, and ends with the process, so that stopping
/// never waits on the input.
pub fn run_until<S: EventSource + 'static>(
    source: S,
    estimator: Estimator,
    config: &PipelineConfig,
    stop: &AtomicBool,
    mut on_output: impl FnMut(Output) -> ControlFlow<()>,
) -> Result<Summary, Error> {
    let capacity = config.queue_chunks.max(1);
    let (msg_tx, msg_rx) = bounded::<Msg>(capacity);
    // Every buffer in flight fits back into the pool: queue + one being filled + one being
    // estimated + slack.
    let (pool_tx, pool_rx) = bounded::<Vec<Event>>(capacity + 4);
    for _ in 0..capacity + 2 {
        // The pool is empty and sized above, so this cannot fail.
        let _ = pool_tx.try_send(Vec::new());
    }
    let (out_tx, out_rx) = bounded::<Output>(OUTPUT_QUEUE);
    let drop_when_behind = config.drop_when_behind;
    let busy_poll = config.busy_poll;
    let started = Instant::now();
    let ingested = Arc::new(Ingested::default());
    // Not scoped: a stop must not wait for a read that may never return (see above).
    let ingest = std::thread::Builder::new()
        .name("evtac-ingest".into())
        .spawn({
            let ingested = Arc::clone(&ingested);
            move || ingest(source, msg_tx, pool_rx, drop_when_behind, &ingested)
        })
        .map_err(|_| Error::Panicked {
            thread: "ingestion",
        })?;

    // Set when the caller is done before the stream is: tells the estimation thread to end
    // even while no chunk arrives.
    let quit = AtomicBool::new(false);
    let (estimator, connections) = std::thread::scope(|scope| {
        let quit = &quit;
        let estimate = std::thread::Builder::new()
            .name("evtac-estimate".into())
            .spawn_scoped(scope, move || {
                estimate(estimator, msg_rx, pool_tx, out_tx, [stop, quit], busy_poll)
            });
        let mut connections = 0u32;
        let mut deliver = |output: Output| {
            if let Output::Notice(Notice::Connected { .. }) = &output {
                connections += 1;
            }
            on_output(output)
        };
        loop {
            if stop.load(Ordering::Relaxed) {
                quit.store(true, Ordering::Relaxed);
                // What the estimation thread has already made (it ends after its current
                // chunk) is still delivered, so the summary counts what the caller was given.
                while let Ok(output) = out_rx.recv() {
                    if deliver(output).is_break() {
                        break;
                    }
                }
                break;
            }
            let output = match out_rx.recv_timeout(STOP_POLL) {
                Ok(output) => output,
                Err(RecvTimeoutError::Timeout) => continue,
                Err(RecvTimeoutError::Disconnected) => break,
            };
            if deliver(output).is_break() {
                quit.store(true, Ordering::Relaxed);
                break;
            }
        }
        // Dropping the receiver stops the estimation thread at its next output, which drops
        // the queue's receiver and so stops the ingestion thread at its next chunk.
        drop(out_rx);
        let estimator = estimate
            .ok()
            .and_then(|h| h.join().ok())
            .ok_or(Error::Panicked {
                thread: "estimation",
            });
        (estimator, connections)
    });
    let (estimator, estimator_failure) = estimator?;
    // The ingestion thread has ended or is about to (its queue is closed) unless it is blocked
    // in a read; only a caller that quit early leaves it behind.
    let ended_early = quit.load(Ordering::Relaxed) || stop.load(Ordering::Relaxed);
    let failure = if ended_early && !ingest.is_finished() {
        None
    } else {
        ingest.join().map_err(|_| Error::Panicked {
            thread: "ingestion",
        })?
    };
    let counters = estimator.counters();
    let dropped = ingested.dropped.load(Ordering::Relaxed);
    let mut summary = Summary::from_stats(estimator.stats(), estimator.processing_stats());
    summary.events = counters.events + dropped;
    summary.events_in_roi = counters.events_in_roi;
    summary.events_dropped = dropped;
    summary.events_out_of_order = counters.events_out_of_order;
    summary.events_filtered = counters.events_filtered;
    // Sources connect before the run starts (see `input::open`): every connection during the
    // run is a reconnection.
    summary.reconnects = connections;
    summary.span_us = counters.span_us;
    summary.wall = ingested
        .first_arrival
        .get()
        .map_or_else(|| started.elapsed(), |t| t.elapsed());
    if let Some(source) = estimator_failure {
        return Err(Error::Estimator {
            source,
            summary: Box::new(summary),
        });
    }
    match failure {
        Some(source) => Err(Error::Input {
            source,
            summary: Box::new(summary),
        }),
        None => Ok(summary),
    }
}

/// The ingestion thread: pulls chunks, stamps their arrival, queues them.
fn ingest<S: EventSource>(
    mut source: S,
    tx: Sender<Msg>,
    pool: Receiver<Vec<Event>>,
    drop_when_behind: bool,
    ingested: &Ingested,
) -> Option<InputError> {
    let mut last_drop_notice: Option<Instant> = None;
    let mut dropped_since_notice = 0usize;
    // The buffer of a dropped chunk, kept for the next one.
    let mut spare: Option<Vec<Event>> = None;
    loop {
        let mut notify = |notice: Notice| {
            // A closed queue means the run is stopping; the notice no longer matters.
            let _ = tx.send(Msg::Notice(notice));
        };
        // Reuse a buffer from the pool; a new one only while the pool is still filling up.
        let mut events = spare
            .take()
            .or_else(|| pool.try_recv().ok())
            .unwrap_or_default();
        let info = match source.next_chunk(&mut events, &mut notify) {
            Ok(Some(info)) => info,
            Ok(None) => break,
            Err(e) => {
                let _ = tx.send(Msg::End(Instant::now()));
                return Some(e);
            }
        };
        let arrival = Instant::now();
        let _ = ingested.first_arrival.set(arrival);
        let msg = Msg::Chunk {
            events,
            horizon: info.horizon,
            arrival,
        };
        if drop_when_behind {
            match tx.try_send(msg) {
                Ok(()) => {}
                Err(TrySendError::Full(Msg::Chunk { events, .. })) => {
                    ingested
                        .dropped
                        .fetch_add(events.len() as u64, Ordering::Relaxed);
                    dropped_since_notice += events.len();
                    spare = Some(events);
                    if last_drop_notice.is_none_or(|t| t.elapsed() >= DROP_NOTICE_EVERY) {
                        last_drop_notice = Some(Instant::now());
                        let _ = tx.send(Msg::Notice(Notice::Dropped {
                            events: std::mem::take(&mut dropped_since_notice),
                        }));
                    }
                }
                Err(_) => return None,
            }
        } else if tx.send(msg).is_err() {
            return None;
        }
    }
    let _ = tx.send(Msg::End(Instant::now()));
    None
}

/// The estimation thread: turns queued chunks into estimates.
fn estimate(
    mut estimator: Estimator,
    rx: Receiver<Msg>,
    pool: Sender<Vec<Event>>,
    out: Sender<Output>,
    stop: [&AtomicBool; 2],
    busy_poll: bool,
) -> (Estimator, Option<EstimatorError>) {
    evtac_learn::flush_denormals();
    let mut failure = None;
    // Set when the caller stopped listening; checked between chunks.
    let stopped = std::cell::Cell::new(false);
    let mut emit = |e: &Estimate| {
        if out.send(Output::Estimate(*e)).is_err() {
            stopped.set(true);
        }
    };
    let emit_frames = |f: FrameSet| {
        if out.send(Output::Frames(f)).is_err() {
            stopped.set(true);
        }
    };
    while !stop.iter().any(|s| s.load(Ordering::Relaxed)) {
        let msg = if busy_poll {
            match rx.try_recv() {
                Ok(msg) => msg,
                Err(TryRecvError::Empty) => {
                    std::hint::spin_loop();
                    continue;
                }
                Err(TryRecvError::Disconnected) => break,
            }
        } else {
            match rx.recv_timeout(STOP_POLL) {
                Ok(msg) => msg,
                Err(RecvTimeoutError::Timeout) => continue,
                Err(RecvTimeoutError::Disconnected) => break,
            }
        };
        match msg {
            Msg::Chunk {
                events,
                horizon,
                arrival,
            } => {
                if let Err(e) = estimator.process(&events, horizon, arrival, &mut emit) {
                    failure = Some(e);
                    break;
                }
                for frames in estimator.take_frames() {
                    emit_frames(frames);
                }
                // A full pool means spare buffers: let this one go.
                let _ = pool.try_send(events);
            }
            Msg::Notice(notice) => {
                if out.send(Output::Notice(notice)).is_err() {
                    break;
                }
            }
            Msg::End(at) => {
                failure = estimator.finish(at, &mut emit).err();
                for frames in estimator.take_frames() {
                    emit_frames(frames);
                }
                break;
            }
        }
        if stopped.get() {
            break;
        }
    }
    (estimator, failure)
}
