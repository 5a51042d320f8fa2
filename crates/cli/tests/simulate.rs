//! Tests of `evtac simulate`.
