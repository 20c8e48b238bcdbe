"""monolayer: multi-phase-field simulations of cell monolayers, driven from Python.

Every cell is its own phase field; cells push on each other through a tissue stress built
from their shapes, and above a threshold activity the tissue flows like an active nematic.
The model, its parameters and its outputs are those of the ``monolayer`` command line
(``docs/model.md``, ``docs/scenes.md`` and ``docs/outputs.md`` in the repository).

A tour::

    import monolayer as ml

    scene = ml.Scene.from_toml("scenes/paper.toml").set("model.zeta", 0.004)
    sim = ml.Simulation(scene, threads=2)
    sim.run(until=100)                       # progress bar; Ctrl-C stops after a step
    cells = sim.cells                        # dict of NumPy columns: pandas.DataFrame(cells)
    sim.add_force(lambda t, c: np.c_[0.01 * np.ones(len(c["x"])), 0 * c["y"]])
    sim.step(10)
    sim.render(colour="velocity")            # a PNG, shown inline in Jupyter

    run = ml.run(scene, out="out/paper")     # what `monolayer run` writes
    run.series                               # a DataFrame of series.csv

Views and copies: every array this package returns is a copy that Python owns, made
read-only where it is a snapshot of the state (``sim.cells``, ``sim.phi()``,
``sim.fields()``); nothing changes under your feet when the simulation steps.
"""

from __future__ import annotations

import csv
import os
import sys
from pathlib import Path
from typing import Any, Callable, Dict, Iterator, List, NamedTuple, Optional, Sequence, Union

import numpy as np

from . import _native
from ._native import Edit, Observation, Scene

__all__ = [
    "Scene",
    "Simulation",
    "Observation",
    "Edit",
    "Image",
    "Run",
    "Point",
    "run",
    "resume",
    "sweep",
]

__version__ = _native.__version__

PathLike = Union[str, "os.PathLike[str]"]


def _progress(total: float, start: float, enabled: bool) -> Optional[Callable[[float], None]]:
    """A function of the model time that reports the progress: a tqdm bar (which draws itself
    in a terminal and as a widget in Jupyter) when tqdm is installed, plain lines otherwise."""
    if not enabled or not total > start:
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        tqdm = None
    if tqdm is not None:
        bar = tqdm(total=round(total - start, 6), unit="TU", leave=False)

        def update(t: float) -> None:
            bar.n = round(min(t, total) - start, 6)
            bar.refresh()
            if t >= total:
                bar.close()

        return update
    marks = {"next": start}

    def text(t: float) -> None:
        if t >= marks["next"]:
            print(f"t = {t:g} of {total:g}", file=sys.stderr, flush=True)
            marks["next"] = t + (total - start) / 10

    return text


class Image:
    """A PNG picture drawn by the command line's renderer; Jupyter shows it inline."""

    def __init__(self, png: bytes, step: Optional[int] = None) -> None:
        self.png = png
        self.step = step

    def _repr_png_(self) -> bytes:
        return self.png

    def save(self, path: PathLike) -> Path:
        """Writes the PNG to ``path``."""
        p = Path(path)
        p.write_bytes(self.png)
        return p

    @property
    def size(self) -> tuple:
        """(width, height) in pixels, from the PNG header."""
        return int.from_bytes(self.png[16:20], "big"), int.from_bytes(self.png[20:24], "big")

    def __repr__(self) -> str:
        w, h = self.size
        at = f" of step {self.step}" if self.step is not None else ""
        return f"Image({w}×{h} PNG{at})"


class Simulation:
    """A scene simulated in memory, stepped and steered from Python.

    ``Simulation(scene, threads=None, backend="cpu")``: ``threads`` is the number of threads
    (every core for None); the result does not depend on it. The steps run with the
    interpreter's lock released, so other Python threads go on meanwhile. Ctrl-C stops a
    ``step`` or ``run`` after the step in progress and raises ``KeyboardInterrupt``; the
    simulation is then at a whole step and can go on.
    """

    def __init__(self, scene: Scene, threads: Optional[int] = None, backend: str = "cpu") -> None:
        self._sim = _native.Simulation(scene, threads, backend)

    @property
    def scene(self) -> Scene:
        """The scene."""
        return self._sim.scene

    @property
    def time(self) -> float:
        """The model time."""
        return self._sim.time

    @property
    def iteration(self) -> int:
        """Steps taken."""
        return self._sim.iteration

    @property
    def n_cells(self) -> int:
        """The number of cells."""
        return self._sim.n_cells

    def step(self, n: int = 1) -> "Simulation":
        """Takes ``n`` steps of the scene's time step."""
        self._sim.step(n)
        return self

    def run(self, until: Optional[float] = None, progress: bool = True) -> "Simulation":
        """Runs to model time ``until`` (the scene's end, ``relax_time + time``, by default),
        with a progress bar unless ``progress=False``."""
        end = self.scene.end_time if until is None else float(until)
        self._sim.run_until(end, _progress(end, self.time, progress))
        return self

    @property
    def cells(self) -> Dict[str, np.ndarray]:
        """The cells' columns at the current state, one row per cell in increasing identity:
        ``id``, ``population``, ``x``, ``y`` (centre of mass), ``vx``, ``vy``, ``fx``, ``fy``
        (interface force), ``cell_fx``, ``cell_fy`` (the terms' whole-cell forces), ``area``,
        ``s_xx``, ``s_xy`` (deformation tensor), then what the scene's terms add (such as
        ``polarity.theta``, or ``nematic.theta`` with ``nematic.x``, ``nematic.y`` the
        components xx and xy of each cell's nematic tensor). With ``[run] forces_by_origin``
        also each cell's force by origin, ``force.ORIGIN.x`` and ``.y`` (``pressure``,
        ``shape_activity``, ``nematic_activity``, ``adhesion``, ``walls``, each term's), which
        add up to ``fx + cell_fx``. Read-only copies: ``pandas.DataFrame(sim.cells)`` just
        works."""
        return self._sim.cells()

    def phi(self) -> tuple:
        """Every cell's field on its patch: ``(phi, origin, id)`` with ``phi`` of shape
        ``(n, nx, ny)``, ``origin`` the lattice node of each patch's corner ``(n, 2)`` and the
        identities; node ``(i, j)`` of cell ``k`` is lattice node
        ``((origin[k, 0] + i) % lx, (origin[k, 1] + j) % ly)``. Read-only copies."""
        return self._sim.phi()

    def fields(self) -> Dict[str, np.ndarray]:
        """The lattice fields of the current state, arrays of shape ``(lx, ly[, k])``:
        ``phi_sum`` (Σφ), ``velocity`` (Σφᵢvᵢ), ``Q`` (Q_xx, Q_xy), ``pressure`` and
        ``sigma`` (σ_xx, σ_yy, σ_xy), and with ``[nematic]`` ``M`` (the cells' own nematic
        field Σφᵢqᵢ). Read-only copies."""
        return self._sim.fields()

    def observables(self) -> Dict[str, float]:
        """The scalars of ``series.csv`` for the current state."""
        return self._sim.observables()

    def add_callback(
        self, fn: Callable[[Observation], Any], every: Optional[float] = None, steps: Optional[int] = None
    ) -> None:
        """Calls ``fn(observation)`` while the simulation runs: every step by default, every
        ``every`` model time units, or every ``steps`` steps. The observation has ``time``,
        ``iteration``, ``cells`` and ``stop()``. An exception stops the run and is raised."""
        self._sim.add_callback(fn, every, steps)

    def add_force(self, fn: Callable[[float, Dict[str, np.ndarray]], Any], name: Optional[str] = None) -> None:
        """Adds a whole-cell force written in Python: ``fn(t, cells)`` returns an ``(n, 2)``
        array of forces, one row per cell in the order of ``cells["id"]``, added to each
        cell's interface force before its velocity ``v = (F + f)/ξ`` is formed.

        ``fn`` is called at every evaluation, both stages of Heun's step: with ``t`` and the
        positions ``x``, ``y`` of the state evaluated (in the corrector, Heun's predicted
        centres), so a force that depends on position is integrated to second order. The
        columns are ``id``, ``population``, ``x``, ``y``, ``vx``, ``vy``, ``area``. ``fn``
        must be a pure function of its arguments (it is also called when the state is
        observed)."""
        self._sim.add_force(fn, name)

    def add_fix(
        self, fn: Callable[[Edit], Any], every: Optional[float] = None, steps: Optional[int] = None
    ) -> None:
        """Calls ``fn(edit)`` between steps (every step by default) to change the state, as
        a Rust ``Fix``: ``edit.set_param("zeta", 0.01)``, ``edit.set_state("polarity.theta",
        values)``."""
        self._sim.add_fix(fn, every, steps)

    def edit(self, fn: Callable[[Edit], Any]) -> "Simulation":
        """Changes the state now, as a fix would between two steps: ``sim.edit(lambda e:
        e.set_param("zeta", 0.01))``."""
        self._sim.edit(fn)
        return self

    def render(self, colour: str = "none", **options: Any) -> Image:
        """The current state drawn as ``monolayer render`` draws a frame: ``colour`` is one
        of none, velocity, pressure, area, deformation, id, population, generation, lineage;
        ``options`` are ``director``, ``defects``, ``flow``, ``axes``, ``polarity``,
        ``nematic``, ``tracks``, ``events`` (booleans), ``director_of`` (``"shape"``, the
        default, or ``"nematic"``: whose director and defects are drawn, the shapes' Q or the
        cells' own nematic field M), ``size`` (pixels) and ``range`` (two numbers).
        Drawn in memory; ``tracks`` needs a run's earlier frames (``Run.render``)."""
        return Image(self._sim.render(colour, **options), self.iteration)

    def __repr__(self) -> str:
        return repr(self._sim)


def _read_csv(path: Path):
    """A CSV table as a pandas DataFrame, or a dict of NumPy columns without pandas."""
    try:
        import pandas as pd
    except ImportError:
        pd = None
    if pd is not None:
        return pd.read_csv(path)
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    head, body = rows[0], rows[1:]
    out = {}
    for k, name in enumerate(head):
        col = [r[k] for r in body]
        try:
            out[name] = np.array([float(v) for v in col])
        except ValueError:
            out[name] = np.array(col)
    return out


class Frames(Sequence):
    """The frames of a run, read lazily: ``run.frames[k]`` is a dict of NumPy arrays
    (``frames/frame_STEP.npz``, see docs/outputs.md), ``run.frames.steps`` their steps."""

    def __init__(self, paths: List[Path]) -> None:
        self.paths = paths
        self.steps = [int(p.stem.split("_")[1]) for p in paths]

    def __len__(self) -> int:
        return len(self.paths)

    def __getitem__(self, k):  # type: ignore[override]
        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(len(self)))]
        with np.load(self.paths[k]) as z:
            return {name: z[name] for name in z.files}

    def at(self, step: int) -> Dict[str, np.ndarray]:
        """The frame at ``step``."""
        return self[self.steps.index(step)]


class Run:
    """A run directory (what ``monolayer run`` or ``monolayer.run`` wrote), read lazily."""

    def __init__(self, path: PathLike) -> None:
        self.path = Path(path)
        if not (self.path / "scene.toml").is_file():
            raise FileNotFoundError(
                f"{self.path} is not a run directory (no scene.toml); give the --out of a run"
            )

    @classmethod
    def open(cls, path: PathLike) -> "Run":
        """Opens the run directory ``path``."""
        return cls(path)

    @property
    def scene(self) -> Scene:
        """The run's resolved scene (read for looking at the run: a term this program does not
        register is kept, and only stepping the scene needs it)."""
        return Scene.read_run(str(self.path / "scene.toml"))

    @property
    def complete(self) -> bool:
        """Whether the run reached its end."""
        return (self.path / "complete").exists()

    @property
    def series(self):
        """``series.csv``: a DataFrame (a dict of columns without pandas)."""
        return _read_csv(self.path / "series.csv")

    @property
    def frames(self) -> Frames:
        """The frames, read when indexed."""
        return Frames(sorted((self.path / "frames").glob("frame_*.npz")))

    @property
    def lineage(self):
        """``lineage.csv`` of a run whose cells divide, else None."""
        p = self.path / "lineage.csv"
        return _read_csv(p) if p.exists() else None

    @property
    def analysis(self) -> Dict[str, Any]:
        """The tables of ``analysis/`` (after ``monolayer analyze``), by file name."""
        d = self.path / "analysis"
        return {p.stem: _read_csv(p) for p in sorted(d.glob("*.csv"))} if d.is_dir() else {}

    def render(self, steps: Optional[Sequence[int]] = None, colour: str = "none", **options: Any) -> List[Image]:
        """Frames drawn as ``monolayer render`` draws them (all, or those at ``steps``);
        options as ``Simulation.render``."""
        pngs = _native.render_dir(str(self.path), list(steps) if steps is not None else None, colour, **options)
        return [Image(b, s) for s, b in pngs]

    def to_xarray(self):
        """The series as an ``xarray.Dataset`` indexed by time (needs xarray and pandas)."""
        import xarray as xr

        return xr.Dataset.from_dataframe(self.series.set_index("time"))

    def __repr__(self) -> str:
        return f"Run({str(self.path)!r}, {len(self.frames)} frames{'' if self.complete else ', not complete'})"


def run(
    scene: Scene,
    out: PathLike,
    overwrite: bool = False,
    threads: Optional[int] = None,
    progress: bool = True,
) -> Run:
    """Runs ``scene`` into the directory ``out``, writing exactly what ``monolayer run``
    writes (frames, ``series.csv``, checkpoints, ``run.json``, the lock). Ctrl-C stops it
    after the step in progress with a checkpoint and raises ``KeyboardInterrupt``;
    ``resume(out)`` goes on. Returns the run."""
    import warnings

    _, said = _native.run_dir(scene, str(out), overwrite, threads, _progress(scene.end_time, 0.0, progress))
    for w in said:
        warnings.warn(w, stacklevel=2)
    return Run(out)


def resume(dir: PathLike, time: Optional[float] = None, threads: Optional[int] = None, progress: bool = True) -> Run:
    """Continues the run in ``dir`` from its latest checkpoint to its end (to ``run.time =
    time`` when given), as ``monolayer run --resume``. Returns the run."""
    r = Run(dir)
    sc = r.scene if time is None else r.scene.set("run.time", float(time))
    _native.resume_dir(str(dir), time, threads, _progress(sc.end_time, 0.0, progress))
    return r


class Point(NamedTuple):
    """A point of a sweep: its name (``key=value_..._seed=S``), its scene and its run
    directory (``OUT/runs/NAME``, where ``monolayer sweep`` puts it)."""

    name: str
    scene: Scene
    out: Optional[Path]


def sweep(
    scene: Scene,
    vary: Dict[str, Sequence[Any]],
    seeds: Optional[Sequence[int]] = None,
    out: Optional[PathLike] = None,
) -> Iterator[Point]:
    """The points of a sweep of ``scene`` over ``vary`` (``{"model.zeta": [0.002, 0.004]}``)
    and ``seeds`` (a range of consecutive seeds), in the order and with the directory layout
    of ``monolayer sweep`` (``out/args.txt`` and ``out/scene.toml``, the sweep's arguments and
    scene, and ``out/runs/NAME``), named as the command line names them
    (``model.zeta=0``, ``model.zeta=0.005``), for any executor::

        spawn = multiprocessing.get_context("spawn")  # never fork a process with threads
        with ProcessPoolExecutor(mp_context=spawn) as pool:
            for p in ml.sweep(scene, {"model.zeta": [0.002, 0.004]}, range(1, 4), "out/s"):
                pool.submit(ml.run, p.scene, p.out)

    ``monolayer sweep SCENE --collect`` and ``monolayer analyze`` then work on ``out``."""
    span = None
    if seeds is not None:
        s = list(seeds)
        if not s or s != list(range(s[0], s[0] + len(s))):
            raise ValueError(f"seeds: give consecutive seeds such as range(1, 5), not {s}")
        span = (s[0], s[-1])
    for name, sc, path in _native.sweep_points(scene, dict(vary), span, None if out is None else str(out)):
        yield Point(name, sc, None if path is None else Path(path))
