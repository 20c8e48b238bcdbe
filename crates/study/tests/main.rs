//! Sweeps and damaged frames end to end: one test executable, a module per topic.

mod damaged_frames;
mod dummy_part;
mod render_state;
mod sweep;
