//! Tests of `evtac online`.
