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

/// The memory this process can still use and what limits it ([`rundir::memory::memory_limit`]).
pub fn memory_limit() -> Option<(f64, String)> {
    rundir::memory::memory_limit()
}

/// Refuses a scene whose [`Scene::memory_estimate`] exceeds `--max-memory`, or by default the
/// memory available now, with the estimate and the keys that change it.
///
/// # Errors
/// The refusal, or a `--max-memory` that does not parse.
pub fn memory(scene: &Scene, max_memory: Option<&str>) -> Result<()> {
    memory_of(scene, 1, max_memory)
}

/// [`memory`] for `runs` such scenes at once (a sweep's `--jobs`): the check every front end
/// shares ([`rundir::memory::check_memory`]).
///
/// # Errors
/// As [`memory`].
pub fn memory_of(scene: &Scene, runs: usize, max_memory: Option<&str>) -> Result<()> {
    rundir::memory::check_memory(scene, runs, limit(max_memory)?, MORE_MEMORY)?;
    Ok(())
}

/// How the command line raises the memory limit, for the guard's message.
pub const MORE_MEMORY: &str = "give a larger --max-memory";

/// The limit `--max-memory` gives, with its name for messages (`None`: the memory this
/// process can use).
///
/// # Errors
/// A `--max-memory` that does not parse.
pub fn limit(max_memory: Option<&str>) -> Result<Option<(f64, String)>> {
    Ok(match max_memory {
        Some(m) => Some((parse_bytes(m)?, format!("--max-memory {m}"))),
        None => None,
    })
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
