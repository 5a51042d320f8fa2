//! Integration tests of `evtac-online`: one binary, one module per concern.

mod live;
mod pipeline;
mod replay;
mod support;
