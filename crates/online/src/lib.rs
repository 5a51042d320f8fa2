//! Online contact-angle estimation from live or replayed event streams.
