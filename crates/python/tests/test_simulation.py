"""The simulation stepped from Python: the lock released, Ctrl-C, every error with its
exception and message, memory over many snapshots and callbacks, edits."""

import asyncio
import os
import resource
import signal
import threading
import time

import numpy as np
import pytest

import monolayer as ml
from conftest import single, small_paper


def test_the_lock_is_released_while_the_simulation_steps(root):
    sim = ml.Simulation(small_paper(root).set("run.time", 400.0), threads=1)
    ticks = []
    running = threading.Event()

    def stepper():
        running.set()
        sim.run(progress=False)

    t = threading.Thread(target=stepper)
    t.start()
    running.wait()
    while t.is_alive():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    t.join()
    # The main thread ran Python all along: hundreds of ticks, none more than 0.2 s apart
    # (with the lock held through the run, there would be one or two).
    assert len(ticks) > 50, len(ticks)
    assert max(np.diff(ticks)) < 0.2
    assert sim.time == pytest.approx(sim.scene.end_time)


def ctrl_c_after(steps, n):
    """Sends a real SIGINT once `steps` holds `n` entries (a daemon with a deadline, so that a
    run failing early leaves nothing waiting)."""

    def send():
        deadline = time.monotonic() + 300
        while len(steps) < n:
            if time.monotonic() > deadline:
                return
            time.sleep(0.001)
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=send, daemon=True).start()


def test_ctrl_c_raises_after_a_whole_step_and_the_simulation_goes_on(root):
    # Long enough that the signal comes mid-run on a slow machine too.
    scene = small_paper(root).set("run.time", 4000.0)
    sim = ml.Simulation(scene, threads=1)
    steps = []
    sim.add_callback(lambda o: steps.append(o.iteration), steps=1)
    ctrl_c_after(steps, 30)
    with pytest.raises(KeyboardInterrupt):
        sim.run(progress=False)
    stopped = sim.iteration
    assert 30 <= stopped < 20_050
    assert sim.time == pytest.approx(stopped * 0.2, abs=1e-9), "a whole step"
    assert steps[-1] == stopped, "the callbacks of the last step ran"
    # It goes on, 100 steps past the stop, and stopping changed nothing: the same state as a
    # run to that time in one go.
    until = (stopped + 100) * 0.2
    sim.run(until=until, progress=False)
    assert sim.iteration == stopped + 100
    again = ml.Simulation(scene, threads=1).run(until=until, progress=False)
    assert again.iteration == stopped + 100
    assert np.array_equal(sim.phi()[0], again.phi()[0])


def test_ctrl_c_still_stops_a_run_after_something_else_set_the_handler(root):
    # asyncio.run (on which Jupyter's kernels run) sets SIGINT's handler and puts Python's
    # back, as any library may: the process's handler is then Python's alone. A handler of
    # ours installed once, for good, was gone from then on, and Ctrl-C came only after the run.
    sim = ml.Simulation(small_paper(root).set("run.time", 4000.0), threads=1)
    sim.step(1)
    asyncio.run(asyncio.sleep(0))
    signal.signal(signal.SIGINT, signal.default_int_handler)
    steps = []
    sim.add_callback(lambda o: steps.append(o.iteration), steps=1)
    ctrl_c_after(steps, 30)
    with pytest.raises(KeyboardInterrupt):
        sim.run(progress=False)
    assert 30 <= sim.iteration < 20_000, "stopped mid-run"
    # Python's handler is back in place after the run.
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


@pytest.mark.parametrize(
    "make, exc, says",
    [
        (lambda r: ml.Scene.from_toml(r / "scenes" / "nope.toml"), OSError, "cannot read scene file"),
        (lambda r: ml.Scene.from_toml(r / "scenes" / "paper.toml").set("model.zeta", "a lot"), ValueError, "model.zeta takes a number"),
        (lambda r: ml.Scene.from_toml(r / "scenes" / "paper.toml").set("domain.lx", 4), ValueError, "lx"),
        (lambda r: ml.Scene.from_toml(r / "scenes" / "paper.toml").set("model.nope", 1), ValueError, "nope"),
        (lambda r: ml.Scene.from_toml(r / "scenes" / "paper.toml").set("model.zeta", object()), TypeError, "not a scene value"),
        (lambda r: ml.Scene.from_dict({"domain": {"lx": 64}}), ValueError, "ly"),
        (lambda r: ml.Simulation(single(), threads=0), ValueError, "threads = 0"),
        (lambda r: ml.Simulation(single(), backend="gpu"), ValueError, "without the GPU backend"),
        (lambda r: ml.Simulation(single(), backend="tpu"), ValueError, "use \"cpu\""),
        (lambda r: ml.Simulation(single()).render(colour="plaid"), ValueError, "colour plaid: use none"),
        (lambda r: ml.Simulation(single()).render(shiny=True), ValueError, "no option \"shiny\""),
        (lambda r: ml.Simulation(single()).edit(lambda e: e.set_param("zeat", 1.0)), ValueError, "no such parameter"),
        (lambda r: ml.Simulation(single()).edit(lambda e: e.set_state("polarity.theta", [0.0])), ValueError, "no per-cell state"),
        (lambda r: ml.Simulation(single()).add_callback(print, every=1.0, steps=2), ValueError, "not both"),
        (lambda r: ml.Run.open(r / "scenes"), FileNotFoundError, "not a run directory"),
        (lambda r: list(ml.sweep(single(), {"model.zeta": [1, 1]})), ValueError, "repeated"),
        (lambda r: list(ml.sweep(single(), {"model.zeta": [0.1]}, seeds=[1, 3])), ValueError, "consecutive"),
        (lambda r: ml.resume(r / "scenes"), FileNotFoundError, "not a run directory"),
    ],
)
def test_every_error_has_its_exception_and_the_command_lines_message(root, make, exc, says):
    with pytest.raises(exc) as e:
        make(root)
    assert says in str(e.value)


def test_errors_inside_a_run_are_raised_and_leave_a_state_that_goes_on(tmp_path, root):
    sim = ml.Simulation(single(), threads=1)
    sim.step(2)

    class Boom(Exception):
        pass

    def bad(t, c):
        raise Boom("from the force")

    sim.add_force(bad, name="bad")
    with pytest.raises(Boom, match="from the force"):
        sim.step(5)
    assert sim.iteration == 2, "stopped before the step, at the last good state"
    # Raised in Heun's corrector (the step's second call): the same, and the state is the
    # step's start to the bit.
    sim5 = ml.Simulation(single(), threads=1)
    sim5.step(2)
    before = sim5.phi()[0].copy()
    calls = []

    def second(t, c):
        calls.append(t)
        if len(calls) == 2:
            raise Boom("in the corrector")
        return np.zeros((len(c["id"]), 2))

    sim5.add_force(second, name="second")
    with pytest.raises(Boom, match="in the corrector"):
        sim5.step(1)
    assert len(calls) == 2 and sim5.iteration == 2
    assert np.array_equal(sim5.phi()[0], before)
    sim5.step(1)
    assert sim5.iteration == 3, "and it goes on"
    # A force of the wrong shape, and a non-finite one.
    sim2 = ml.Simulation(single(), threads=1)
    sim2.add_force(lambda t, c: np.zeros((3, 2)))
    with pytest.raises(ValueError, match=r"shape \(1, 2\)"):
        sim2.step(1)
    sim3 = ml.Simulation(single(), threads=1)
    sim3.add_force(lambda t, c: np.full((1, 2), np.nan))
    with pytest.raises(ValueError, match="not finite"):
        sim3.step(1)
    # A callback's exception stops the run after its step.
    sim4 = ml.Simulation(single(), threads=1)

    def cb(o):
        if o.iteration == 3:
            raise KeyError("at 3")

    sim4.add_callback(cb)
    with pytest.raises(KeyError, match="at 3"):
        sim4.step(10)
    assert sim4.iteration == 3
    sim4.step(2)
    assert sim4.iteration == 5
    # Writing into a run directory that is there.
    ml.run(single(run__time=1.0), tmp_path / "r", progress=False)
    with pytest.raises(OSError, match="overwrite"):
        ml.run(single(run__time=1.0), tmp_path / "r", progress=False)


def rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def test_memory_stays_flat_over_many_snapshots_and_callbacks():
    sim = ml.Simulation(single(), threads=1)
    seen = []
    sim.add_callback(lambda o: seen.append(o.cells["x"][0]) if len(seen) < 1 else None)

    def churn(k):
        for _ in range(k):
            c = sim.cells
            assert c["x"].flags.writeable is False
        sim.step(k)

    churn(1000)
    before = rss_mb()
    churn(10_000)
    after = rss_mb()
    # 10⁴ snapshots of 13 columns and 10⁴ callbacks with their cells' dicts; a leak of one
    # dict (about 1 kB) per call would show as 20 MB.
    assert after - before < 4.0, f"{before:.1f} -> {after:.1f} MB"
    assert sim.iteration == 11_000


def test_snapshots_do_not_change_when_the_simulation_steps():
    sim = ml.Simulation(single(), threads=1)
    sim.add_force(lambda t, c: np.c_[0.04 + 0 * c["x"], 0 * c["y"]])
    sim.step(5)
    c, (phi, origin, ids), f = sim.cells, sim.phi(), sim.fields()
    kept = {k: v.copy() for k, v in c.items()}
    phi0 = phi.copy()
    sim.step(20)
    assert all(np.array_equal(c[k], kept[k]) for k in c)
    assert np.array_equal(phi, phi0)
    assert not sim.cells["x"][0] == kept["x"][0], "the state moved"
    with pytest.raises(ValueError):
        c["x"][0] = 1.0
    assert f["phi_sum"].shape == (64, 64) and f["velocity"].shape == (64, 64, 2)


def test_an_edit_changes_the_parameters_as_a_fix_would(root):
    scene = small_paper(root)
    a = ml.Simulation(scene, threads=1)
    a.edit(lambda e: e.set_param("zeta", 0.0))
    a.add_fix(lambda e: e.set_param("zeta", 0.0))  # the activity switch would set ζ again
    a.run(progress=False)
    b = ml.Simulation(scene.copy().set("model.zeta", 0.0), threads=1).run(progress=False)
    assert np.array_equal(a.phi()[0], b.phi()[0])
    c = ml.Simulation(scene, threads=1).run(progress=False)
    assert not np.array_equal(a.phi()[0], c.phi()[0]), "the edit made a difference"


def test_adhesion_by_pair_of_populations_is_a_scene_key(root):
    """`[adhesion] pairs` (issue 49) from Python: set as a nested list, run, and refused with
    the pair named when it is not symmetric or not one row per population."""
    text = (root / "scenes" / "sorting.toml").read_text()
    scene = (
        ml.Scene.from_text(text)
        .set("run.relax_time", 0.0)
        .set("run.time", 2.0)
        .set("adhesion.pairs", [[0.006, 0.0], [0.0, 0.003]])
    )
    assert "pairs" in scene.to_toml()
    sim = ml.Simulation(scene, threads=1)
    sim.run(progress=False)
    with pytest.raises(ValueError, match="a–b.*symmetric"):
        scene.set("adhesion.pairs", [[0.006, 0.001], [0.0, 0.0]])
    with pytest.raises(ValueError, match="one row of 2 values"):
        scene.set("adhesion.pairs", [[0.006]])


def test_repulsion_by_pair_of_populations_is_a_scene_key(root):
    """`[repulsion] pairs` (issue 49) from Python: set as a nested list, run, and refused with
    the pair named when it is not symmetric."""
    text = (root / "scenes" / "sorting.toml").read_text()
    scene = (
        ml.Scene.from_text(text)
        .set("run.relax_time", 0.0)
        .set("run.time", 2.0)
        .set("repulsion.pairs", [[0.1, 0.3], [0.3, 0.1]])
    )
    assert "[repulsion]" in scene.to_toml()
    ml.Simulation(scene, threads=1).run(progress=False)
    with pytest.raises(ValueError, match="repulsion.*symmetric"):
        scene.set("repulsion.pairs", [[0.1, 0.3], [0.2, 0.1]])


def test_the_cell_nematic_is_a_scene_key_with_columns(root):
    """`[nematic]` (issue 49) from Python: its keys are set like any other, each cell's axis
    and tensor are columns of `sim.cells`, and a bad key is refused by name."""
    text = (root / "scenes" / "nematic.toml").read_text()
    scene = (
        ml.Scene.from_text(text)
        .set("run.relax_time", 0.0)
        .set("run.time", 2.0)
        .set("nematic.zeta", -0.01)
        .set("nematic.angle", 0.25)
    )
    sim = ml.Simulation(scene, threads=1)
    cells = sim.cells
    assert np.allclose(cells["nematic.theta"], 0.25)
    # The tensor's components xx and xy.
    assert np.allclose(cells["nematic.x"], np.cos(0.5))
    assert np.allclose(cells["nematic.y"], np.sin(0.5))
    # The cells' nematic field M = Σφ_i q_i before any step: every axis at 0.25, so M is
    # along 2θ = 0.5 wherever there is tissue, in proportion to Σφ_i.
    fields = sim.fields()
    m, phi = fields["M"], fields["phi_sum"]
    assert m.shape == (100, 100, 2)
    tissue = phi > 0.5
    assert tissue.sum() > 1000
    assert np.allclose(np.arctan2(m[..., 1], m[..., 0])[tissue], 0.5, atol=1e-6)
    ratio = np.hypot(m[..., 0], m[..., 1])[tissue] / phi[tissue]
    assert np.allclose(ratio, ratio[0], rtol=1e-5)
    sim.run(progress=False)
    assert sim.cells["fx"].shape == (60,)
    # The director and defects of M (director_of="nematic") are not those of the shapes' Q.
    of_m = sim.render(director=True, defects=True, director_of="nematic")
    of_q = sim.render(director=True, defects=True)
    assert of_m.size == of_q.size and of_m.png != of_q.png
    with pytest.raises(ValueError, match=r"director_of plaid"):
        sim.render(director=True, director_of="plaid")
    plain = ml.Simulation(single())
    with pytest.raises(ValueError, match=r"no \[nematic\]"):
        plain.render(director=True, director_of="nematic")
    with pytest.raises(ValueError, match=r"\[nematic\].*elastic"):
        scene.set("nematic.elastic", -1.0)


def test_the_forces_by_origin_are_columns_of_the_cells(root):
    """With `[run] forces_by_origin` (issue 49), `sim.cells` has each cell's force by origin,
    and the parts add up to the interface force plus the terms' force (1e-12 of the largest)."""
    text = (root / "scenes" / "nematic.toml").read_text()
    scene = (
        ml.Scene.from_text(text)
        .set("run.relax_time", 0.0)
        .set("run.time", 2.0)
        .set("model.zeta", 0.005)
        .set("run.forces_by_origin", True)
    )
    sim = ml.Simulation(scene, threads=1)
    sim.run(progress=False)
    cells = sim.cells
    parts = ["pressure", "shape_activity", "nematic_activity"]
    for axis in ["x", "y"]:
        total = cells["f" + axis] + cells["cell_f" + axis]
        summed = sum(cells[f"force.{p}.{axis}"] for p in parts)
        size = max(np.abs(cells[f"force.{p}.{axis}"]).max() for p in parts)
        assert np.abs(summed - total).max() < 1e-12 * size
    plain = ml.Simulation(scene.set("run.forces_by_origin", False), threads=1)
    assert not any(k.startswith("force.") for k in plain.cells)
