//! Workspace-level integration tests of monolayer live in `main.rs` and its modules; this
//! library is empty and exists only so that the package has a target besides the tests.
