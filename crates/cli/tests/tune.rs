//! Tests of `evtac tune`.
