//! Pictures on synthetic data: one test executable, a module per topic.

mod pictures;
mod tissue;
