//! The pipeline's behaviour around its input: reconnection after a drop, a stalled stream,
//! dropping when asked, stopping early (also while the input blocks). A small DV network server on loopback (the bytes of an
//! AEDAT4 file without its magic and data table: DV's network framing) stands in for a camera.

use crate::support::{self, SENSOR, Synthetic};
use evtac_events::Event;
use evtac_formats::aedat::{AedatReader, AedatWriter, Compression, WriterConfig};
use evtac_learn::Model;
use evtac_online::input::{
    self, EventSource, MemorySource, NetworkOptions, OpenOptions, SourceSpec,
};
use evtac_online::pipeline::{self, Output, PipelineConfig};
use evtac_online::{Backoff, Estimate, Estimator, Notice, Summary};
use std::io::Write;
use std::net::TcpListener;
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// A DV network stream of `events`: the stream header, then one byte range per packet.
struct Stream {
    header: Vec<u8>,
    packets: Vec<Vec<u8>>,
}

impl Stream {
    /// Sends the header and then `packets` on `connection`, as DV does to a new client.
    fn send(&self, connection: &mut impl Write, packets: &[Vec<u8>]) {
        connection.write_all(&self.header).unwrap();
        for p in packets {
            connection.write_all(p).unwrap();
        }
    }
}

fn network_stream(events: &[Event]) -> Stream {
    let config = WriterConfig {
        resolution: SENSOR,
        source_name: "evtac-test".into(),
        compression: Compression::None,
    };
    let mut writer = AedatWriter::new(Vec::new(), config).unwrap();
    writer.write_events(events).unwrap();
    let bytes = writer.finish().unwrap();
    let mut reader = AedatReader::from_slice(&bytes).unwrap();
    let mut offsets = Vec::new();
    while let Some(chunk) = reader.next_chunk().unwrap() {
        offsets.push(chunk.offset as usize);
    }
    offsets.push(reader.offset() as usize);
    let magic = evtac_formats::aedat::MAGIC.len();
    Stream {
        header: bytes[magic..offsets[0]].to_vec(),
        packets: offsets
            .windows(2)
            .map(|w| bytes[w[0]..w[1]].to_vec())
            .collect(),
    }
}

fn model(dir: &std::path::Path) -> Model {
    let (_, repr) = support::representations()[1];
    support::seeded_bundle(dir, 3, &repr, None);
    Model::load(dir).unwrap()
}

/// A synthetic stream of `duration_us` (seeded) for a server that sends it in two halves: the
/// events, their packets, the index of the second half's first packet, and a listener on a free
/// local port with that port.
fn halves(seed: u64, duration_us: i64) -> (Vec<Event>, Stream, usize, TcpListener, u16) {
    let events: Vec<Event> = Synthetic::new(seed, 300_000.0, 1000, duration_us).collect();
    let stream = network_stream(&events);
    let half = stream.packets.len() / 2;
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    (events, stream, half, listener, port)
}

fn quick_network(attempts: u32, stall_ms: u64) -> NetworkOptions {
    NetworkOptions {
        backoff: Backoff {
            initial: Duration::from_millis(20),
            max: Duration::from_millis(100),
            attempts,
        },
        connect_timeout: Duration::from_millis(500),
        stall_timeout: Duration::from_millis(stall_ms),
    }
}

/// Runs the pipeline on `tcp://127.0.0.1:port`; returns estimates, notices and the summary.
fn run_tcp(
    model: &Model,
    port: u16,
    network: NetworkOptions,
) -> (Vec<Estimate>, Vec<Notice>, Summary) {
    let mut notices = Vec::new();
    let spec = SourceSpec::Tcp {
        host: "127.0.0.1".into(),
        port,
    };
    let options = OpenOptions {
        network,
        ..OpenOptions::default()
    };
    let opened = input::open(&spec, &options, &mut |n| notices.push(n)).unwrap();
    let estimator = Estimator::for_model(model, opened.resolution.unwrap(), 1000).unwrap();
    let mut estimates = Vec::new();
    let summary = support::run_to_end(opened.source, estimator, &mut notices, |e| {
        estimates.push(e)
    });
    (estimates, notices, summary)
}

#[test]
fn a_dropped_connection_is_retried_and_nothing_that_arrived_is_lost() {
    let (events, stream, half, listener, port) = halves(1, 200_000);
    let server = std::thread::spawn(move || {
        // First connection: the first half of the packets, then the server hangs up.
        let (mut c, _) = listener.accept().unwrap();
        stream.send(&mut c, &stream.packets[..half]);
        drop(c);
        // The camera comes back: the second half, then the server goes away for good.
        let (mut c, _) = listener.accept().unwrap();
        stream.send(&mut c, &stream.packets[half..]);
    });
    let dir = tempfile::tempdir().unwrap();
    let model = model(dir.path());
    let (estimates, notices, summary) = run_tcp(&model, port, quick_network(3, 2000));
    server.join().unwrap();

    assert_eq!(summary.reconnects, 1, "{notices:?}");
    assert_eq!(summary.events, events.len() as u64);
    assert!(
        notices
            .iter()
            .any(|n| matches!(n, Notice::Lost { reason, .. } if reason.contains("closed"))),
        "{notices:?}"
    );
    assert!(
        notices
            .iter()
            .any(|n| matches!(n, Notice::GaveUp { attempts: 3, .. }))
    );
    support::assert_same_estimates(&estimates, &support::replayed(&model, &events, usize::MAX));
}

#[test]
fn a_stalled_stream_is_reported_and_reopened() {
    let (events, stream, half, listener, port) = halves(2, 100_000);
    let server = std::thread::spawn(move || {
        let (mut c, _) = listener.accept().unwrap();
        stream.send(&mut c, &stream.packets[..half]);
        // Silent, connection open: the client must give up on it and reconnect.
        let (mut c2, _) = listener.accept().unwrap();
        drop(c);
        stream.send(&mut c2, &stream.packets[half..]);
    });
    let dir = tempfile::tempdir().unwrap();
    let model = model(dir.path());
    let (estimates, notices, summary) = run_tcp(&model, port, quick_network(2, 200));
    server.join().unwrap();
    assert!(
        notices
            .iter()
            .any(|n| matches!(n, Notice::Lost { reason, .. } if reason.contains("stalled"))),
        "{notices:?}"
    );
    assert_eq!(summary.reconnects, 1);
    support::assert_same_estimates(&estimates, &support::replayed(&model, &events, usize::MAX));
}

#[test]
fn an_unreachable_server_fails_with_a_clear_message() {
    // Bind then close: nothing listens on the port now.
    let port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let spec: SourceSpec = format!("tcp://127.0.0.1:{port}").parse().unwrap();
    let options = OpenOptions {
        network: quick_network(1, 200),
        ..OpenOptions::default()
    };
    let mut notices = Vec::new();
    let err = input::open(&spec, &options, &mut |n| notices.push(n)).unwrap_err();
    let text = err.to_string();
    assert!(text.contains(&format!("tcp://127.0.0.1:{port}")), "{text}");
    assert!(text.contains("2 attempts"), "{text}");
    assert_eq!(
        notices
            .iter()
            .filter(|n| matches!(n, Notice::AttemptFailed { .. }))
            .count(),
        2
    );
}

/// Runs `source` through the pipeline with a caller that breaks off after `n` estimates, and
/// checks that it saw exactly `n`.
fn break_after(source: impl EventSource + 'static, model: &Model, n: u64) -> Summary {
    let mut seen = 0u64;
    let summary = pipeline::run(
        source,
        Estimator::for_model(model, SENSOR, 1000).unwrap(),
        &PipelineConfig::default(),
        |out| {
            if matches!(out, Output::Estimate(_)) {
                seen += 1;
            }
            if seen == n {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    )
    .unwrap();
    assert_eq!(seen, n);
    summary
}

/// A stop (Ctrl-C in `evtac online`) while estimates wait for a slow consumer: the estimates
/// already made are still delivered, so the summary counts exactly what the caller was given
/// (it used to count estimates that were dropped undelivered).
#[test]
fn a_stop_delivers_the_estimates_already_made() {
    let events: Vec<Event> = Synthetic::new(4, 300_000.0, 1000, 200_000).collect();
    let dir = tempfile::tempdir().unwrap();
    let model = model(dir.path());
    let stop = AtomicBool::new(false);
    let mut delivered = 0u64;
    let summary = pipeline::run_until(
        MemorySource::new(events, 256),
        Estimator::for_model(&model, SENSOR, 1000).unwrap(),
        &PipelineConfig::default(),
        &stop,
        |out| {
            if let Output::Estimate(_) = out {
                delivered += 1;
                if delivered == 1 {
                    // A slow consumer: the estimator runs ahead meanwhile. Then stop.
                    std::thread::sleep(Duration::from_millis(50));
                    stop.store(true, Ordering::Relaxed);
                }
            }
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    assert!(summary.estimates > 1, "the estimator ran ahead: {summary}");
    assert_eq!(summary.estimates, delivered);
}

#[test]
fn stopping_early_and_dropping_when_behind() {
    let events: Vec<Event> = Synthetic::new(3, 300_000.0, 1000, 300_000).collect();
    let dir = tempfile::tempdir().unwrap();
    let model = model(dir.path());

    // The caller stops after 10 estimates: the run ends cleanly.
    let summary = break_after(MemorySource::new(events.clone(), 512), &model, 10);
    assert!(summary.estimates >= 10);

    // A one-chunk queue and a slow consumer: with dropping, events are dropped and counted,
    // never silently; without, none are.
    for drop_when_behind in [false, true] {
        let config = PipelineConfig {
            queue_chunks: 1,
            drop_when_behind,
            ..PipelineConfig::default()
        };
        let mut notices = 0;
        let summary = pipeline::run(
            MemorySource::new(events.clone(), 64),
            Estimator::for_model(&model, SENSOR, 1000).unwrap(),
            &config,
            |out| {
                match out {
                    Output::Estimate(_) => std::thread::sleep(Duration::from_micros(200)),
                    Output::Notice(Notice::Dropped { .. }) => notices += 1,
                    Output::Notice(_) | Output::Frames(_) => {}
                }
                ControlFlow::Continue(())
            },
        )
        .unwrap();
        assert_eq!(summary.events, events.len() as u64);
        if drop_when_behind {
            assert!(summary.events_dropped > 0 && notices > 0, "{summary}");
        } else {
            assert_eq!(summary.events_dropped, 0);
            assert_eq!(
                summary.estimates,
                support::replayed(&model, &events, usize::MAX).len() as u64
            );
        }
    }
}

#[test]
fn out_of_order_events_are_skipped_and_counted() {
    let mut events: Vec<Event> = Synthetic::new(4, 100_000.0, 1000, 20_000).collect();
    // A camera restarted behind a reconnection: its clock starts over.
    let again: Vec<Event> = events.iter().take(100).copied().collect();
    events.extend(again);
    let dir = tempfile::tempdir().unwrap();
    let model = model(dir.path());
    let summary = pipeline::run(
        MemorySource::new(events, 333),
        Estimator::for_model(&model, SENSOR, 1000).unwrap(),
        &PipelineConfig::default(),
        |_| ControlFlow::Continue(()),
    )
    .unwrap();
    assert_eq!(summary.events_out_of_order, 100);
    // One estimate per millisecond of the first 20 ms, whatever came after.
    assert!((19..=20).contains(&summary.estimates), "{summary}");
}

/// Delivers `events` in chunks, then blocks for good, as standard input does when its producer
/// goes quiet.
struct ThenSilence {
    inner: MemorySource,
}

impl EventSource for ThenSilence {
    fn next_chunk(&mut self, out: &mut Vec<Event>, notify: &mut dyn FnMut(Notice)) -> input::Next {
        match self.inner.next_chunk(out, notify)? {
            Some(info) => Ok(Some(info)),
            None => loop {
                std::thread::park();
            },
        }
    }
}

#[test]
fn a_stop_ends_the_run_with_its_summary_while_the_input_blocks() {
    let events: Vec<Event> = Synthetic::new(5, 100_000.0, 1000, 30_000).collect();
    let dir = tempfile::tempdir().unwrap();
    let model = model(dir.path());
    let silent = || ThenSilence {
        inner: MemorySource::new(events.clone(), 1000),
    };

    // A stop flag raised from another thread (as the Ctrl-C handler does) once the stream has
    // gone quiet.
    let stop = AtomicBool::new(false);
    let mut seen = 0u64;
    let summary = std::thread::scope(|scope| {
        let run = scope.spawn(|| {
            pipeline::run_until(
                silent(),
                Estimator::for_model(&model, SENSOR, 1000).unwrap(),
                &PipelineConfig::default(),
                &stop,
                |out| {
                    if matches!(out, Output::Estimate(_)) {
                        seen += 1;
                    }
                    ControlFlow::Continue(())
                },
            )
        });
        std::thread::sleep(Duration::from_millis(300));
        stop.store(true, Ordering::Relaxed);
        run.join().unwrap().unwrap()
    });
    // Every estimate the events allow (the last interval or two need a later event to close
    // them, which never comes).
    assert!((27..=30).contains(&seen), "{seen}");
    assert_eq!(summary.estimates, seen);
    assert_eq!(summary.events, events.len() as u64);

    // A caller that breaks off while the input blocks is not held up either.
    let summary = break_after(silent(), &model, 20);
    assert!(summary.estimates >= 20);
}

#[test]
fn busy_polling_gives_the_same_estimates() {
    let events: Vec<Event> = Synthetic::new(6, 300_000.0, 1000, 40_000).collect();
    let dir = tempfile::tempdir().unwrap();
    let model = model(dir.path());
    let mut estimates = Vec::new();
    let config = PipelineConfig {
        busy_poll: true,
        ..PipelineConfig::default()
    };
    let summary = pipeline::run(
        MemorySource::new(events.clone(), 700),
        Estimator::for_model(&model, SENSOR, 1000).unwrap(),
        &config,
        |out| {
            if let Output::Estimate(e) = out {
                estimates.push(e);
            }
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    support::assert_same_estimates(&estimates, &support::replayed(&model, &events, usize::MAX));
    assert_eq!(summary.estimates, estimates.len() as u64);
}
