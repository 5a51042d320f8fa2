//! Integration tests of `evtac-learn`: one binary, one module per concern.

mod bundle;
mod converges;
mod learns;
mod pytorch;
