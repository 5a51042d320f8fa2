//! Tests of `evtac info`.
