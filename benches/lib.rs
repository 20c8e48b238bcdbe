//! Criterion benchmarks of monolayer live in `step.rs`; this library is empty.
