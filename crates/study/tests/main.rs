//! Sweeps and damaged frames end to end, and the module graph: one test executable, a module
//! per topic.

mod damaged_frames;
mod module_graph;
mod sweep;
