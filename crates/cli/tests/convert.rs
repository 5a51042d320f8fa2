//! Tests of `evtac convert`.
