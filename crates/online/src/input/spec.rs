//! Where events come from: a file, a live DV network stream, or standard input.
//!
//! A [`SourceSpec`] is what the user typed (`--input`); it is parsed once, up front, so that a
//! typo in `tcp://host:port` is reported before any model is loaded.

use std::path::PathBuf;

/// An input named on the command line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SourceSpec {
    /// A recording on disk (AEDAT 4.0/3.1/2.0, EVT 2.0/2.1/3.0, CSV or NPY; format by extension or magic).
    File(PathBuf),
    /// A live AEDAT4 network stream (DV software's network output, dv-processing's
    /// `NetworkWriter`), reached over TCP.
    Tcp {
        /// Host name or address, e.g. `127.0.0.1`.
        host: String,
        /// TCP port.
        port: u16,
    },
    /// Standard input: an AEDAT4 file or network stream, or CSV text (told apart by the first
    /// bytes).
    Stdin,
}

/// Errors of this module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A `tcp://` input without a `HOST:PORT` part.
    #[error("input `{input}` is not of the form tcp://HOST:PORT")]
    TcpForm {
        /// The input as given.
        input: String,
    },
    /// The port of a `tcp://` input is not a number from 1 to 65535.
    #[error("port `{port}` in input `{input}` is not a number from 1 to 65535")]
    Port {
        /// The input as given.
        input: String,
        /// The port text.
        port: String,
    },
    /// An empty input string.
    #[error("the input is empty (give a file path, tcp://HOST:PORT, or - for standard input)")]
    Empty,
}

impl std::str::FromStr for SourceSpec {
    type Err = Error;

    /// Parses `-` (standard input), `tcp://HOST:PORT` (IPv6 hosts in brackets, `tcp://[::1]:7777`)
    /// or a file path.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.is_empty() {
            return Err(Error::Empty);
        }
        if s == "-" {
            return Ok(Self::Stdin);
        }
        let Some(rest) = s.strip_prefix("tcp://") else {
            return Ok(Self::File(PathBuf::from(s)));
        };
        let rest = rest.trim_end_matches('/');
        let (host, port) = rest.rsplit_once(':').ok_or_else(|| Error::TcpForm {
            input: s.to_string(),
        })?;
        let host = host.trim_start_matches('[').trim_end_matches(']');
        if host.is_empty() {
            return Err(Error::TcpForm {
                input: s.to_string(),
            });
        }
        let port = port
            .parse::<u16>()
            .ok()
            .filter(|&p| p > 0)
            .ok_or_else(|| Error::Port {
                input: s.to_string(),
                port: port.to_string(),
            })?;
        Ok(Self::Tcp {
            host: host.to_string(),
            port,
        })
    }
}

impl std::fmt::Display for SourceSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::File(path) => write!(f, "{}", path.display()),
            Self::Tcp { host, port } if host.contains(':') => write!(f, "tcp://[{host}]:{port}"),
            Self::Tcp { host, port } => write!(f, "tcp://{host}:{port}"),
            Self::Stdin => write!(f, "standard input"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_three_kinds() {
        assert_eq!("-".parse::<SourceSpec>().unwrap(), SourceSpec::Stdin);
        assert_eq!(
            "tcp://127.0.0.1:7777".parse::<SourceSpec>().unwrap(),
            SourceSpec::Tcp {
                host: "127.0.0.1".into(),
                port: 7777
            }
        );
        assert_eq!(
            "tcp://[::1]:7777".parse::<SourceSpec>().unwrap(),
            SourceSpec::Tcp {
                host: "::1".into(),
                port: 7777
            }
        );
        assert_eq!(
            "a/b.aedat4".parse::<SourceSpec>().unwrap(),
            SourceSpec::File("a/b.aedat4".into())
        );
        assert_eq!(
            SourceSpec::Tcp {
                host: "::1".into(),
                port: 1
            }
            .to_string(),
            "tcp://[::1]:1"
        );
    }

    #[test]
    fn rejects_bad_tcp_inputs() {
        assert!(matches!(
            "tcp://localhost".parse::<SourceSpec>(),
            Err(Error::TcpForm { .. })
        ));
        assert!(matches!(
            "tcp://localhost:0".parse::<SourceSpec>(),
            Err(Error::Port { .. })
        ));
        assert!(matches!(
            "tcp://localhost:99999".parse::<SourceSpec>(),
            Err(Error::Port { .. })
        ));
        assert!(matches!(
            "tcp://:80".parse::<SourceSpec>(),
            Err(Error::TcpForm { .. })
        ));
        assert!(matches!("".parse::<SourceSpec>(), Err(Error::Empty)));
    }
}
