//! A live DV network stream (`tcp://HOST:PORT`): what DV software's network output and
//! dv-processing's `dv.io.NetworkWriter` serve, decoded by `evtac_formats::aedat::AedatReader`'s
//! network mode, with reconnection.
//!
//! A connection that closes, fails, or stays silent for longer than the stall timeout is
//! reported ([`Notice::Lost`]) and retried with exponential backoff ([`Backoff`]). Events that
//! arrived before the loss stay in the pipeline and are estimated; a packet cut in half by the
//! loss never arrived and is not. After the last attempt fails the stream ends normally, so the
//! estimates up to the last event are still emitted.

use super::{ChunkInfo, EventSource, InputError, Next};
use crate::{Backoff, Notice};
use evtac_events::{Event, Resolution};
use evtac_formats::aedat::{AedatError, AedatReader};
use std::io::{BufReader, ErrorKind};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

/// How a network input connects and reconnects.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NetworkOptions {
    /// Retry policy after a loss (also used for the first connection).
    pub backoff: Backoff,
    /// Longest wait for a TCP connection to open; for a ROS 2 input, for its publisher to be
    /// discovered and its first sample to arrive.
    pub connect_timeout: Duration,
    /// A connection silent for this long is considered stalled and reopened.
    pub stall_timeout: Duration,
}

impl Default for NetworkOptions {
    /// Default backoff, 2 s to connect, 2 s of silence is a stall.
    fn default() -> Self {
        Self {
            backoff: Backoff::default(),
            connect_timeout: Duration::from_secs(2),
            stall_timeout: Duration::from_secs(2),
        }
    }
}

type Reader = AedatReader<BufReader<TcpStream>>;

/// A DV network stream over TCP, reconnecting on loss.
pub struct NetworkSource {
    host: String,
    port: u16,
    name: String,
    options: NetworkOptions,
    reader: Option<Reader>,
    resolution: Option<Resolution>,
    /// The stream ended for good (all attempts failed).
    ended: bool,
}

impl std::fmt::Debug for NetworkSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NetworkSource")
            .field("input", &self.name)
            .field("connected", &self.reader.is_some())
            .field("resolution", &self.resolution)
            .finish_non_exhaustive()
    }
}

/// Why a connection attempt failed, for messages.
fn describe(e: &AedatError) -> String {
    match e {
        AedatError::Io { source, .. } if is_timeout(source.kind()) => {
            "no stream header before the stall timeout".to_string()
        }
        other => other.to_string(),
    }
}

fn is_timeout(kind: ErrorKind) -> bool {
    matches!(kind, ErrorKind::WouldBlock | ErrorKind::TimedOut)
}

impl NetworkSource {
    /// Connects to `host:port` and reads the stream header, retrying with the backoff policy;
    /// fails with the last reason when every attempt does.
    pub fn connect(
        host: &str,
        port: u16,
        options: NetworkOptions,
        notify: &mut dyn FnMut(Notice),
    ) -> Result<Self, InputError> {
        let name = if host.contains(':') {
            format!("tcp://[{host}]:{port}")
        } else {
            format!("tcp://{host}:{port}")
        };
        let mut source = Self {
            host: host.to_string(),
            port,
            name,
            options,
            reader: None,
            resolution: None,
            ended: false,
        };
        match source.open() {
            Ok(reader) => {
                source.adopt(reader, notify);
                return Ok(source);
            }
            Err(reason) => notify(Notice::AttemptFailed {
                input: source.name.clone(),
                attempt: 0,
                reason,
            }),
        }
        if source.retry(notify) {
            Ok(source)
        } else {
            Err(InputError::Connect {
                input: source.name.clone(),
                reason: format!(
                    "no stream after {} attempts (is the DV network output running?)",
                    options.backoff.attempts + 1
                ),
            })
        }
    }

    /// The sensor size announced in the stream header.
    pub fn resolution(&self) -> Option<Resolution> {
        self.resolution
    }

    /// The input as `tcp://HOST:PORT`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// One connection attempt: TCP connect and stream header.
    fn open(&self) -> Result<Reader, String> {
        let addrs = (self.host.as_str(), self.port)
            .to_socket_addrs()
            .map_err(|e| format!("cannot resolve {}: {e}", self.host))?;
        let mut last = format!("{} resolves to no address", self.host);
        for addr in addrs {
            match TcpStream::connect_timeout(&addr, self.options.connect_timeout) {
                Ok(stream) => {
                    let setup = stream
                        .set_read_timeout(Some(self.options.stall_timeout))
                        .and_then(|()| stream.set_nodelay(true));
                    if let Err(e) = setup {
                        last = format!("configuring the socket to {addr}: {e}");
                        continue;
                    }
                    return AedatReader::network(BufReader::with_capacity(1 << 16, stream))
                        .map_err(|e| describe(&e));
                }
                Err(e) => last = format!("{addr}: {e}"),
            }
        }
        Err(last)
    }

    fn adopt(&mut self, reader: Reader, notify: &mut dyn FnMut(Notice)) {
        if let Some(r) = reader.resolution() {
            self.resolution = Some(r);
        }
        self.reader = Some(reader);
        notify(Notice::Connected {
            input: self.name.clone(),
        });
    }

    /// Reconnects with backoff; `false` when every attempt failed.
    fn retry(&mut self, notify: &mut dyn FnMut(Notice)) -> bool {
        let backoff = self.options.backoff;
        let mut attempt = 0;
        while let Some(delay) = backoff.delay(attempt) {
            attempt += 1;
            notify(Notice::Retrying {
                input: self.name.clone(),
                attempt,
                attempts: backoff.attempts,
                delay,
            });
            std::thread::sleep(delay);
            match self.open() {
                Ok(reader) => {
                    self.adopt(reader, notify);
                    return true;
                }
                Err(reason) => notify(Notice::AttemptFailed {
                    input: self.name.clone(),
                    attempt,
                    reason,
                }),
            }
        }
        notify(Notice::GaveUp {
            input: self.name.clone(),
            attempts: attempt,
        });
        false
    }
}

impl EventSource for NetworkSource {
    fn next_chunk(&mut self, out: &mut Vec<Event>, notify: &mut dyn FnMut(Notice)) -> Next {
        out.clear();
        loop {
            if self.ended {
                return Ok(None);
            }
            let Some(reader) = self.reader.as_mut() else {
                if !self.retry(notify) {
                    self.ended = true;
                }
                continue;
            };
            let reason = match reader.next_chunk() {
                Ok(Some(chunk)) => {
                    out.extend_from_slice(chunk.events);
                    return Ok(Some(ChunkInfo::default()));
                }
                Ok(None) => "the server closed the connection".to_string(),
                Err(AedatError::Io { source, .. }) if is_timeout(source.kind()) => format!(
                    "no data for {:.1} s (stalled)",
                    self.options.stall_timeout.as_secs_f64()
                ),
                Err(e) => e.to_string(),
            };
            self.reader = None;
            notify(Notice::Lost {
                input: self.name.clone(),
                reason,
            });
        }
    }
}
