"""A scene run from Python writes what the command line writes, byte for byte; an in-memory
simulation ends where the command line's run ends; a run stopped by Ctrl-C resumes to the
same bytes."""

import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import monolayer as ml
from conftest import SMALL, small_paper


def files(d: Path):
    """series.csv and every frame of a run directory, by name."""
    out = {"series.csv": (d / "series.csv").read_bytes()}
    for f in sorted((d / "frames").glob("*.npz")):
        out[f.name] = f.read_bytes()
    return out


def cli_run(cli, root, out, threads="2"):
    sets = [a for k, v in SMALL.items() for a in ("--set", f"{k}={v}")]
    subprocess.run(
        [cli, "run", str(root / "scenes" / "paper.toml"), "--out", str(out), "--quiet", "--threads", threads, *sets],
        check=True,
    )


def test_a_run_from_python_writes_the_command_lines_bytes(tmp_path, cli, root):
    cli_run(cli, root, tmp_path / "cli")
    r = ml.run(small_paper(root), tmp_path / "py", threads=1, progress=False)
    want, got = files(tmp_path / "cli"), files(r.path)
    assert list(got) == list(want) and len(want) == 5
    for name in want:
        assert got[name] == want[name], name
    assert r.complete
    # The reader: the series as a table, the frames lazily.
    s = r.series
    assert list(s["time"])[-1] == pytest.approx(30.0)
    assert r.frames.steps[-1] == 150 and r.frames[-1]["centre"].shape == (15, 2)


def test_an_in_memory_simulation_ends_where_the_command_line_ends(tmp_path, cli, root):
    cli_run(cli, root, tmp_path / "cli", threads="1")
    sim = ml.Simulation(small_paper(root), threads=2).run(progress=False)
    last = ml.Run.open(tmp_path / "cli").frames[-1]
    c = sim.cells
    assert np.array_equal(c["id"], last["id"])
    assert np.array_equal(np.c_[c["x"], c["y"]], last["centre"])
    assert np.array_equal(np.c_[c["vx"], c["vy"]], last["velocity"])
    phi, origin, ids = sim.phi()
    assert np.array_equal(phi, last["phi"]) and np.array_equal(origin, last["origin"])


def test_ctrl_c_stops_a_run_directory_with_a_checkpoint_and_it_resumes_to_the_same_bytes(tmp_path, cli, root):
    cli_run(cli, root, tmp_path / "cli")
    scene = small_paper(root).set("run.time", 2000.0)
    # The uninterrupted run of the longer scene, from Python.
    full = ml.run(scene, tmp_path / "full", threads=1, progress=False)
    frames = tmp_path / "stopped" / "frames"

    def ctrl_c():
        # A real SIGINT, as a terminal's Ctrl-C or Jupyter's interrupt sends, once the run
        # has written its third frame (20 TU in).
        # (A daemon with a deadline: a run that fails early must not leave it waiting.)
        deadline = time.monotonic() + 300
        while len(list(frames.glob("*.npz"))) < 3:
            if time.monotonic() > deadline:
                return
            time.sleep(0.005)
        os.kill(os.getpid(), signal.SIGINT)

    watcher = threading.Thread(target=ctrl_c, daemon=True)
    watcher.start()
    with pytest.raises(KeyboardInterrupt) as e:
        ml.run(scene, tmp_path / "stopped", threads=1, progress=False)
    watcher.join()
    # Python's own handler raised it (its message is empty).
    assert isinstance(e.value, KeyboardInterrupt)
    stopped = ml.Run.open(tmp_path / "stopped")
    assert not stopped.complete
    assert list((tmp_path / "stopped" / "checkpoints").glob("*.npz")), "a checkpoint at the stop"
    r = ml.resume(tmp_path / "stopped", threads=2, progress=False)
    assert r.complete
    assert files(r.path) == files(full.path)
