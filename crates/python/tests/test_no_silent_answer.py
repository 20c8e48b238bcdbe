"""Issue 53 from Python: a run that goes bad is an error with the last good state, no abort
whatever the input, and Python's own types and errors (each test failed on the main of
2026-12-06)."""

import re
import threading
import warnings
from pathlib import Path

import numpy as np
import pytest

import monolayer as ml
from conftest import single, small_paper


def blowing_up(root):
    """The paper's small scene without line tension, forward Euler at dt 0.5: it blows up
    within a few hundred steps (nothing smooths the interfaces)."""
    return small_paper(root).update(
        {
            "model.gamma": 0.0,
            "model.zeta": 0.01,
            "integrator.npc": 0,
            "integrator.dt": 0.5,
            "integrator.stability_check": False,
            "run.relax_time": 0.0,
            "run.time": 2000.0,
        }
    )


def blow_up_step(root):
    """The step that blows up, read from the error of a run past it."""
    sim = ml.Simulation(blowing_up(root), threads=1)
    with pytest.raises(RuntimeError) as e:
        sim.step(4000)
    m = re.findall(r"at step (\d+)", str(e.value))
    assert m, str(e.value)
    return int(m[-1]), sim


def test_a_blow_up_in_the_last_step_raises_and_keeps_the_last_good_state(root):
    n, after_error = blow_up_step(root)
    # After an error the state is the last good one: finite, one step before the blow-up.
    assert after_error.iteration == n - 1
    phi, _, _ = after_error.phi()
    assert np.isfinite(phi).all() and phi.max() <= 3.0 and phi.min() >= -2.0
    # The blow-up as the last step of a call is an error too (it returned on main).
    sim = ml.Simulation(blowing_up(root), threads=1)
    sim.step(n - 1)
    with pytest.raises(RuntimeError, match=f"at step {n} "):
        sim.step(1)
    assert sim.iteration == n - 1
    assert np.isfinite(sim.phi()[0]).all()
    assert np.array_equal(sim.phi()[0], phi)


def test_run_until_between_two_steps_says_where_it_stopped():
    sim = ml.Simulation(single(), threads=1)
    with pytest.warns(UserWarning, match=r"stops at t = 1.5 \(step 3\).*dt = 0.5"):
        sim.run(until=1.2, progress=False)
    assert sim.time == pytest.approx(1.5)
    # On a multiple of dt: no warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.run(until=2.0, progress=False)
    assert sim.iteration == 4


@pytest.mark.parametrize("n", [-1, 2**64 - 1, 2**70])
def test_a_step_count_out_of_range_is_a_value_error_that_names_it(n):
    sim = ml.Simulation(single(), threads=1)
    with pytest.raises(ValueError, match=r"step\(n\): n = .*give a whole number from 0 to"):
        sim.step(n)
    assert sim.iteration == 0


def test_numpy_scalars_are_taken_as_their_python_types():
    sim = ml.Simulation(single(), threads=1)
    sim.step(np.int64(2))
    assert sim.iteration == 2
    with pytest.raises(TypeError, match="whole number"):
        sim.step(1.5)
    s = single().set("cells.count", np.int64(1)).set("integrator.stability_check", np.bool_(False))
    s = s.set("model.zeta", np.float64(0.001)).set("integrator.margin", np.int32(16))
    text = s.to_toml()
    assert "count = 1\n" in text and "stability_check = false" in text
    ml.Simulation(s, threads=np.int64(1)).step(1)
    sim.add_callback(lambda o: None, steps=np.int64(2))


def test_an_edit_goes_through_the_scene_validation():
    sim = ml.Simulation(single(), threads=1)
    for name, value in [("xi", -1.0), ("mu", -1.0), ("gamma", -0.5)]:
        with pytest.raises(ValueError, match=f"model.{name}"):
            sim.edit(lambda e: e.set_param(name, value))
    # Nothing was applied; a valid edit still is.
    sim.edit(lambda e: e.set_param("zeta", 0.002))
    sim.step(1)


def test_a_callback_that_calls_its_own_simulation_is_told_what_to_do_instead():
    sim = ml.Simulation(single(), threads=1)
    sim.add_callback(lambda obs: sim.cells, steps=1)
    with pytest.raises(RuntimeError, match="is stepping.*obs.cells"):
        sim.step(2)
    # The simulation is usable after.
    assert sim.iteration >= 0
    sim2 = ml.Simulation(single(), threads=1)
    sim2.add_force(lambda t, c: (sim2.step(1), np.zeros((len(c["x"]), 2)))[1])
    with pytest.raises(RuntimeError, match="is stepping"):
        sim2.step(1)


def test_two_threads_that_share_a_simulation_are_told_to_take_turns(root):
    sim = ml.Simulation(small_paper(root).set("run.time", 4000.0), threads=1)
    started = threading.Event()
    sim.add_callback(lambda o: started.set(), steps=1)
    t = threading.Thread(target=lambda: sim.step(400))
    t.start()
    started.wait(60)
    with pytest.raises(RuntimeError, match="take turns"):
        sim.cells
    t.join()


def test_gpu_scenes_are_refused_by_name(tmp_path):
    with pytest.raises(ValueError, match="backend"):
        ml.Simulation(single().set("integrator.backend", "gpu"))


def test_a_scene_too_large_for_memory_is_a_memory_error_and_writes_nothing(tmp_path):
    # About 10¹¹ bytes: more than any machine this runs on has free.
    huge = ml.Scene.from_dict(
        {
            "domain": {"lx": 40000, "ly": 40000},
            "cells": {"count": 2000000, "radius": 8.0},
            "integrator": {"precision": "f64"},
            "run": {"time": 1.0},
        }
    )
    with pytest.raises(MemoryError, match=r"needs about .*reduce \[cells\] count"):
        ml.Simulation(huge, threads=1)
    out = tmp_path / "never"
    with pytest.raises(MemoryError):
        ml.run(huge, out, progress=False)
    assert not out.exists()


def test_a_refused_run_leaves_no_directory(root, tmp_path):
    # threads = 0 was refused only after the directory held run.json and scene.toml.
    out = tmp_path / "never"
    with pytest.raises(ValueError, match="threads = 0"):
        ml.run(small_paper(root), out, threads=0, progress=False)
    assert not out.exists()


def test_a_sweep_names_its_points_as_the_command_line_and_refuses_a_comma(tmp_path):
    names = [p.name for p in ml.sweep(single(), {"model.zeta": [0.0, 0.005]}, None, None)]
    # As `monolayer sweep --vary model.zeta=0,0.005` names them (not `model.zeta=0.0`).
    assert names == ["model.zeta=0_seed=1", "model.zeta=0.005_seed=1"], names
    with pytest.raises(ValueError, match="holds a ','"):
        list(ml.sweep(single(), {"cells.init": ["a,b"]}, None, None))
