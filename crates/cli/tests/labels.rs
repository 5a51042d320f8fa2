//! Tests of `evtac labels`.
