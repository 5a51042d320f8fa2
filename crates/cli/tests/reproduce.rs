//! Tests of `evtac reproduce`.
