//! The memory guard of every front end: a scene whose [`Scene::memory_estimate`] exceeds the
//! memory this process can still use is refused before anything is allocated, with the
//! estimate and the keys that change it. The command line (`monolayer run`, `sweep`) and
//! Python (`Simulation`, `monolayer.run`) call the same check, so that a run too large for
//! the machine is a clear error everywhere, never an abort in the allocator.

use scene::Scene;

/// A scene that would not fit: the message names the estimate, the limit and what to change.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct MemoryError {
    /// The refusal, with the keys to change.
    pub message: String,
    /// The estimate, in bytes.
    pub needed: f64,
    /// The limit, in bytes (zero where the allocator refused the estimate itself).
    pub limit: f64,
}

/// The memory this process can still use and what limits it: the smallest of the machine's
/// `MemAvailable`, the address-space and data-size limits (`ulimit -v`, `ulimit -d`) less what
/// the process already uses of them, and the memory limit of its cgroup and of each cgroup
/// above it (SLURM's `--mem`, a container's limit) less their usage. `None` where none can be
/// read.
pub fn memory_limit() -> Option<(f64, String)> {
    let mut best: Option<(f64, String)> = None;
    let mut consider = |bytes: Option<f64>, what: &str| {
        if let Some(b) = bytes {
            if best.as_ref().is_none_or(|(m, _)| b < *m) {
                best = Some((b.max(0.0), what.to_string()));
            }
        }
    };
    let meminfo = std::fs::read_to_string("/proc/meminfo").unwrap_or_default();
    consider(
        kib_field(&meminfo, "MemAvailable:"),
        "the memory available on this machine",
    );
    let limits = std::fs::read_to_string("/proc/self/limits").unwrap_or_default();
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let limit = |name: &str| -> Option<f64> {
        let line = limits.lines().find(|l| l.starts_with(name))?;
        line[name.len()..].split_whitespace().next()?.parse().ok()
    };
    if let (Some(max), Some(used)) = (limit("Max address space"), kib_field(&status, "VmSize:")) {
        consider(
            Some(max - used),
            "the address-space limit (ulimit -v) less what this process already uses",
        );
    }
    if let (Some(max), Some(used)) = (limit("Max data size"), kib_field(&status, "VmData:")) {
        consider(
            Some(max - used),
            "the data-size limit (ulimit -d) less what this process already uses",
        );
    }
    // The memory cgroup of this process and each one above it: cgroup v2 (mounted at
    // /sys/fs/cgroup, or at /sys/fs/cgroup/unified beside v1) and v1 (the memory controller).
    let cgroup = std::fs::read_to_string("/proc/self/cgroup").unwrap_or_default();
    let mut walk = |base: &str, path: &str, max: &str, used: &str| {
        let root = std::path::PathBuf::from(base);
        let mut dir = root.join(path.trim_start_matches('/'));
        loop {
            let read = |f: &str| -> Option<f64> {
                std::fs::read_to_string(dir.join(f))
                    .ok()?
                    .trim()
                    .parse()
                    .ok()
            };
            if let (Some(m), Some(u)) = (read(max), read(used)) {
                consider(
                    Some(m - u),
                    "the memory limit of this process's cgroup less its usage",
                );
            }
            if dir == root || !dir.pop() {
                break;
            }
        }
    };
    for line in cgroup.lines() {
        let mut parts = line.splitn(3, ':');
        let (_, controllers, path) = match (parts.next(), parts.next(), parts.next()) {
            (Some(a), Some(b), Some(c)) => (a, b, c),
            _ => continue,
        };
        if controllers.is_empty() {
            for base in ["/sys/fs/cgroup", "/sys/fs/cgroup/unified"] {
                walk(base, path, "memory.max", "memory.current");
            }
        } else if controllers.split(',').any(|c| c == "memory") {
            walk(
                "/sys/fs/cgroup/memory",
                path,
                "memory.limit_in_bytes",
                "memory.usage_in_bytes",
            );
        }
    }
    best
}

/// A `Name:   123 kB` field of a /proc file, in bytes.
fn kib_field(text: &str, name: &str) -> Option<f64> {
    let line = text.lines().find(|l| l.starts_with(name))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

fn gib(b: f64) -> String {
    if b >= 1024.0f64.powi(3) {
        format!("{:.1} GiB", b / 1024.0f64.powi(3))
    } else {
        format!("{:.0} MiB", b / 1024.0f64.powi(2))
    }
}

/// Refuses `runs` runs of `scene` at once when their [`Scene::memory_estimate`] exceeds
/// `limit` (bytes and what it is, such as `--max-memory 8G`), or by default the memory this
/// process can still use ([`memory_limit`]; no check where none can be read). `flag` is the
/// front end's way to give a larger limit (`--max-memory` on the command line).
///
/// # Errors
/// [`MemoryError`], naming the estimate, the limit and the keys that change it.
pub fn check_memory(
    scene: &Scene,
    runs: usize,
    limit: Option<(f64, String)>,
    flag: &str,
) -> Result<(), MemoryError> {
    let est = scene.memory_estimate() * runs.max(1) as f64;
    let Some((limit, what)) = limit.or_else(memory_limit) else {
        return reserve(scene, est);
    };
    if est > limit {
        let f = scene.file();
        let shape = scene.patch_shape();
        let f32_hint = match scene.precision() {
            mechanics::Precision::F64 => {
                ", use [integrator] precision = \"f32\" (half the field memory)"
            }
            mechanics::Precision::F32 => "",
        };
        let at_once = if runs > 1 {
            format!(", {runs} runs at a time (use a smaller --jobs)")
        } else {
            String::new()
        };
        let message = format!(
            "the run needs about {} ({} cell(s){} of {}×{} patch nodes on a {}×{} lattice{at_once}), more than {} ({what}); reduce {}, [domain] lx and ly or [integrator] margin{f32_hint}, or {flag}",
            gib(est),
            scene.max_cells(),
            if f.division.is_some() { " at most, [division] max_cells" } else { "" },
            shape.nx,
            shape.ny,
            f.domain.lx,
            f.domain.ly,
            gib(limit),
            if f.division.is_some() { "[division] max_cells" } else { "[cells] count" }
        );
        return Err(MemoryError {
            message,
            needed: est,
            limit,
        });
    }
    reserve(scene, est)
}

/// Asks the allocator once for the whole estimate and gives it back at once, so that a run
/// the limits allow but the allocator would refuse (a `--max-memory` above what the machine
/// has, the kernel's overcommit rule, an estimate that no limit could be read for) is this
/// error, and not an abort in the first large allocation after the run directory is written.
/// Nothing is touched: the pages are only mapped and unmapped, which takes microseconds.
fn reserve(scene: &Scene, est: f64) -> Result<(), MemoryError> {
    let bytes = est.ceil().min(isize::MAX as f64) as usize;
    if Vec::<u8>::new().try_reserve_exact(bytes).is_ok() {
        return Ok(());
    }
    Err(MemoryError {
        message: format!(
            "the run needs about {} ({} cell(s) on a {}×{} lattice), and the allocator refused that much memory; reduce [cells] count, [domain] lx and ly or [integrator] margin, or run it on a machine with more memory",
            gib(est),
            scene.max_cells(),
            scene.file().domain.lx,
            scene.file().domain.ly,
        ),
        needed: est,
        limit: 0.0,
    })
}
