//! Integration tests of `evtac-labels`: one test binary, one module per concern.

mod dataset;
mod degenerate;
mod pipeline;
mod real;
mod simulated;
mod synthetic;
