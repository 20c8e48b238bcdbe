//! One integration-test binary for the whole workspace, with topical modules.

mod analysis_tests;
mod guard_tests;
mod mechanics_tests;
mod module_graph;
mod patch_tests;
mod phasefield_tests;
mod regression;
mod simulation_tests;
mod strategies;
mod terms_tests;
