//! The README of monolayer, whose Rust examples run as this crate's doc tests (from the
//! repository's root, where the README's paths start), and one crate that re-exports the
//! workspace's libraries for users who want a single dependency.
#![doc = include_str!("../README.md")]

pub use analysis;
pub use mechanics;
pub use phasefield;
pub use render;
pub use rundir;
pub use scene;
pub use study;
