//! The device for the GPU tests: whichever Vulkan adapter is present (lavapipe in CI).
//!
//! Without an adapter the tests say so and return, so that `cargo test` passes on a machine
//! with no Vulkan driver; with `MONOLAYER_GPU_REQUIRED=1` (set by `.ci/run`, which installs
//! lavapipe) a missing adapter fails them instead.

#![allow(dead_code)]

/// Whether a missing adapter is a failure (`MONOLAYER_GPU_REQUIRED=1`).
pub fn required() -> bool {
    std::env::var("MONOLAYER_GPU_REQUIRED").is_ok_and(|v| v == "1")
}

/// An open device, or `None` (after saying why) when there is none and none is required.
pub fn try_device() -> Option<gpu::Device> {
    match gpu::Device::open() {
        Ok(d) => Some(d),
        Err(e) if !required() => {
            eprintln!("skipped: {e} (set MONOLAYER_GPU_REQUIRED=1 to make this a failure)");
            None
        }
        Err(e) => panic!("MONOLAYER_GPU_REQUIRED=1 and {e}"),
    }
}

/// An open device; panics when there is none (for helpers called after [`try_device`]).
pub fn device() -> gpu::Device {
    gpu::Device::open().expect("a Vulkan adapter")
}
