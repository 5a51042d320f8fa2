//! Integration tests of the simulator: one test binary, one module per concern.

mod behaviour;
mod dataset;
mod docs_table;
