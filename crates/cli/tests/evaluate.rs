//! Tests of `evtac evaluate`.
