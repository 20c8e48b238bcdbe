//! # monolayer-cli
//!
//! The `monolayer` command, a thin layer over `phasefield` and `mechanics`:
//! [`scene`] reads and validates scene files, [`run`] drives a simulation, [`output`]
//! writes (and reads back) what it produces, and [`analyze`] turns a run into the paper's
//! quantities. Only this crate touches the filesystem.
#![deny(missing_docs)]

pub mod analyze;
pub mod output;
pub mod run;
pub mod scene;
