//! Integration tests of `evtac-online`: one binary, one module per concern.

mod dense;
mod frames;
mod live;
mod mcap_log;
mod pipeline;
mod processing;
mod replay;
mod ros2;
mod support;
