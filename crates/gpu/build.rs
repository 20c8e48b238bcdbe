//! Whether a Vulkan driver is installed where the loader looks for one (an ICD manifest,
//! `*.json`, in `/usr/share/vulkan/icd.d` and its siblings), read when the tests are built.
//! Without one (and without `VK_ICD_FILENAMES`, `VK_DRIVER_FILES` or
//! `MONOLAYER_GPU_REQUIRED=1`), the cfg `no_vulkan_driver` marks the GPU tests ignored, with the
//! reason, so that the test command's count says they did not run: they would otherwise
//! pass by returning early. With a driver they run, and skip at run time only when it
//! offers no adapter. (`crates/cli` builds with this script too, for its `gpu::` tests.)

use std::path::Path;

const ICD_DIRS: [&str; 4] = [
    "/usr/share/vulkan/icd.d",
    "/usr/local/share/vulkan/icd.d",
    "/etc/vulkan/icd.d",
    "/usr/share/vulkan/implicit_layer.d",
];

fn main() {
    println!("cargo::rustc-check-cfg=cfg(no_vulkan_driver)");
    for v in [
        "VK_ICD_FILENAMES",
        "VK_DRIVER_FILES",
        "MONOLAYER_GPU_REQUIRED",
    ] {
        println!("cargo::rerun-if-env-changed={v}");
    }
    // Watch the nearest directory that exists (a path that does not would rerun this script,
    // and rebuild the crate, on every build): installing a driver creates or changes it.
    for d in &ICD_DIRS[..3] {
        let mut p = Path::new(d);
        while !p.exists() {
            match p.parent() {
                Some(q) => p = q,
                None => break,
            }
        }
        println!("cargo::rerun-if-changed={}", p.display());
    }
    let set = |v: &str| std::env::var(v).is_ok_and(|s| !s.is_empty());
    let required = std::env::var("MONOLAYER_GPU_REQUIRED").is_ok_and(|v| v == "1");
    let found = ICD_DIRS[..3].iter().any(|d| {
        std::fs::read_dir(d).is_ok_and(|r| {
            r.flatten()
                .any(|e| e.path().extension().is_some_and(|x| x == "json"))
        })
    });
    if !(required || found || set("VK_ICD_FILENAMES") || set("VK_DRIVER_FILES")) {
        println!("cargo::rustc-cfg=no_vulkan_driver");
    }
}
