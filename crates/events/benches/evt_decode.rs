//! Decoding throughput benchmark (being built).
fn main() {}
