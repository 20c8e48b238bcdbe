//! # monolayer-cli
//!
//! The `monolayer` command, a thin layer over `phasefield` and `mechanics`:
//! [`scene`] reads and validates scene files, [`run`] drives a simulation and [`output`]
//! writes what it produces. Only this crate touches the filesystem.
#![deny(missing_docs)]

pub mod output;
pub mod run;
pub mod scene;
