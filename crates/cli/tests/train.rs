//! Tests of `evtac train`.
