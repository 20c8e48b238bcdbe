//! # monolayer-cli
//!
//! The `monolayer` command, a thin layer over the libraries: the `scene` crate reads and
//! validates scene files and builds the simulation; [`run`] adds the run directory's output
//! writers and a progress report to it, [`output`] writes (and reads back) what a run
//! produces, and [`analyze`] turns a run into the paper's quantities. Only this crate touches
//! the filesystem or prints.
#![deny(missing_docs)]

pub mod analyze;
pub mod output;
pub mod run;
