"""What stepping from Python costs against the command line, and what a force written in Python
costs per step, measured side by side (issue 39).

Usage, from the repository's root, with the package installed (`pip install ./crates/python`)
and the binary built (`cargo build --release`):

    python3 docs/python_cost.py [--repeats 5] [--threads 2]

For the paper's scene (60 cells, 100²) and the large one (960 cells, 400²), each shortened to a
fixed number of steps with frames and series at the same intervals, it alternates:
  cli   `monolayer run SCENE --out DIR` (wall time of the process; "cli start" is the same
        with `run.time = 0`: the process, the initial tissue and its frame),
  run   `monolayer.run(scene, out=DIR)` (the same run directory, from Python),
  sim   `Simulation(scene).run()` (in memory, no files),
  force `Simulation(scene)` with a NumPy force `f = -k (r - r0)` added, `.run()`,
and prints the median wall time of each, the overheads against the CLI and the cost of the
force per step, with the CPU model and the load average.
"""

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import monolayer as ml

ROOT = Path(__file__).resolve().parents[1]
BIN = os.environ.get("MONOLAYER_BIN", str(ROOT / "target" / "release" / "monolayer"))

CASES = {
    # name: (scene file, overrides)
    "60 cells": ("paper.toml", {"run.relax_time": 0.0, "run.time": 200.0, "run.output_every": 50.0, "run.series_every": 5.0}),
    "960 cells": ("large.toml", {"run.relax_time": 0.0, "run.time": 20.0, "run.output_every": 10.0, "run.series_every": 5.0}),
}


def cpu_model() -> str:
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def main() -> None:
    a = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    a.add_argument("--repeats", type=int, default=5)
    a.add_argument("--threads", type=int, default=2)
    args = a.parse_args()
    print(f"CPU: {cpu_model()}, {os.cpu_count()} cores; load before: {os.getloadavg()[0]:.2f}")
    tmp = Path(tempfile.mkdtemp())
    for name, (file, sets) in CASES.items():
        scene = ml.Scene.from_toml(ROOT / "scenes" / file).update(sets)
        steps = round(scene.end_time / 0.2)
        cli_sets = [x for k, v in sets.items() for x in ("--set", f"{k}={v}")]

        def cli():
            out = tmp / "cli"
            t = time.perf_counter()
            subprocess.run([BIN, "run", str(ROOT / "scenes" / file), "--out", str(out), "--overwrite", "--quiet",
                            "--threads", str(args.threads), *cli_sets], check=True)
            return time.perf_counter() - t

        def start():
            out = tmp / "cli0"
            t = time.perf_counter()
            subprocess.run([BIN, "run", str(ROOT / "scenes" / file), "--out", str(out), "--overwrite", "--quiet",
                            "--threads", str(args.threads), *cli_sets, "--set", "run.time=0"], check=True)
            return time.perf_counter() - t

        def run():
            out = tmp / "py"
            shutil.rmtree(out, ignore_errors=True)
            t = time.perf_counter()
            ml.run(scene, out, threads=args.threads, progress=False)
            return time.perf_counter() - t

        def sim(force=False):
            s = ml.Simulation(scene, threads=args.threads)
            if force:
                mid = np.array([50.0, 50.0])
                s.add_force(lambda t, c: -1e-4 * (np.c_[c["x"], c["y"]] - mid))
            t = time.perf_counter()
            s.run(progress=False)
            return time.perf_counter() - t

        kinds = {"cli": cli, "cli start": start, "run": run, "sim": sim, "force": lambda: sim(True)}
        times = {k: [] for k in kinds}
        for _ in range(args.repeats):
            for k, f in kinds.items():
                times[k].append(f())
        med = {k: statistics.median(v) for k, v in times.items()}
        print(f"\n{name} ({file}, {steps} steps, {args.threads} threads), medians of {args.repeats}:")
        for k, v in times.items():
            print(f"  {k:9s} {med[k]:8.3f} s   [{', '.join(f'{x:.3f}' for x in v)}]")
        print(f"  monolayer.run against the CLI's run: {100 * (med['run'] / med['cli'] - 1):+.1f} %")
        print(f"  Simulation.run (no files) against the CLI's run: {100 * (med['sim'] / med['cli'] - 1):+.1f} %")
        print(f"  a NumPy force: {1e3 * (med['force'] - med['sim']) / steps:.3f} ms per step "
              f"({100 * (med['force'] / med['sim'] - 1):+.1f} %)")
    print(f"\nload after: {os.getloadavg()[0]:.2f}")
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
