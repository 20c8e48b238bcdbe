"""A sweep run point by point from Python, by a process pool, has the layout of
`monolayer sweep`: the command line collects its summary, and each point's run is the one the
command line's sweep writes, byte for byte."""

import multiprocessing
import pickle
import subprocess
from concurrent.futures import ProcessPoolExecutor

import monolayer as ml
from conftest import small_paper


def test_a_sweep_run_by_a_process_pool_is_the_command_lines_sweep(tmp_path, cli, root):
    scene = small_paper(root).set("run.time", 10.0)
    assert pickle.loads(pickle.dumps(scene)).to_toml() == scene.to_toml()
    points = list(ml.sweep(scene, {"model.zeta": [0.0, 0.005]}, seeds=range(1, 3), out=tmp_path / "py"))
    assert [p.name for p in points] == [
        "model.zeta=0_seed=1",
        "model.zeta=0_seed=2",
        "model.zeta=0.005_seed=1",
        "model.zeta=0.005_seed=2",
    ]
    # Spawned, not forked: a fork copies a process whose other threads (a simulation's pool,
    # a progress bar's monitor) may hold locks that no thread of the child will release.
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        list(pool.map(ml.run, [p.scene for p in points], [p.out for p in points], [False] * 4, [1] * 4, [False] * 4))
    o = subprocess.run([cli, "sweep", "--collect", "--out", str(tmp_path / "py")], capture_output=True, text=True)
    assert o.returncode == 0, o.stderr
    summary = (tmp_path / "py" / "summary.csv").read_text().splitlines()
    assert len(summary) == 5, summary
    # The command line's own sweep of the same points, typed as the README types them: the
    # two front ends name each point alike.
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(scene.to_toml())
    o = subprocess.run(
        [cli, "sweep", str(scene_file), "--vary", "model.zeta=0,0.005", "--seeds", "1-2", "--out", str(tmp_path / "cli"), "--quiet", "--jobs", "2"],
        capture_output=True,
        text=True,
    )
    assert o.returncode == 0, o.stderr
    for p in points:
        mine = (p.out / "series.csv").read_bytes()
        theirs = (tmp_path / "cli" / "runs" / p.name / "series.csv").read_bytes()
        assert mine == theirs, p.name
