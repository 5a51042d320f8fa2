//! Which streams of an AEDAT4 file to read.
//!
//! A file may hold several streams of one kind: dv-processing's `StereoCameraWriter` records
//! two cameras, each with its own event (and IMU, trigger) stream, and their timestamps
//! interleave. Read as one stream, the two cameras' events would be mixed under one camera's
//! name and size, so a reader picks one stream of each kind ([`StreamSelection::resolve`]): the
//! one the user names (`--stream NAME|ID`, `--imu-stream`, `--trigger-stream`), else the only
//! one, else an error listing the streams. With several cameras, the IMU and trigger streams
//! default to those of the chosen event stream's camera (the same `source`).

use super::header::{AedatHeader, StreamInfo, StreamKind};
use crate::selection::{StreamChoice, StreamSelection};

impl StreamChoice {
    fn matches(&self, s: &StreamInfo) -> bool {
        match self {
            Self::Id(id) => s.id == *id,
            Self::Name(n) => {
                let (name, source) = (s.name.as_deref(), s.source.as_deref());
                name == Some(n)
                    || source == Some(n)
                    || matches!((source, name), (Some(src), Some(nm)) if *n == format!("{src}/{nm}"))
            }
        }
    }
}

/// The stream ids a selection resolved to (`None`: the file has no stream of that kind, or none
/// of the chosen camera's).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ChosenStreams {
    /// The event stream.
    pub events: Option<i32>,
    /// The IMU stream.
    pub imu: Option<i32>,
    /// The trigger stream.
    pub triggers: Option<i32>,
}

impl ChosenStreams {
    /// Whether stream `id` is one of the chosen.
    pub fn contains(&self, id: i32) -> bool {
        [self.events, self.imu, self.triggers].contains(&Some(id))
    }
}

/// A selection that does not pick exactly one stream of a kind.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{reason}; the file's streams are:\n{listing}")]
pub struct SelectionError {
    /// What went wrong, naming the flag that fixes it.
    pub reason: String,
    /// Every stream of the file, one per line ([`list_streams`]).
    pub listing: String,
}

/// One line per stream: id, type, name, camera, resolution.
pub fn list_streams(header: &AedatHeader) -> String {
    header
        .streams
        .iter()
        .map(|s| {
            let resolution = s.resolution.map(|r| format!(" {r}")).unwrap_or_default();
            format!(
                "  id {}: {} `{}` from {}{resolution}",
                s.id,
                s.type_identifier,
                s.name.as_deref().unwrap_or("-"),
                s.source.as_deref().unwrap_or("-"),
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

impl StreamSelection {
    /// Picks one stream of each kind from `header` (see the module docs).
    pub fn resolve(&self, header: &AedatHeader) -> Result<ChosenStreams, SelectionError> {
        let fail = |reason: String| SelectionError {
            reason,
            listing: list_streams(header),
        };
        let event_streams = header
            .streams
            .iter()
            .filter(|s| s.kind == StreamKind::Events)
            .count();
        let events = pick(
            header,
            &StreamKind::Events,
            self.events.as_ref(),
            None,
            "--stream",
        )
        .map_err(fail)?;
        // With several cameras, the other kinds follow the chosen camera.
        let camera = (event_streams > 1)
            .then(|| events.and_then(|id| header.stream(id)?.source.clone()))
            .flatten();
        let camera = camera.as_deref();
        let imu = pick(
            header,
            &StreamKind::Imu,
            self.imu.as_ref(),
            camera,
            "--imu-stream",
        )
        .map_err(fail)?;
        let triggers = pick(
            header,
            &StreamKind::Triggers,
            self.triggers.as_ref(),
            camera,
            "--trigger-stream",
        )
        .map_err(fail)?;
        Ok(ChosenStreams {
            events,
            imu,
            triggers,
        })
    }
}

fn kind_name(kind: &StreamKind) -> &'static str {
    match kind {
        StreamKind::Events => "event",
        StreamKind::Imu => "IMU",
        StreamKind::Triggers => "trigger",
        _ => "other",
    }
}

/// The one stream of `kind` that `choice` names, else the only one (of `camera`'s, when given).
fn pick(
    header: &AedatHeader,
    kind: &StreamKind,
    choice: Option<&StreamChoice>,
    camera: Option<&str>,
    flag: &str,
) -> Result<Option<i32>, String> {
    let what = kind_name(kind);
    let of_kind = header.streams.iter().filter(|s| &s.kind == kind);
    let candidates: Vec<&StreamInfo> = match choice {
        Some(c) => of_kind.filter(|s| c.matches(s)).collect(),
        None => of_kind
            .filter(|s| camera.is_none() || s.source.as_deref() == camera)
            .collect(),
    };
    match (candidates.as_slice(), choice) {
        ([one], _) => Ok(Some(one.id)),
        ([], None) => Ok(None),
        ([], Some(c)) => Err(format!("{flag} {c}: no {what} stream has that id or name")),
        (_, Some(c)) => Err(format!(
            "{flag} {c}: {} {what} streams have that name; name one by its id",
            candidates.len()
        )),
        (_, None) => Err(format!(
            "the file has {} {what} streams{}: pick one with {flag} NAME|ID",
            candidates.len(),
            camera.map(|c| format!(" from {c}")).unwrap_or_default()
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Resolution;
    use crate::aedat::Compression;

    fn stream(id: i32, kind: StreamKind, name: &str, source: &str) -> StreamInfo {
        let type_identifier = match kind {
            StreamKind::Events => "EVTS",
            StreamKind::Imu => "IMUS",
            StreamKind::Triggers => "TRIG",
            _ => "FRME",
        };
        StreamInfo {
            id,
            type_identifier: type_identifier.into(),
            resolution: (kind == StreamKind::Events).then_some(Resolution::new(640, 480)),
            kind,
            name: Some(name.into()),
            source: Some(source.into()),
        }
    }

    fn header(streams: Vec<StreamInfo>) -> AedatHeader {
        AedatHeader {
            compression: Compression::Lz4,
            data_table_position: None,
            streams,
            description: String::new(),
        }
    }

    fn stereo() -> AedatHeader {
        header(vec![
            stream(0, StreamKind::Events, "events", "left_cam"),
            stream(1, StreamKind::Imu, "imu", "left_cam"),
            stream(2, StreamKind::Events, "events", "right_cam"),
            stream(3, StreamKind::Imu, "imu", "right_cam"),
            stream(4, StreamKind::Triggers, "triggers", "right_cam"),
        ])
    }

    #[test]
    fn the_only_stream_of_each_kind_is_the_default() {
        let h = header(vec![
            stream(0, StreamKind::Events, "events", "cam"),
            stream(1, StreamKind::Frames, "frames", "cam"),
            stream(2, StreamKind::Imu, "imu", "cam"),
        ]);
        let chosen = StreamSelection::default().resolve(&h).unwrap();
        assert_eq!(
            chosen,
            ChosenStreams {
                events: Some(0),
                imu: Some(2),
                triggers: None
            }
        );
    }

    #[test]
    fn several_cameras_need_a_choice_and_the_error_lists_the_streams() {
        let err = StreamSelection::default().resolve(&stereo()).unwrap_err();
        assert!(err.reason.contains("2 event streams"), "{err}");
        assert!(err.reason.contains("--stream"), "{err}");
        assert!(
            err.to_string()
                .contains("id 2: EVTS `events` from right_cam 640x480"),
            "{err}"
        );
    }

    #[test]
    fn a_camera_chosen_by_name_or_id_brings_its_own_imu_and_triggers() {
        for choice in ["right_cam", "2", "right_cam/events"] {
            let sel = StreamSelection {
                events: Some(choice.parse().unwrap()),
                ..Default::default()
            };
            let chosen = sel.resolve(&stereo()).unwrap();
            assert_eq!(
                chosen,
                ChosenStreams {
                    events: Some(2),
                    imu: Some(3),
                    triggers: Some(4)
                },
                "{choice}"
            );
        }
        let left = StreamSelection {
            events: Some(StreamChoice::Id(0)),
            ..Default::default()
        };
        let chosen = left.resolve(&stereo()).unwrap();
        assert_eq!((chosen.imu, chosen.triggers), (Some(1), None));
    }

    #[test]
    fn an_ambiguous_or_unknown_name_is_an_error() {
        let sel = StreamSelection {
            events: Some("events".parse().unwrap()),
            ..Default::default()
        };
        let err = sel.resolve(&stereo()).unwrap_err();
        assert!(
            err.reason.contains("2 event streams have that name"),
            "{err}"
        );
        let sel = StreamSelection {
            events: Some(StreamChoice::Id(1)),
            ..Default::default()
        };
        let err = sel.resolve(&stereo()).unwrap_err();
        assert!(err.reason.contains("--stream 1: no event stream"), "{err}");
    }
}
