//! The `monolayer` binary end to end: one test executable (one link), a module per topic.

mod adaptive;
mod adhesion;
mod cli;
mod common;
mod division;
mod docs;
mod forces;
mod from_state;
mod gpu;
mod hostile;
mod nematic;
mod resume_all;
mod signals;
mod terms;
mod view;
mod walls;
