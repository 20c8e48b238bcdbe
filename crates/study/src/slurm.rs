//! The SLURM backend of a sweep: a job-array script with one array task per pending point,
//! each running `monolayer run` on that point's resolved scene. `summary.csv` is then built
//! from the finished runs with [`crate::write_summary`] (`monolayer sweep --collect`).

use std::path::{Path, PathBuf};

use crate::plan::Point;
use crate::sweep::{pending, prepare_point, COMPLETE};
use crate::SweepError;

/// What [`write_job_array`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct JobArray {
    /// The `sbatch` script.
    pub script: PathBuf,
    /// The number of array tasks (pending points); 0 writes no script.
    pub tasks: usize,
}

/// Prepares every pending point of `points` in `dir` (its run directory and resolved
/// `scene.toml`), lists them in `dir/slurm/points.txt`, and writes `dir/slurm/sweep.sbatch`:
/// a job array of one task per pending point, each with `threads` CPUs, running
/// `BINARY run RUN/scene.toml --out RUN --overwrite --threads THREADS --quiet` and then marking
/// the run complete. Task logs go to `dir/slurm/TASK.out`.
///
/// `binary` must be an absolute path that the compute nodes see.
///
/// # Errors
/// When a file cannot be written.
pub fn write_job_array(
    dir: &Path,
    points: &[Point],
    binary: &Path,
    threads: usize,
) -> Result<JobArray, SweepError> {
    let (todo, _) = pending(dir, points);
    let slurm = dir.join("slurm");
    let io = |path: &Path, source| SweepError::write("slurm", path, source);
    std::fs::create_dir_all(&slurm).map_err(|e| io(&slurm, e))?;
    let script = slurm.join("sweep.sbatch");
    let mut list = String::new();
    for p in &todo {
        // A point stopped in an earlier submission keeps its checkpoint: its task resumes.
        let out = if rundir::RunDir::resumable(&crate::sweep::run_dir(dir, p), &p.scene) {
            crate::sweep::run_dir(dir, p)
        } else {
            prepare_point(dir, p)?
        };
        list += &absolute(&out).display().to_string();
        list += "\n";
    }
    let points_txt = slurm.join("points.txt");
    std::fs::write(&points_txt, &list).map_err(|e| io(&points_txt, e))?;
    if todo.is_empty() {
        let _ = std::fs::remove_file(&script);
        return Ok(JobArray { script, tasks: 0 });
    }
    let text = format!(
        "#!/bin/bash\n\
         # A monolayer sweep: one array task per run directory listed in points.txt.\n\
         # Submit with `sbatch {script}`; when all tasks are done, build summary.csv with\n\
         # `monolayer sweep ... --out {dir} --collect` (the same arguments as the sweep).\n\
         #SBATCH --job-name=monolayer-sweep\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --cpus-per-task={threads}\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --output={logs}/%a.out\n\
         # SIGTERM to this script two minutes before the time limit; the run stops after its\n\
         # step with a checkpoint, and the task is requeued and resumes from it.\n\
         #SBATCH --signal=B:TERM@120\n\
         #SBATCH --requeue\n\
         #SBATCH --open-mode=append\n\
         set -uo pipefail\n\
         run=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" {points})\n\
         if cmp -s \"$run/scene.toml\" \"$run/{COMPLETE}\"; then exit 0; fi\n\
         if compgen -G \"$run/checkpoints/checkpoint_*.npz\" >/dev/null; then\n\
         \x20   {binary} run --resume \"$run\" --threads {threads} --quiet &\n\
         else\n\
         \x20   {binary} run \"$run/scene.toml\" --out \"$run\" --overwrite --threads {threads} --quiet &\n\
         fi\n\
         pid=$!\n\
         trap 'kill -TERM $pid' TERM\n\
         wait $pid; rc=$?\n\
         # A trapped signal interrupts `wait`: wait again for the run to write its checkpoint.\n\
         while kill -0 $pid 2>/dev/null; do wait $pid; rc=$?; done\n\
         if [ $rc -eq 143 ]; then\n\
         \x20   scontrol requeue \"${{SLURM_ARRAY_JOB_ID}}_${{SLURM_ARRAY_TASK_ID}}\"\n\
         \x20   exit 0\n\
         fi\n\
         exit $rc\n",
        script = absolute(&script).display(),
        dir = absolute(dir).display(),
        last = todo.len() - 1,
        logs = absolute(&slurm).display(),
        points = absolute(&points_txt).display(),
        binary = binary.display(),
    );
    std::fs::write(&script, text).map_err(|e| io(&script, e))?;
    Ok(JobArray {
        script,
        tasks: todo.len(),
    })
}

fn absolute(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}
