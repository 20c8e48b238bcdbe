"""Forces written in Python: a constant force moves an isolated cell at F/ξ (to the accuracy of
the Rust test of self-propulsion), a harmonic trap holds a cell with the stiffness it was
given, Heun's two stages integrate a force that depends on position to second order, and the
result does not depend on the thread count."""

import numpy as np
import pytest

import monolayer as ml
from conftest import single

XI = 2.0  # the paper's friction (scene default)


def relaxed(**sets):
    """One paper cell relaxed at rest for 100 TU (as the Rust test)."""
    sim = ml.Simulation(single(**sets), threads=1)
    sim.run(until=100.0, progress=False)
    return sim


def const(fx, fy=0.0):
    return lambda t, c: np.column_stack([np.full(len(c["x"]), fx), np.full(len(c["x"]), fy)])


def test_a_constant_force_moves_an_isolated_cell_at_f_over_xi():
    # As crates/mechanics/src/terms/tests.rs: the velocity is F/ξ to round-off, the centre
    # moves 1.83 % slower at the interface width λ = 2.5 (the central differences'
    # dispersion), below 2.5 % asserted there and here; 50 TU to start, 100 TU measured.
    sim = relaxed(run__time=400.0)
    sim.add_force(const(0.04))
    sim.run(until=150.0, progress=False)
    x0 = sim.cells["x"][0]
    sim.run(until=250.0, progress=False)
    c = sim.cells
    v = (c["x"][0] - x0) / 100.0
    assert abs(c["vx"][0] - 0.04 / XI) < 1e-9 and abs(c["fx"][0]) < 1e-9
    assert c["cell_fx"][0] == 0.04
    assert abs(c["y"][0] - 32.0) < 1e-9
    err = 1 - v / (0.04 / XI)
    assert 0 < err < 0.025, err


def trap(k, x0, y0, push=0.0):
    def f(t, c):
        return np.column_stack([-k * (c["x"] - x0) + push, -k * (c["y"] - y0)])

    return f


def test_a_harmonic_trap_holds_a_cell_with_its_stiffness():
    # A trap of stiffness k at x0 and a push F: the cell settles at x0 + F/k (the interface
    # force of an isolated cell vanishes, so the balance is exact: measured 7e-5 off),
    # approached as exp(−k t/ξ).
    k, push = 0.02, 0.01
    sim = relaxed(run__time=2000.0)
    x_start = sim.cells["x"][0]
    sim.add_force(trap(k, x_start, 32.0, push))
    xs = []
    sim.add_callback(lambda o: xs.append((o.time, o.cells["x"][0])), every=10.0)
    sim.run(until=100.0 + 1000.0, progress=False)
    t, x = np.array(xs).T
    offset = x[-1] - x_start
    assert abs(offset - push / k) / (push / k) < 1e-3, offset
    # The rate of approach over the first three relaxation times: k/ξ less the lag of the
    # centre behind the velocity that the interface's advection has (1.83 % in steady motion
    # at speed 0.02, measured 3.2 % here at speeds from 0.005 down; 3.5 % fitted over the
    # 2nd to 4th relaxation times). Asserted: slower than k/ξ, by less than 5 %.
    d = push / k - (x - x_start)
    early = (t - 100.0 <= 3 * XI / k) & (d > 0)
    rate = -np.polyfit(t[early], np.log(d[early]), 1)[0] / (k / XI)
    assert 0.95 < rate < 1.0, rate


def trap_end(dt, frozen=False):
    """x at t = 60 of a cell in a trap (k = 0.05 at x = 36) from t = 10 at time step dt; with
    `frozen` the force of each step's corrector is the one of its predictor (the positions at
    the step's start), the first-order scheme a force evaluated once per step would be."""
    kept = {"calls": 0, "x": None}

    def f(t, c):
        x = c["x"]
        if frozen:
            if kept["calls"] % 2 == 0:
                kept["x"] = x.copy()
            x = kept["x"]
            kept["calls"] += 1
        return np.column_stack([-0.05 * (x - 36.0), -0.05 * (c["y"] - 32.0)])

    sim = ml.Simulation(single(integrator__dt=dt), threads=1)
    sim.run(until=10.0, progress=False)
    sim.add_force(f)
    sim.run(until=60.0, progress=False)
    return sim.cells["x"][0]


def test_heun_evaluates_a_position_dependent_force_at_the_predicted_state():
    # The force in the corrector stage sees the centres of Heun's predicted fields: the end
    # at dt = 0.5 agrees with dt = 0.0625 to 2.5e-6 of a 2.8 displacement (measured; what
    # is left is not in the force), where the force frozen at the step's start is off by
    # 7.8e-3, 3.3e-3, 1.1e-3 at dt = 0.5, 0.25, 0.125 (first order).
    fine = trap_end(0.0625)
    assert abs(fine - 34.839) < 1e-3
    assert abs(trap_end(0.5) - fine) < 2e-5
    frozen = [trap_end(dt, frozen=True) - fine for dt in (0.5, 0.25)]
    assert frozen[0] > 5e-3 and 1.8 < frozen[0] / frozen[1] < 3, frozen


def test_a_python_force_gives_the_same_result_on_one_and_two_threads(root):
    from conftest import small_paper

    results = []
    for threads in [1, 2]:
        sim = ml.Simulation(small_paper(root), threads=threads)
        sim.add_force(lambda t, c: np.column_stack([0.01 * np.sin(c["y"] / 8 + t / 10), -0.01 * np.cos(c["x"] / 8)]))
        sim.run(progress=False)
        results.append((sim.cells, sim.phi()[0]))
    (a, pa), (b, pb) = results
    assert all(np.array_equal(a[k], b[k]) for k in a)
    assert np.array_equal(pa, pb)
    assert np.abs(a["cell_fx"]).max() > 0
