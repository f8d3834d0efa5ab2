//! Criterion benchmarks of the closed forms: ns per evaluation (placeholder, filled below).
fn main() {}
