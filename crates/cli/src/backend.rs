//! `[integrator] backend`: where a run's steps go. The GPU backend (the `gpu` crate, wgpu on
//! Vulkan) is compiled in with the `gpu` cargo feature, so that the default build stays free
//! of wgpu's compile time; a binary without it refuses `backend = "gpu"` with the command
//! that builds one.

use anyhow::Result;
use mechanics::Simulation;
use phasefield::Real;
use scene::{ComputeBackend, Scene};

/// An opened device, taken before the run directory is prepared, so that a missing adapter
/// is an error before any output is touched.
pub struct Opened {
    #[cfg(feature = "gpu")]
    device: Option<gpu::Device>,
}

impl Opened {
    /// The adapter a GPU run will use, in words (`None` for a CPU run).
    pub fn describe(&self) -> Option<String> {
        #[cfg(feature = "gpu")]
        {
            self.device.as_ref().map(gpu::Device::describe)
        }
        #[cfg(not(feature = "gpu"))]
        {
            None
        }
    }
}

/// Opens what `scene`'s backend needs: nothing for the CPU, the Vulkan adapter for the GPU.
///
/// # Errors
/// `backend = "gpu"` in a binary built without the `gpu` feature, or no usable adapter.
pub fn open(scene: &Scene) -> Result<Opened> {
    match scene.backend() {
        ComputeBackend::Cpu => Ok(Opened {
            #[cfg(feature = "gpu")]
            device: None,
        }),
        ComputeBackend::Gpu => open_gpu(scene),
    }
}

/// Refuses what `scene`'s backend cannot run, before anything is opened or written: for the
/// GPU, the parts of the model it does not declare (`gpu::SUPPORTED`), or a binary built
/// without it.
///
/// # Errors
/// Naming each part with its scene table, and the fix.
pub fn check(scene: &Scene) -> Result<()> {
    match scene.backend() {
        ComputeBackend::Cpu => Ok(()),
        ComputeBackend::Gpu => check_gpu(scene),
    }
}

#[cfg(not(feature = "gpu"))]
fn check_gpu(scene: &Scene) -> Result<()> {
    open_gpu(scene).map(|_| ())
}

#[cfg(feature = "gpu")]
fn check_gpu(scene: &Scene) -> Result<()> {
    let unsupported = gpu::unsupported(
        &scene.configured_extensions(),
        &scene.model_params(scene.zeta()),
    );
    if !unsupported.is_empty() {
        anyhow::bail!(
            "[integrator] backend = \"gpu\": the GPU backend does not run {} yet; remove them from the scene to run on the GPU, or set backend = \"cpu\"",
            unsupported.join(", ")
        );
    }
    let kinds = scene.populations().kinds().len();
    if kinds > gpu::MAX_KINDS {
        anyhow::bail!(
            "[integrator] backend = \"gpu\": the GPU backend holds at most {} populations, and [[population]] has {kinds}; merge some [[population]] tables, or set backend = \"cpu\"",
            gpu::MAX_KINDS
        );
    }
    Ok(())
}

/// What the GPU's buffers for `[division] max_cells` cost, said before it is paid: the
/// backend allocates every per-cell buffer for the most cells the clock allows at the start
/// (its buffers do not grow), which for a `max_cells` far above the cells present is device
/// memory and start-up time the run may never use (`max_cells = 100000` with 8 cells took
/// 80 s to start on lavapipe, against 0.35 s at the count). `None` when it is at most 4× the
/// cells present, or the scene has no division.
#[cfg(feature = "gpu")]
pub fn gpu_capacity_note(scene: &Scene) -> Option<String> {
    let f = scene.file();
    f.division.as_ref()?;
    let (now, most) = (f.cells.count, scene.max_cells());
    if most <= 4 * now.max(1) {
        return None;
    }
    let parts = scene.parts();
    let npc = f.integrator.npc;
    let gb = |n: usize| {
        gpu::GpuMemory::estimate(scene.lattice(), &scene.patch_shape(), n, npc, &parts).total as f64
            / 1e9
    };
    Some(format!(
        "the GPU backend allocates its buffers for [division] max_cells = {most} cells at the start (they do not grow as the tissue does): about {:.2} GB of device memory, against {:.2} GB for the {now} cells present, and a start-up that grows with it; set max_cells to the most cells the run needs",
        gb(most),
        gb(now)
    ))
}

#[cfg(feature = "gpu")]
fn open_gpu(scene: &Scene) -> Result<Opened> {
    check_gpu(scene)?;
    if let Some(note) = gpu_capacity_note(scene) {
        crate::say!("note: {note}");
    }
    let device =
        gpu::Device::open().map_err(|e| anyhow::anyhow!("[integrator] backend = \"gpu\": {e}"))?;
    Ok(Opened {
        device: Some(device),
    })
}

#[cfg(not(feature = "gpu"))]
fn open_gpu(_scene: &Scene) -> Result<Opened> {
    anyhow::bail!(
        "[integrator] backend = \"gpu\": this monolayer binary was built without the GPU backend; \
         build one with `cargo build --release -p monolayer-cli --features gpu` (it needs a Vulkan \
         driver at run time: `apt-get install mesa-vulkan-drivers libvulkan1` for the CPU driver, \
         or the GPU vendor's), or set backend = \"cpu\""
    )
}

/// `sim` with its steps on the opened device (unchanged for the CPU).
///
/// # Errors
/// What the GPU backend refuses in the state (its memory estimate above the device's, say).
pub fn attach<T: Real>(sim: Simulation<T>, opened: Opened) -> Result<Simulation<T>> {
    #[cfg(feature = "gpu")]
    if let Some(device) = opened.device {
        let backend = gpu::GpuBackend::on(device, sim.tissue(), sim.step_params())
            .map_err(|e| anyhow::anyhow!("[integrator] backend = \"gpu\": {e}"))?;
        return Ok(sim.with_backend(Box::new(backend)));
    }
    #[cfg(not(feature = "gpu"))]
    let _ = opened;
    Ok(sim)
}
