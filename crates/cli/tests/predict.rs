//! Tests of `evtac predict`.
