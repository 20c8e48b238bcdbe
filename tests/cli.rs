//! The `monolayer` binary end to end.
