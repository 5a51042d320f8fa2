//! Integration tests of `evtac-online`: one binary, one module per concern.

mod live;
mod pipeline;
mod processing;
mod replay;
mod ros2;
mod support;
