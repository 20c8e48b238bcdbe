//! # monolayer-cli
//!
//! The `monolayer` command, a thin layer over the libraries: the `scene` crate reads and
//! validates scene files and builds the simulation, the `rundir` crate writes (and reads
//! back) the files of a run directory; [`run`] runs a scene with a progress report,
//! [`sweep`] runs a scene over a grid of values and seeds (the `study` crate), [`reproduce`]
//! makes the paper's figures with a verdict on each claim,
//! `study::analyze` turns a run into the paper's quantities, and [`view`] reports the
//! progress of `study::view`'s pictures and ParaView files. Only this crate prints.
#![deny(missing_docs)]

/// Writes a line to stderr like `eprintln!`, but ignores a stderr that went away (a closed
/// pipe, a terminal that hung up), where `eprintln!` would panic: losing a message must not
/// change how a run ends.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

pub mod backend;
pub mod guard;
pub mod lines;
pub mod reproduce;
pub mod run;
pub mod sweep;
pub mod view;
