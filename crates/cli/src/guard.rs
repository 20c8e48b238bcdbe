//! Guards before work: a scene that would not fit in memory, and a thread count beyond the
//! machine, are caught before anything is allocated or started.

use anyhow::{bail, Result};
use scene::Scene;

/// Bytes from `8G`, `512M`, `64K`, `1.5G` or a plain number of bytes.
///
/// # Errors
/// A message naming the flag and the accepted forms.
pub fn parse_bytes(s: &str) -> Result<f64> {
    let t = s.trim();
    let (num, mult) = match t.char_indices().last() {
        Some((i, c)) if c.eq_ignore_ascii_case(&'k') => (&t[..i], 1024.0),
        Some((i, c)) if c.eq_ignore_ascii_case(&'m') => (&t[..i], 1024.0 * 1024.0),
        Some((i, c)) if c.eq_ignore_ascii_case(&'g') => (&t[..i], 1024.0f64.powi(3)),
        Some((i, c)) if c.eq_ignore_ascii_case(&'t') => (&t[..i], 1024.0f64.powi(4)),
        _ => (t, 1.0),
    };
    match num.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v * mult),
        _ => bail!("--max-memory {s}: give a size such as 8G, 512M or 1073741824 (bytes)"),
    }
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

/// Refuses a scene whose [`Scene::memory_estimate`] exceeds `--max-memory`, or by default the
/// memory available now, with the estimate and the keys that change it.
///
/// # Errors
/// The refusal, or a `--max-memory` that does not parse.
pub fn memory(scene: &Scene, max_memory: Option<&str>) -> Result<()> {
    memory_of(scene, 1, max_memory)
}

/// [`memory`] for `runs` such scenes at once (a sweep's `--jobs`).
///
/// # Errors
/// As [`memory`].
pub fn memory_of(scene: &Scene, runs: usize, max_memory: Option<&str>) -> Result<()> {
    let (limit, what) = match max_memory {
        Some(m) => (parse_bytes(m)?, format!("--max-memory {m}")),
        None => match memory_limit() {
            Some(limit) => limit,
            None => return Ok(()),
        },
    };
    let est = scene.memory_estimate() * runs.max(1) as f64;
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
        bail!(
            "the run needs about {} ({} cell(s){} of {}×{} patch nodes on a {}×{} lattice{at_once}), more than {} ({what}); reduce {}, [domain] lx and ly or [integrator] margin{f32_hint}, or give a larger --max-memory",
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
    }
    Ok(())
}

/// The thread count to use for `--threads n`: at least 1, and at most the machine's cores
/// (more only time-slice the same cores; results do not depend on the count).
///
/// # Errors
/// `--threads 0`.
pub fn threads(n: usize) -> Result<usize> {
    if n == 0 {
        bail!("--threads must be at least 1");
    }
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    if n > cores {
        crate::say!("note: --threads {n} capped at the {cores} cores of this machine (results do not depend on it)");
        return Ok(cores);
    }
    Ok(n)
}
