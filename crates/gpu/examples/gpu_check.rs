//! The device check's measurements (`docs/gpu_check.sh run`), one subcommand each, each
//! printing one line of `key=value` pairs that the script appends to its results as it goes.
//!
//! ```text
//! gpu_check adapter                     the adapter wgpu chose, and its limits
//! gpu_check bandwidth MIB               device-to-device copy bandwidth (read + write)
//! gpu_check throughput N PART [STEPS] [VARIANT]
//!                                       seconds per step at N cells, PART = minimal, polarity,
//!                                       populations, walls, adhesion or division, in the
//!                                       kernels' VARIANT (plain, the default, or shared-patch)
//! gpu_check agree N STEPS               GPU against the CPU after STEPS steps
//! gpu_check determinism N STEPS         a hash of the state after STEPS steps, twice
//! gpu_check variants N STEPS            the shared-patch variant against the plain kernels
//! gpu_check hashes N STEPS              a hash of the state after STEPS steps for every part,
//!                                       variant and layout (one chunk and one lattice binding,
//!                                       or split): a change that must keep the bits compares
//!                                       these lines before and after
//! ```
//!
//! The scene is the paper's (`scenes/paper.toml`, embedded: nothing is read from disk),
//! scaled to N cells at its density (15 cells per 50², a square box of side
//! `L = ⌈√(N · 2500/15)⌉`), the cells placed hexagonally with the scene's initial discs, no
//! relaxation, ζ = 0.005, dt 0.2, Heun, f32. A scene the backend refuses prints
//! `refused="…"` with the reason, and exits 0: a refusal is a result.

use std::time::Instant;

use mechanics::backend::Backend;
use mechanics::Tissue;
use scene::Scene;

const PAPER: &str = include_str!("../../../scenes/paper.toml");

fn usage() -> ! {
    eprintln!(
        "usage: gpu_check adapter | bandwidth MIB | throughput N PART [STEPS] [VARIANT] | agree N STEPS | determinism N STEPS | variants N STEPS | hashes N STEPS"
    );
    std::process::exit(2)
}

fn arg<T: std::str::FromStr>(args: &[String], i: usize) -> T {
    args.get(i)
        .and_then(|a| a.parse().ok())
        .unwrap_or_else(|| usage())
}

/// The side of the square box that holds `n` cells at the paper's density.
fn side(n: usize) -> usize {
    (n as f64 * 2500.0 / 15.0).sqrt().ceil() as usize
}

/// The paper's scene at `n` cells with the extension `part` added (its own section).
fn scene(n: usize, part: &str) -> Result<Scene, String> {
    let l = side(n);
    let extra = match part {
        "minimal" => String::new(),
        "polarity" => "[polarity]\nalpha = 0.02\nrotational_diffusion = 4.5e-4\nalign = \"velocity\"\nalign_rate = 1.0\n".into(),
        "populations" => format!(
            "[[population]]\nname = \"a\"\ncount = {}\nzeta = 0.01\n\n[[population]]\nname = \"b\"\ncount = {}\nzeta = -0.01\n",
            n / 2,
            n - n / 2
        ),
        "walls" => "[walls]\nkind = \"channel\"\nthickness = 1.0\nkappa = 1.0\n".into(),
        "adhesion" => "[adhesion]\nomega = 0.0075\n".into(),
        "division" => format!(
            "[division]\ncycle_time = 300.0\ncycle_spread = 100.0\ngrowth_time = 50.0\nmax_cells = {}\n",
            2 * n
        ),
        // Division whose growth phase is under way from the start (for `hashes`).
        "growth" => format!(
            "[division]\ncycle_time = 40.0\ncycle_spread = 5.0\ngrowth_time = 39.0\nmax_cells = {}\n",
            2 * n
        ),
        other => return Err(format!("no part {other:?}")),
    };
    let text = format!("{PAPER}\n{extra}");
    let overrides = [
        format!("cells.count={n}"),
        format!("domain.lx={l}"),
        format!("domain.ly={l}"),
        "cells.init=\"hexagonal\"".to_string(),
        "integrator.dt=0.2".to_string(),
        "model.zeta=0.005".to_string(),
        "run.relax_time=0".to_string(),
    ];
    Scene::parse(&text, &overrides).map_err(|e| e.to_string())
}

fn tissue(n: usize, part: &str) -> Result<(Tissue<f32>, mechanics::StepParams), String> {
    let scene = scene(n, part)?;
    let mut t = scene.tissue::<f32>().map_err(|e| e.to_string())?;
    t.sort_cells(&mut Vec::new());
    Ok((t, scene.step_params()))
}

/// FNV-1a over the fields and the centres, as bytes.
fn hash(t: &Tissue<f32>) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    for v in t.cells().phi() {
        eat(&v.to_le_bytes());
    }
    for s in 0..t.n_cells() {
        for c in t.centres()[s] {
            eat(&c.to_le_bytes());
        }
    }
    h
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let line = match args.first().map(String::as_str) {
        Some("adapter") => adapter(),
        Some("bandwidth") => bandwidth(arg(&args, 1)),
        Some("throughput") => throughput(
            arg(&args, 1),
            args.get(2).map_or("minimal", String::as_str),
            args.get(3).map_or(20, |_| arg(&args, 3)),
            args.get(4)
                .map_or(Some(gpu::Variant::Plain), |v| gpu::Variant::from_name(v))
                .unwrap_or_else(|| usage()),
        ),
        Some("agree") => agree(arg(&args, 1), arg(&args, 2)),
        Some("determinism") => determinism(arg(&args, 1), arg(&args, 2)),
        Some("variants") => variants(arg(&args, 1), arg(&args, 2)),
        Some("hashes") => hashes(arg(&args, 1), arg(&args, 2)),
        _ => usage(),
    };
    match line {
        Ok(l) => println!("{l}"),
        Err(e) => {
            println!("{} error=\"{}\"", args.join(" "), e.replace('"', "'"));
            std::process::exit(1)
        }
    }
}

fn adapter() -> Result<String, String> {
    let d = gpu::Device::open().map_err(|e| e.to_string())?;
    Ok(format!(
        "check=adapter adapter=\"{}\" max_binding_bytes={}",
        d.describe(),
        d.max_binding()
    ))
}

fn bandwidth(mib: u64) -> Result<String, String> {
    let d = gpu::Device::open().map_err(|e| e.to_string())?;
    let gb_s = d.copy_bandwidth(mib << 20, 10).map_err(|e| e.to_string())?;
    Ok(format!(
        "check=bandwidth bytes={} copy_gb_s={gb_s:.1}",
        mib << 20
    ))
}

/// The backend for `t` in the kernels' `variant`, on a device of its own.
fn backend(
    t: &Tissue<f32>,
    sp: &mechanics::StepParams,
    variant: gpu::Variant,
) -> Result<gpu::GpuBackend, gpu::GpuError> {
    gpu::GpuBackend::check(t, sp)?;
    let options = gpu::GpuOptions {
        variant,
        ..Default::default()
    };
    gpu::GpuBackend::with_options(gpu::Device::open()?, t, sp, options)
}

fn throughput(n: usize, part: &str, steps: usize, variant: gpu::Variant) -> Result<String, String> {
    let head = format!(
        "check=throughput part={part} variant={} cells={n} lattice={}",
        variant.name(),
        side(n)
    );
    // A part the backend does not run is refused whatever the size: asked at 60 cells, so
    // that a refusal at 10⁶ does not cost the host a minute of building.
    if n > 60 {
        let (t, sp) = tissue(60, part)?;
        if let Err(e @ gpu::GpuError::Unsupported(_)) = gpu::GpuBackend::new(&t, &sp) {
            return Ok(format!(
                "{head} refused=\"{}\"",
                e.to_string().replace('"', "'")
            ));
        }
    }
    let t0 = Instant::now();
    let (mut t, sp) = tissue(n, part)?;
    let build = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let mut gpu = match backend(&t, &sp, variant) {
        Ok(g) => g,
        Err(
            e @ (gpu::GpuError::Unsupported(_)
            | gpu::GpuError::TooLarge(_)
            | gpu::GpuError::Setting(_)),
        ) => {
            return Ok(format!(
                "{head} refused=\"{}\"",
                e.to_string().replace('"', "'")
            ))
        }
        Err(e) => return Err(e.to_string()),
    };
    let upload = t0.elapsed().as_secs_f64();
    // Warm-up: pipelines compiled, caches and clocks up.
    for _ in 0..3 {
        gpu.step(&t, &sp).map_err(|e| e.to_string())?;
    }
    gpu.wait().map_err(|e| e.to_string())?;
    let t0 = Instant::now();
    for _ in 0..steps {
        gpu.step(&t, &sp).map_err(|e| e.to_string())?;
    }
    gpu.wait().map_err(|e| e.to_string())?;
    let per_step = t0.elapsed().as_secs_f64() / steps as f64;
    // The state is checked (a failed step reports here), so the timing is of real steps.
    gpu.sync(&mut t).map_err(|e| e.to_string())?;
    let rate = (n * t.cells().patch_len()) as f64 / per_step;
    Ok(format!(
        "{head} margin={} chunks={} steps={steps} s_per_step={per_step:.4e} node_updates_per_s={rate:.3e} bytes_per_node_update={:.1} build_s={build:.2} upload_s={upload:.2}",
        sp_margin(&t),
        gpu.n_chunks(),
        gpu.bytes_per_node_update(),
    ))
}

fn sp_margin(t: &Tissue<f32>) -> usize {
    t.cells().shape().margin.unwrap_or(0)
}

/// The largest difference of the fields and of the centres after `steps` steps, GPU (f32
/// arithmetic) against CPU (f32 storage, f64 arithmetic), with the bounds of the agreement
/// tests on lavapipe after 100 steps (`crates/gpu/tests/agreement.rs`: 1e-5 and 1e-4).
fn agree(n: usize, steps: usize) -> Result<String, String> {
    let (mut cpu, sp) = tissue(n, "minimal")?;
    let mut on_gpu = cpu.clone();
    let mut gpu = gpu::GpuBackend::new(&on_gpu, &sp).map_err(|e| e.to_string())?;
    let mut ws = mechanics::Workspace::new(cpu.cells());
    for _ in 0..steps {
        cpu.step(&mut ws, &sp).map_err(|e| e.to_string())?;
        gpu.step(&on_gpu, &sp).map_err(|e| e.to_string())?;
    }
    gpu.sync(&mut on_gpu).map_err(|e| e.to_string())?;
    let dphi = cpu
        .cells()
        .phi()
        .iter()
        .zip(on_gpu.cells().phi())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    let l = side(n) as f64;
    let dcentre = (0..n)
        .map(|s| {
            let (a, b) = (cpu.centres()[s], on_gpu.centres()[s]);
            (0..2)
                .map(|k| {
                    let d = (a[k] - b[k]).abs();
                    d.min(l - d)
                })
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    let ok = f64::from(dphi) <= 1e-5 && dcentre <= 1e-4;
    Ok(format!(
        "check=agree cells={n} steps={steps} max_dphi={dphi:.3e} max_dcentre={dcentre:.3e} bound_phi=1e-5 bound_centre=1e-4 agree={}",
        if ok { "yes" } else { "no" }
    ))
}

/// The state after `steps` steps on the device, hashed, for two runs from the same start.
fn determinism(n: usize, steps: usize) -> Result<String, String> {
    let (start, sp) = tissue(n, "minimal")?;
    let mut hashes = Vec::new();
    for _ in 0..2 {
        let mut t = start.clone();
        let mut gpu = gpu::GpuBackend::new(&t, &sp).map_err(|e| e.to_string())?;
        for _ in 0..steps {
            gpu.step(&t, &sp).map_err(|e| e.to_string())?;
        }
        gpu.sync(&mut t).map_err(|e| e.to_string())?;
        hashes.push(hash(&t));
    }
    Ok(format!(
        "check=determinism cells={n} steps={steps} hash_1={:016x} hash_2={:016x} identical={}",
        hashes[0],
        hashes[1],
        if hashes[0] == hashes[1] { "yes" } else { "no" }
    ))
}

/// The shared-patch variant against the plain kernels after `steps` steps from the same
/// state: the largest difference of the fields (bound 1e-5, the agreement's with the CPU), and
/// whether the states are the same bits (they are on lavapipe, where the two compute the same
/// arithmetic on the same values; a driver may contract a multiply and an add differently in
/// the two).
fn variants(n: usize, steps: usize) -> Result<String, String> {
    let (start, sp) = tissue(n, "minimal")?;
    let mut states = Vec::new();
    for variant in [gpu::Variant::Plain, gpu::Variant::SharedPatch] {
        let mut t = start.clone();
        let mut gpu = backend(&t, &sp, variant).map_err(|e| e.to_string())?;
        for _ in 0..steps {
            gpu.step(&t, &sp).map_err(|e| e.to_string())?;
        }
        gpu.sync(&mut t).map_err(|e| e.to_string())?;
        states.push(t);
    }
    let dphi = states[0]
        .cells()
        .phi()
        .iter()
        .zip(states[1].cells().phi())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    let (h0, h1) = (hash(&states[0]), hash(&states[1]));
    Ok(format!(
        "check=variants cells={n} steps={steps} max_dphi={dphi:.3e} bound_phi=1e-5 identical={} agree={}",
        if h0 == h1 { "yes" } else { "no" },
        if f64::from(dphi) <= 1e-5 { "yes" } else { "no" }
    ))
}

/// The state after `steps` steps for each part with each variant and layout, hashed: one line
/// a case, `part=… variant=… layout=… hash=…` (or the refusal).
fn hashes(n: usize, steps: usize) -> Result<String, String> {
    let mut lines = Vec::new();
    for part in [
        "minimal",
        "polarity",
        "populations",
        "walls",
        "adhesion",
        "division",
        "growth",
    ] {
        let (start, sp) = tissue(n, part)?;
        for variant in [gpu::Variant::Plain, gpu::Variant::SharedPatch] {
            for split in [false, true] {
                let options = gpu::GpuOptions {
                    variant,
                    max_chunk_cells: split.then_some(n.div_ceil(3)),
                    max_lattice_nodes: split.then_some(start.cells().lattice().len() / 2 + 7),
                };
                let mut t = start.clone();
                let head = format!(
                    "check=hashes part={part} variant={} layout={} cells={n} steps={steps}",
                    variant.name(),
                    if split { "split" } else { "whole" }
                );
                let dev = gpu::Device::open().map_err(|e| e.to_string())?;
                let mut gpu = match gpu::GpuBackend::with_options(dev, &t, &sp, options) {
                    Ok(g) => g,
                    Err(e) => {
                        lines.push(format!("{head} refused=\"{e}\""));
                        continue;
                    }
                };
                for _ in 0..steps {
                    gpu.step(&t, &sp).map_err(|e| e.to_string())?;
                }
                let obs = gpu.observables(&t).map_err(|e| e.to_string())?;
                gpu.sync(&mut t).map_err(|e| e.to_string())?;
                let v = obs.map_or(0, |o| o.v_rms.to_bits());
                lines.push(format!("{head} hash={:016x} v_rms={v:016x}", hash(&t)));
            }
        }
    }
    Ok(lines.join("\n"))
}
