//! The GPU backend of monolayer: the paper's whole fixed time step (docs/model.md §2–5) in
//! WGSL compute shaders, run through wgpu on Vulkan (any Vulkan device: an NVIDIA or AMD GPU,
//! or Mesa's CPU driver lavapipe, which CI tests on).
//!
//! [`GpuBackend`] implements [`mechanics::backend::Backend`]: hand it to
//! [`mechanics::Simulation::with_backend`] and the simulation's steps run on the device, while
//! outputs, checkpoints and schedules stay the driver's.
//!
//! ```no_run
//! use mechanics::prelude::*;
//! use phasefield::{init, Lattice, PatchShape};
//!
//! let lattice = Lattice::new(100, 100);
//! let shape = PatchShape::new(lattice, 16).unwrap();
//! let centres = init::positions(lattice, 40, 4.0, &init::Layout::Random { seed: 1 }).unwrap();
//! let cells = init::discs(lattice, shape, &centres, 4.0, 2.5).to_precision::<f32>();
//! let tissue = Tissue::new(cells, ModelParams::paper(0.0));
//! let step = StepParams::default();
//! let gpu = gpu::GpuBackend::new(&tissue, &step).expect("a Vulkan adapter");
//! let mut sim = Simulation::new(tissue, step).with_backend(Box::new(gpu)).stop_iteration(100);
//! sim.run().unwrap();
//! ```
//!
//! The layout of the step (buffers, kernels, dispatch order, how the sums are made
//! deterministic) is in ARCHITECTURE.md; [`Device`] finds the adapter, [`GpuBackend`] holds
//! the buffers and records the steps.

mod bindings;
mod device;
mod features;
mod kernels;
mod layout;
mod memory;
mod shader;
mod shared;
mod step;

pub use device::{adapter_info, Device, GpuError};
pub use features::{unsupported, SETTINGS, SUPPORTED};
pub use layout::GpuOptions;
pub use memory::GpuMemory;
pub use shader::Variant;
pub use shared::{Chunk, Kind, Params, MAX_KINDS};
pub use step::{Evaluation, GpuBackend};

/// The WGSL source of the step's kernels, with the constants of a patch shape and pressure
/// form filled in (for the tests that compare each equation with its Rust reference).
pub use shader::shader_source;
