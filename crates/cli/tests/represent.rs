//! Tests of `evtac represent`.
