//! Where events come from: a file, a live DV network stream, a ROS 2 topic, or standard input.
//!
//! A [`SourceSpec`] is what the user typed (`--input`); it is parsed once, up front, so that a
//! typo in `tcp://host:port` or a ROS 2 topic name is reported before any model is loaded.

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
    /// A ROS 2 topic of events (`ros2:///event_camera/events`), subscribed to over DDS.
    Ros2 {
        /// The ROS 2 topic, absolute (`/event_camera/events`).
        topic: String,
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
    /// A `ros2://` input whose topic name ROS 2 would refuse.
    #[error(
        "input `{input}`: {source} (the form is ros2:///TOPIC, e.g. ros2:///event_camera/events)"
    )]
    Ros2Topic {
        /// The input as given.
        input: String,
        /// What is wrong with the name.
        #[source]
        source: crate::ros2::Error,
    },
    /// An empty input string.
    #[error(
        "the input is empty (give a file path, tcp://HOST:PORT, ros2:///TOPIC, or - for standard \
         input)"
    )]
    Empty,
}

impl std::str::FromStr for SourceSpec {
    type Err = Error;

    /// Parses `-` (standard input), `tcp://HOST:PORT` (IPv6 hosts in brackets, `tcp://[::1]:7777`),
    /// `ros2:///TOPIC` (`ros2://TOPIC` too: ROS 2 topics are absolute here) or a file path.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.is_empty() {
            return Err(Error::Empty);
        }
        if s == "-" {
            return Ok(Self::Stdin);
        }
        if let Some(rest) = s.strip_prefix("ros2://") {
            let topic = format!("/{}", rest.trim_start_matches('/'));
            crate::ros2::dds_topic_name(&topic).map_err(|source| Error::Ros2Topic {
                input: s.to_string(),
                source,
            })?;
            return Ok(Self::Ros2 { topic });
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
            Self::Ros2 { topic } => write!(f, "ros2://{topic}"),
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

    #[test]
    fn ros2_topics_are_absolute_and_checked() {
        for input in ["ros2:///event_camera/events", "ros2://event_camera/events"] {
            let spec = input.parse::<SourceSpec>().unwrap();
            assert_eq!(
                spec,
                SourceSpec::Ros2 {
                    topic: "/event_camera/events".into()
                },
                "{input}"
            );
            assert_eq!(spec.to_string(), "ros2:///event_camera/events");
        }
        for bad in [
            "ros2://",
            "ros2:///",
            "ros2:///cam/",
            "ros2:///cam-0/events",
        ] {
            let e = bad.parse::<SourceSpec>().unwrap_err().to_string();
            assert!(
                e.contains(&format!("input `{bad}`")) && e.contains("invalid ROS 2 topic name"),
                "{bad}: {e}"
            );
        }
    }
}
